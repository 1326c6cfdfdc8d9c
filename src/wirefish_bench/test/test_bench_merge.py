# SPDX-License-Identifier: Apache-2.0
"""`bench --only`: the named sections' rows replaced, every other row kept byte for byte."""

from pathlib import Path

import pytest
from wirefish_bench import bench
from wirefish_bench.bench_report import (merge_markdown, MergeError, parse_markdown,
                                         render_markdown, Section)

# BENCHMARKS.md names each run by when it started (bench_report's format): four runs' stamps.
RUN_1, RUN_2 = '2026-12-03 15:12 UTC', '2026-12-04 16:40:05 UTC'
RUN_3, RUN_4 = '2026-12-04 16:50:00 UTC', '2026-12-04 16:55:00 UTC'
RUN_LINE = f'- {RUN_1[:5]}'  # the header's line of a run starts with the run's stamp
HISTORY = '## History\n\n### 2026-12-01: a dated entry\n\n| what | then |\n|---|---|\n| a | b |\n'
OLD_ROWS = {
    'cpg': '| CPG node at 100 Hz: achieved rate | p99 ≤ 0.2 ms | **classic**: 100.0 Hz<br>'
           '**events**: 99.9 Hz | met (classic: met) | 10 s |',
    # a trailing space and odd figures: kept as they are, not re-rendered
    'firmware': '| Firmware: cycles per received frame | ≤ 32 KB flash | TSC ticks 550 | met | '
                'host build | ',
    'radio': '| Fish-shore radio link: bytes/s crossing | fits 100kbit/s | multicast: 9243 / '
             '2550 | multicast: met; static: missed | tc tbf |',
    'fleet': '| 2 fish, one process per node, 13 processes | — | **classic**: servo_cmd min 100.0 '
             'Hz | met (classic: met) | all streaming after 5/4 s |',
}
LEGACY = '\n'.join([
    '# Benchmarks', '',
    'Written by `make bench` (`python -m wirefish_bench.bench`); figures from one run.',
    f'Machine: Xeon, 2 cores, Python 3.11.7, numpy 2.4.6, kernel k1; {RUN_1}, load '
    'average 0.5 at the start. Shared and noisy: medians and p99 from one run.', '',
    '| figure | goal | measured | verdict | how |', '|---|---|---|---|---|', *OLD_ROWS.values(),
    '', 'Raw numbers: `out/bench/results.json` of the same run.', '', HISTORY])


def _results(date: str, load: float, **sections: dict) -> dict:
    """Return a run's results: its machine and ``sections`` ({name with _: results})."""
    results = {'machine': {'cpu': 'Xeon', 'cores': 2, 'python': '3.11.7', 'numpy': '2.4.6',
                           'kernel': 'k2', 'date': date, 'load_average_1min': load},
               'sections': [name.replace('_', '-') for name in sections]}
    keys = {'firmware': 'firmware', 'radio_link': 'radio_link', 'sim_clock': 'sim_clock'}
    for name, result in sections.items():
        results[keys[name]] = result
    return results


FIRMWARE_RUN = _results(RUN_2, 1.3,
                        firmware={'error': 'CalledProcessError: make cycles'})


def _lines(text: str) -> list[str]:
    return text.splitlines()


def _headings(text: str) -> list[str]:
    return [line for line in _lines(text) if line.startswith('## `')]


def test_other_sections_rows_are_kept_byte_for_byte_and_the_named_ones_replaced():
    merged = merge_markdown(parse_markdown(LEGACY), FIRMWARE_RUN)
    lines = _lines(merged)
    for key in ('cpg', 'radio', 'fleet'):
        assert OLD_ROWS[key] in lines
    assert OLD_ROWS['firmware'] not in merged and 'TSC ticks 550' not in merged
    at = lines.index(f'## `firmware`, run of {RUN_2}')
    assert lines[at + 4].startswith('| Firmware: ')
    assert '| CalledProcessError: make cycles | not measured |' in lines[at + 4]
    assert merged.endswith('\n' + HISTORY)


def test_the_header_lists_each_run_with_its_machine_its_load_and_its_rows():
    merged = merge_markdown(parse_markdown(LEGACY), FIRMWARE_RUN)
    runs = [line for line in _lines(merged) if line.startswith(RUN_LINE)]
    assert runs == [
        f'- {RUN_1}, whole run: Xeon, 2 cores, Python 3.11.7, numpy 2.4.6, kernel '
        'k1; load average 0.5 at the start. Its rows: cpg-rate, radio-link, fleet.',
        f'- {RUN_2}, `--only firmware`: Xeon, 2 cores, Python 3.11.7, numpy '
        '2.4.6, kernel k2; load average 1.3 at the start. Its rows: firmware.']
    assert _headings(merged) == [
        f'## `cpg-rate`, run of {RUN_1}',
        f'## `radio-link`, run of {RUN_1}',
        f'## `firmware`, run of {RUN_2}',
        f'## `fleet`, run of {RUN_1}']


def test_a_second_run_keeps_the_first_runs_rows_and_a_run_with_none_left_leaves_the_header():
    first = merge_markdown(parse_markdown(LEGACY), FIRMWARE_RUN)
    firmware_row = next(line for line in _lines(first) if line.startswith('| Firmware: '))
    second = merge_markdown(parse_markdown(first), _results(
        RUN_3, 0.9, radio_link={'error': 'only root'}))
    assert firmware_row in _lines(second) and OLD_ROWS['cpg'] in _lines(second)
    assert OLD_ROWS['radio'] not in second
    assert '| only root | not measured |' in second
    assert [line.split(',')[0] for line in _lines(second) if line.startswith(RUN_LINE)] == [
        f'- {RUN_1}', f'- {RUN_2}', f'- {RUN_3}']
    # a third run of radio-link again: the second run has no row left, so no line either
    third = merge_markdown(parse_markdown(second), _results(
        RUN_4, 0.9, radio_link={'error': 'only root'}))
    assert ([b for b in parse_markdown(third).blocks if b.section != 'radio-link']
            == [b for b in parse_markdown(second).blocks if b.section != 'radio-link'])
    assert RUN_3 not in third


