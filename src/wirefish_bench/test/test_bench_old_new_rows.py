# SPDX-License-Identifier: Apache-2.0
"""bench_old_new's BENCHMARKS.md rows from given figures (pure: no processes)."""

import pytest
from wirefish_bench.bench_old_new import rows


def _result(new_p99_ms):
    return {'cpg': {which: {'source_p99_ms': [p99, p99], 'source_p50_ms': [0.01, 0.01],
                            'median_source_p99_ms': p99, 'cpu_percent': [5.0, 5.0]}
                    for which, p99 in (('old', 6.2), ('new', new_p99_ms))},
            'simulators': {'fish': 8, 'old_cpu_percent': 258.0, 'new_cpu_percent': 32.0,
                           'ratio': 32.0 / 258.0},
            'intakes': {'a callback per message and a 50 Hz tick': 6.3,
                        'a 50 Hz tick taking a batch': 3.9,
                        'servo pair read from each message': 6.1,
                        'servo pair read from the raw bytes': 4.8}}


@pytest.mark.parametrize('new_p99_ms, verdict', [(0.15, 'met'), (0.38, 'missed')])
def test_the_cpg_row_is_met_at_a_p99_of_0_2_ms_or_less(new_p99_ms, verdict):
    cpg = rows(_result(new_p99_ms))[0]
    assert cpg[3] == verdict and 'old 6.200 ms' in cpg[2]


def test_the_simulator_and_intake_rows_quote_old_and_new():
    _, simulators, intakes = rows(_result(0.2))
    assert 'old 258.0 %, new 32.0 % (ratio 0.12)' in simulators[2]
    assert 'kinematics: old 6.30 %, new 3.90 %' in intakes[2]
    assert 'bridge: old 6.10 %, new 4.80 %' in intakes[2]


def test_a_failed_run_is_one_row_that_says_so():
    row = rows({'error': 'RuntimeError: boom'})[0]
    assert row[2:4] == ('RuntimeError: boom', 'not measured')
