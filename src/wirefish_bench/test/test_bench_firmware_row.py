"""The firmware's BENCHMARKS.md row: its verdict follows the flash and RAM budget."""

import pytest
from wirefish_bench.bench_firmware import row

CYCLES = {'counter': 'tsc', 'repeats': 5,
          **{name: {'median': 400, 'worst': 700, 'raw_max': 10**7, 'runs': 20000}
             for name in ('servo_cmd_received', 'longest_frame_received', 'telemetry_sent')}}


@pytest.mark.parametrize('size, verdict', [
    ({'flash_B': 12008, 'ram_B': 3400}, 'met'),
    ({'flash_B': 40000, 'ram_B': 3400}, 'missed'),
    ({'flash_B': 12008, 'ram_B': 9000}, 'missed'),
    ({'error': 'arm-none-eabi-gcc not installed'}, 'not measured'),
])
def test_verdict_follows_the_budget(size, verdict):
    figure, goal, measured, got, how = row({'cycles': CYCLES, 'size': size})
    assert got == verdict and 'worst of 20000 polls' in measured


def test_a_failed_benchmark_is_reported_as_such():
    assert row({'error': 'CalledProcessError: make'})[3] == 'not measured'
