# SPDX-License-Identifier: Apache-2.0
"""The sim-clock section's rows: the sweep old vs new, --speed max against the wall clock."""

import pytest
from wirefish_bench.bench_report import Section, SECTION_ROWS


def _sweep(old_wall: float, new_wall: float, difference: float = 0.0) -> dict:
    return {'old': {'wall_s': [old_wall, old_wall + 2.0], 'cpu_s': [37.6, 36.3],
                    'median_wall_s': old_wall + 1.0},
            'new': {'wall_s': [new_wall, new_wall + 2.0], 'cpu_s': [7.2, 7.7],
                    'median_wall_s': new_wall + 1.0},
            'largest_speed_difference_m_s': difference, 'points': 70}


def _graph(speed: str, factor: float, cpu_per_s: float) -> dict:
    return {'speed': speed, 'wall_s': 20.0, 'simulated_s': 20.0 * factor,
            'real_time_factor': factor, 'cpu_s': 20.0 * factor * cpu_per_s,
            'cpu_s_per_simulated_s': cpu_per_s, 'processes': 7}


def _rows(sweep: dict) -> list:
    return SECTION_ROWS[Section.SIM_CLOCK]({'sim_clock': {
        'sweep': sweep, 'wall_clock': _graph('wall clock', 1.0, 0.32),
        'speed_max': _graph('max', 3.95, 0.28)}})


@pytest.mark.parametrize('new_wall, difference, verdict', [
    (13.0, 0.0, 'met'),      # 14 s of 45 s: under a third
    (15.0, 0.0, 'missed'),   # 16 s of 45 s: more than a third
    (10.0, 1e-3, 'missed'),  # faster, but the speeds moved
])
def test_the_sweep_is_met_at_a_third_of_old_with_the_same_speeds(new_wall, difference, verdict):
    figure, goal, measured, got, how = _rows(_sweep(44.0, new_wall, difference))[0]
    assert got == verdict
    assert measured.startswith(f'wall old 45.0 s (runs 44.0 / 46.0), new {new_wall + 1:.1f} s')
    assert 'CPU old 37.0 s, new 7.5 s: 0.20 of old' in measured
    assert f'largest speed difference {difference:.1e} m/s over 70 points' in measured


def test_speed_max_is_quoted_beside_the_wall_clocks_cpu_per_simulated_second():
    figure, goal, measured, verdict, how = _rows(_sweep(44.0, 14.0))[1]
    assert measured == ('--speed max: 3.95 simulated s per wall s, 0.28 CPU s per simulated s; '
                        'wall clock: 1.00 simulated s per wall s, 0.32 CPU s per simulated s '
                        '(--speed max 0.88 of it); 7 processes')
    assert verdict == '—' and '20 s wall windows' in how


def test_a_failed_part_is_a_row_that_says_why():
    rows = SECTION_ROWS[Section.SIM_CLOCK]({'sim_clock': {
        'sweep': {'error': 'CalledProcessError: git archive'},
        'wall_clock': _graph('wall clock', 1.0, 0.32),
        'speed_max': {'error': 'RuntimeError: no /clock'}}})
    assert [row[2:4] for row in rows] == [('CalledProcessError: git archive', 'not measured'),
                                          ('RuntimeError: no /clock', 'not measured')]
    whole = SECTION_ROWS[Section.SIM_CLOCK]({'sim_clock': {'error': 'ImportError: x'}})
    assert [row[2:4] for row in whole] == [('ImportError: x', 'not measured')] * 2
