# SPDX-License-Identifier: Apache-2.0
"""BENCHMARKS.md rows of the gait library: its answer and `wirefish gaits build`."""

import pytest
from wirefish_bench.bench_report import rows

MACHINE = {'machine': {}}


def _library(median_s: float, from_library: bool = True) -> dict:
    return {'retune_library': {
        'fit_round_trip_s': 0.2, 'fit_iterations': 100, 'library_round_trip_s_median': median_s,
        'library_round_trip_s_max': 2 * median_s, 'library_tuner_s_median': 0.0004,
        'all_from_library': from_library, 'how': 'h'}}


def _row(results: dict, starts: str) -> tuple:
    return next(r for r in rows({**MACHINE, **results}) if r[0].startswith(starts))


@pytest.mark.parametrize('median_s, from_library, verdict', [
    (0.011, True, 'met'), (0.025, True, 'missed'), (0.011, False, 'missed')])
def test_the_library_row_is_met_only_under_20_ms_and_from_the_library(
        median_s, from_library, verdict):
    figure, goal, measured, got, _ = _row(_library(median_s, from_library), 'Retune goal')
    assert got == verdict
    assert f'median {1e3 * median_s:.1f} ms' in measured


def test_a_failed_library_benchmark_is_a_row_that_says_why():
    row = _row({'retune_library': {'error': 'RuntimeError: no server'}}, 'Retune goal')
    assert row[2:4] == ('RuntimeError: no server', 'failed')


@pytest.mark.parametrize('returncode, verdict', [(0, 'met'), (1, 'failed (exit 1)')])
def test_the_gaits_build_row_shows_the_wall_time_and_the_exit(returncode, verdict):
    build = {'wall_s': 7.34, 'returncode': returncode, 'summary': 'stored 25 gaits', 'how': 'h'}
    figure, goal, measured, got, _ = _row({'gaits_build': build}, '`wirefish gaits build`')
    assert got == verdict
    assert measured.startswith('7.3 s; stored 25 gaits')


def test_the_radio_link_row_is_in_the_table_when_measured():
    row = _row({'radio_link': {'error': 'not root'}}, 'Fish-shore radio link')
    assert row[2:4] == ('not root', 'not measured')
