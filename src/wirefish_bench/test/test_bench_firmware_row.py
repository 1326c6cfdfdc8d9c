# SPDX-License-Identifier: Apache-2.0
"""The firmware's BENCHMARKS.md row: its verdict follows the flash and RAM budget."""

import pytest
from wirefish_bench.bench_firmware import arm_cpg_step, row

CYCLES = {'counter': 'tsc', 'repeats': 5,
          **{name: {'median': 400, 'worst': 700, 'raw_max': 10**7, 'runs': 20000}
             for name in ('servo_cmd_received', 'longest_frame_received', 'telemetry_sent',
                          'gait_poll')},
          'cpg_step': {'median': 243, 'worst': 297, 'raw_max': 10**6, 'runs': 20000}}
MAKE_OUTPUT = 'cpg_step on the Cortex-M4 build: 1680 instructions (QEMU count)\n'


@pytest.mark.parametrize('size, verdict', [
    ({'flash_B': 12008, 'ram_B': 3400}, 'met'),
    ({'flash_B': 40000, 'ram_B': 3400}, 'missed'),
    ({'flash_B': 12008, 'ram_B': 9000}, 'missed'),
    ({'error': 'arm-none-eabi-gcc not installed'}, 'not measured'),
])
def test_verdict_follows_the_budget(size, verdict):
    figure, goal, measured, got, how = row({'cycles': CYCLES, 'size': size,
                                            'arm_cpg_step': arm_cpg_step(MAKE_OUTPUT)})
    assert got == verdict and 'worst of 20000 polls' in measured


def test_the_arm_step_time_is_the_count_at_168_mhz_said_as_an_estimate():
    step = arm_cpg_step(MAKE_OUTPUT)
    # 1680 instructions x 1.2 and 1.5 cycles / 168 MHz: 12 and 15 us of the 1 ms step
    assert step['instructions'] == 1680
    assert step['step_s_estimate'] == pytest.approx([12e-6, 15e-6])
    assert step['share_of_step_period_estimate'] == pytest.approx([0.012, 0.015])
    measured = row({'cycles': CYCLES, 'size': {'flash_B': 1, 'ram_B': 1},
                    'arm_cpg_step': step})[2]
    assert 'one CPG step 297 (median 243)' in measured
    assert '1680 instructions (counted in QEMU), an estimated 12-15 µs at 168 MHz' in measured
    assert '1.2-1.5 % of its 1 ms period' in measured


def test_a_make_output_without_the_count_is_an_error():
    with pytest.raises(ValueError, match='no instruction count'):
        arm_cpg_step('make: nothing to be done\n')


def test_an_arm_step_not_measured_says_why_and_keeps_the_size_verdict():
    figure, goal, measured, got, how = row({
        'cycles': CYCLES, 'size': {'flash_B': 12008, 'ram_B': 3400},
        'arm_cpg_step': {'error': 'qemu-system-arm not installed'}})
    assert 'Cortex-M4 not measured: qemu-system-arm not installed' in measured
    assert got == 'met'


def test_a_failed_benchmark_is_reported_as_such():
    assert row({'error': 'CalledProcessError: make'})[3] == 'not measured'
