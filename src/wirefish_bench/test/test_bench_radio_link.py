# SPDX-License-Identifier: Apache-2.0
"""The radio-link benchmark's BENCHMARKS.md row."""

from wirefish_bench.bench_radio_link import row


def _mode(fish_to_shore: float) -> dict:
    window = {'fish_to_shore_B_s': fish_to_shore, 'shore_to_fish_B_s': 2000.0}
    return {'unshaped': window, 'shaped': window}


def test_the_row_is_met_when_every_discovery_fits_the_limit_unshaped():
    figure, goal, measured, verdict, _ = row({'multicast': _mode(10000.0)})
    assert verdict == 'met' and 'multicast: 10000 / 2000 unshaped' in measured


def test_each_discovery_gets_its_own_verdict_when_only_one_fits():
    verdict = row({'multicast': _mode(10000.0), 'static': _mode(42000.0)})[3]
    assert verdict == 'multicast: met; static: missed'


def test_the_row_is_missed_when_no_discovery_fits():
    assert row({'multicast': _mode(13000.0), 'static': _mode(42000.0)})[3] == 'missed'


def test_a_machine_without_root_reports_why_nothing_was_measured():
    assert row({'error': 'only root'})[2:4] == ('only root', 'not measured')