def test_a_section_new_to_the_file_is_added_in_run_order():
    merged = merge_markdown(parse_markdown(LEGACY), _results(
        RUN_2, 1.3, sim_clock={'error': 'RuntimeError: no clock'}))
    assert _headings(merged) == [
        f'## `cpg-rate`, run of {RUN_1}',
        f'## `radio-link`, run of {RUN_1}',
        f'## `firmware`, run of {RUN_1}',
        f'## `sim-clock`, run of {RUN_2}',
        f'## `fleet`, run of {RUN_1}']
    assert all(row in _lines(merged) for row in OLD_ROWS.values())


def test_a_whole_run_rewrites_every_section_under_one_run_and_keeps_the_history():
    text = render_markdown({**FIRMWARE_RUN, 'sections': list(Section)}, HISTORY)
    assert [line for line in _lines(text) if line.startswith(RUN_LINE)] == [
        f'- {RUN_2}, whole run: Xeon, 2 cores, Python 3.11.7, numpy 2.4.6, '
        'kernel k2; load average 1.3 at the start. Its rows: '
        + ', '.join(Section) + '.']
    assert len(_headings(text)) == len(Section) and text.endswith('\n' + HISTORY)
    assert parse_markdown(text) == parse_markdown(text.replace(HISTORY, '') + HISTORY)


def test_a_row_that_belongs_to_no_section_stops_the_merge():
    with pytest.raises(MergeError, match="no section: 'A figure nobody renders: bytes/s"):
        parse_markdown(LEGACY.replace('| Fish-shore radio link', '| A figure nobody renders'))


def test_a_run_already_in_the_file_is_refused():
    first = merge_markdown(parse_markdown(LEGACY), FIRMWARE_RUN)
    with pytest.raises(MergeError, match=f'already has a run of {RUN_2}'):
        merge_markdown(parse_markdown(first), FIRMWARE_RUN)


def _fake_sections(monkeypatch) -> list[str]:
    """Replace every section's runner by one that records its call and fails at once."""
    called: list[str] = []

    def runner(section: Section):
        def run(scale: float) -> dict:
            called.append(section.value)
            return {'firmware' if section == Section.FIRMWARE else f'x_{section}': {
                'error': 'not run'}}
        return run
    monkeypatch.setattr(bench, 'SECTIONS', {s: (text, runner(s))
                                            for s, (text, _) in bench.SECTIONS.items()})
    monkeypatch.setattr(bench, 'machine', lambda: dict(FIRMWARE_RUN['machine']))
    return called


def test_only_runs_the_named_sections_and_merges_them(monkeypatch, tmp_path: Path):
    called = _fake_sections(monkeypatch)
    markdown = tmp_path / 'BENCHMARKS.md'
    markdown.write_text(LEGACY)
    assert bench.main(['--only', 'firmware', '--markdown', str(markdown),
                       '--out', str(tmp_path)]) == 0
    assert called == ['firmware']
    assert (tmp_path / 'results.json').is_file()
    assert markdown.read_text() == merge_markdown(parse_markdown(LEGACY), {
        **FIRMWARE_RUN, 'quick': False, 'firmware': {'error': 'not run'}})


def test_a_plain_run_is_a_whole_run(monkeypatch, tmp_path: Path):
    called = _fake_sections(monkeypatch)
    markdown = tmp_path / 'BENCHMARKS.md'
    markdown.write_text(LEGACY)
    assert bench.main(['--markdown', str(markdown), '--out', str(tmp_path)]) == 0
    assert called == [s.value for s in bench.SECTIONS]
    text = markdown.read_text()
    assert RUN_1[:10] not in text.replace(HISTORY, '') and ', whole run: ' in text


def test_an_unknown_section_is_a_usage_error_and_nothing_runs(monkeypatch, tmp_path, capsys):
    called = _fake_sections(monkeypatch)
    markdown = tmp_path / 'BENCHMARKS.md'
    markdown.write_text(LEGACY)
    with pytest.raises(SystemExit) as stopped:
        bench.main(['--only', 'firmware,firmwar', '--markdown', str(markdown)])
    assert stopped.value.code == 2 and called == []
    error = capsys.readouterr().err
    assert "unknown section 'firmwar'" in error and 'cpg-rate, links,' in error
    assert markdown.read_text() == LEGACY


def test_a_file_whose_rows_cannot_be_kept_stops_before_anything_runs(monkeypatch, tmp_path):
    called = _fake_sections(monkeypatch)
    markdown = tmp_path / 'BENCHMARKS.md'
    broken = LEGACY.replace('| Fish-shore radio link', '| A figure nobody renders')
    markdown.write_text(broken)
    assert bench.main(['--only', 'firmware', '--markdown', str(markdown)]) == 1
    assert called == [] and markdown.read_text() == broken


def test_every_section_has_a_runner_and_rows():
    from wirefish_bench.bench_report import SECTION_ROWS
    assert set(SECTION_ROWS) == set(Section)
    assert list(bench.SECTIONS) == list(Section)
