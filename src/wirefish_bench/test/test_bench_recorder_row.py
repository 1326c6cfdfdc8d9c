# SPDX-License-Identifier: Apache-2.0
"""The recorder benchmark's row: its verdict follows the CPU ratio and the loss."""

import pytest
from wirefish_bench.bench_recorder import row


def _result(old_cpu: float, new_cpu: float, new_missing: int) -> dict:
    return {'recorders': {'window_s': 30.0, 'ratio': new_cpu / old_cpu,
                          'old': {'cpu_percent': old_cpu, 'missing': 0},
                          'new': {'cpu_percent': new_cpu, 'missing': new_missing}},
            'writers_us_per_message': {'mcap (new)': 4.2}}


@pytest.mark.parametrize('old_cpu, new_cpu, new_missing, verdict', [
    (8.0, 3.0, 0, 'met'),
    (8.0, 5.0, 0, 'missed'),  # more than half of the old recorder's CPU
    (8.0, 3.0, 2, 'missed'),  # cheaper, but it lost messages
])
def test_the_verdict_needs_half_the_cpu_and_no_loss(old_cpu, new_cpu, new_missing, verdict):
    figure, goal, measured, got, how = row(_result(old_cpu, new_cpu, new_missing))
    assert got == verdict
    assert f'old {old_cpu:.1f} %, new {new_cpu:.1f} %' in measured


def test_a_failed_run_is_not_measured():
    assert row({'error': 'RuntimeError: no graph'})[3] == 'not measured'
