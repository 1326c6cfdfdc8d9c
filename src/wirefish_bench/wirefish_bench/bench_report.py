# SPDX-License-Identifier: Apache-2.0
"""Render benchmark results (the dict of `wirefish_bench.bench`) as BENCHMARKS.md."""

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
import re

import numpy as np
from wirefish_bench.bench_firmware import row as firmware_row
from wirefish_bench.bench_old_new import rows as old_new_rows
from wirefish_bench.bench_radio_link import row as radio_row
from wirefish_bench.bench_recorder import row as recorder_row
from wirefish_bench.bench_view import row as view_row
from wirefish_common.executors import ExecutorKind

Row = tuple[str, str, str, str, str]  # figure, goal, measured, verdict, how


def _fmt(value, spec: str = '.3g') -> str:
    if isinstance(value, (int, float)):
        return format(value, spec)
    return str(value)


def _get(result, *keys):
    for key in keys:
        if not isinstance(result, dict) or key not in result:
            return None
        result = result[key]
    return result


def _verdict(measured, goal_ok) -> str:
    if measured is None:
        return 'not measured'
    return 'met' if goal_ok else 'missed'


# Each node figure on the classic executor and the events executor (old, then new), one run.
EXECUTORS = (ExecutorKind.CLASSIC, ExecutorKind.EVENTS)
FLEET_HOW = 'all streaming after {ready} s; then 3 s warm-up, 10 s window; psutil CPU'


def _side_by_side(by_executor: dict, describe) -> str:
    """Return 'classic: ...; events: ...' (``describe(result)`` per executor)."""
    parts = []
    for executor in EXECUTORS:
        r = by_executor.get(executor)
        text = ('not measured' if r is None else r['error'] if 'error' in r else describe(r))
        parts.append(f'**{executor}**: {text}')
    return '<br>'.join(parts)


def _verdicts(by_executor: dict, ok) -> str:
    """Return the verdict of the events executor, then the classic one's in brackets."""
    def one(executor: str) -> str:
        r = by_executor.get(executor)
        if r is None or 'error' in r:
            return 'not measured'
        return 'met' if ok(r) else 'missed'
    return f'{one("events")} (classic: {one("classic")})'


def _by_executor(items, *keys) -> dict:
    """Group result dicts by ``keys`` then executor: {key tuple: {executor: result}}."""
    grouped: dict = {}
    for r in items:
        if 'error' in r:
            continue
        grouped.setdefault(tuple(r.get(k) for k in keys), {})[r.get('executor')] = r
    return grouped


def _cpg_rows(results: dict) -> list[Row]:
    rows = [('CPG node rate', '', r['error'], 'failed', '')
            for r in results.get('cpg_rate', []) if 'error' in r]
    for (rate,), pair in _by_executor(results.get('cpg_rate', []), 'rate_hz').items():
        def describe(r) -> str:
            return (f'{r["achieved_hz"]:.1f} Hz; period error at the source p50/p99/max '
                    f'{r["source_period_error_p50_ms"]:.3f} / '
                    f'{r["source_period_error_p99_ms"]:.3f} / '
                    f'{r["source_period_error_max_ms"]:.2f} ms, at the receiver '
                    f'{r["period_error_p50_ms"]:.3f} / {r["period_error_p99_ms"]:.3f} / '
                    f'{r["period_error_max_ms"]:.2f} ms; {r["cpu_percent"]:.1f} % of a core')

        def ok(r) -> bool:
            return (r['source_period_error_p99_ms'] <= 0.2 and r['period_error_p99_ms'] <= 0.2
                    and r['cpu_percent'] <= 7.0)

        def ok_at_default(r) -> bool:
            return r['source_period_error_p99_ms'] <= 0.2
        goals = {1000.0: ('p99 ≤ 0.2 ms at the source and the receiver, CPU ≤ 7 %', ok),
                 SERVO_CMD_HZ: ('p99 ≤ 0.2 ms at the source (the default rate)',
                                ok_at_default)}
        goal, check = goals.get(rate, ('—', None))
        rows.append((f'CPG node at {rate:g} Hz: achieved rate, period error, CPU',
                     goal, _side_by_side(pair, describe),
                     _verdicts(pair, check) if check else '—',
                     '10 s; source: header stamps of servo_cmd (the node clock when the loop '
                     'published); receiver: arrival times in a separate process, spun on the '
                     "row's executor; psutil CPU"))
    return rows


def _link_rows(results: dict) -> list[Row]:
    links = results.get('links_by_executor', {})
    rows = []
    for key, label in (('command', 'servo_cmd publish → frame bytes on the fish side'),
                       ('telemetry', 'telemetry bytes written → imu/data received')):
        pair = {e: (r if 'error' in r else r[key]) for e, r in links.items()}
        how = next((r['how'] for r in links.values() if 'how' in r), 'see bench_links.py')
        rows.append((f'{label}, p50 / p99', 'p99 ≤ 1 ms',
                     _side_by_side(pair, lambda r: f'{_fmt(r.get("p50_ms"))} / '
                                   f'{_fmt(r.get("p99_ms"))} ms ({r.get("count")} samples)'),
                     _verdicts(pair, lambda r: r.get('p99_ms', float('inf')) <= 1.0),
                     f'{how} (the classic row receives on the classic executor, the events '
                     'row on the events executor)'))
    return rows


def _kinematics_rows(results: dict) -> list[Row]:
    rows = [('Kinematics node CPU', '—', r['error'], 'failed', '')
            for r in results.get('kinematics_cpu', []) if 'error' in r]
    for (stations, rate), pair in _by_executor(results.get('kinematics_cpu', []),
                                               'stations', 'rate_hz').items():
        rows.append((f'Kinematics node CPU, {stations} stations × {rate:g} Hz body_wave', '—',
                     _side_by_side(pair, lambda r: f'{r["cpu_percent"]:.1f} % of a core'),
                     '—', '10 s with the CPG feeding servo_cmd at 200 Hz; markers at their '
                     'default 10 Hz; psutil'))
    return rows


# One fish's onboard graph: at most this share of the classic executor's CPU in the same run
# (one process per node), and at most this much of a core.
ONBOARD_OF_CLASSIC = 0.25
ONBOARD_GOAL_PERCENT = 15.0
SERVO_CMD_HZ = 100.0  # servo_cmd's default rate (the rate the bridge forwards to the board)


def _fleet_ok(r: dict) -> bool:
    return (not r['crashed'] and r['servo_cmd_hz_min'] >= 0.95 * SERVO_CMD_HZ
            and r['imu_hz_min'] >= 0.95 * 100)


def _onboard_names(one_fish: dict) -> list[str]:
    for pair in one_fish.values():
        for r in pair.values():
            if r.get('onboard_processes'):
                return list(r['onboard_processes'])
    return ['?']


def _fleet_rows(results: dict) -> list[Row]:
    fleet = results.get('fleet', [])
    rows = [('Fish graphs on one machine', '8 at default rates', r['error'], 'failed', '')
            for r in fleet if 'error' in r]
    grouped = _by_executor(fleet, 'single_process', 'fish')
    one_fish = {single: grouped.get((single, 1), {}) for single in (False, True)}
    if any(one_fish.values()):
        def onboard(single: bool, executor: str) -> float | None:
            r = one_fish[single].get(executor)
            return None if r is None else r['onboard_cpu_percent_per_fish']
        old = onboard(False, ExecutorKind.CLASSIC)
        new = [v for v in (onboard(single, ExecutorKind.EVENTS) for single in (False, True))
               if v is not None]
        best = min(new) if new else None

        def runs(single: bool, executor: str) -> str:
            values = one_fish[single].get(executor, {}).get('onboard_cpu_percent_runs')
            return (f' (median of {" / ".join(f"{v:.1f}" for v in values)})'
                    if values and len(values) > 1 else '')

        measured = '<br>'.join(
            f'**{e}**, {"one process per fish" if single else "one process per node"}: '
            f'{_fmt(onboard(single, e), ".1f")} %{runs(single, e)}'
            for single in (False, True) for e in EXECUTORS)
        verdict = 'not measured'
        if old is not None and best is not None:
            measured += f'<br>best events / classic per node: {best / old:.2f}'
            verdict = 'met' if (best <= ONBOARD_OF_CLASSIC * old
                                and best <= ONBOARD_GOAL_PERCENT) else 'missed'
        rows.append(("One fish's onboard graph at default rates, CPU (% of a core)",
                     "≤ ¼ of the classic executor's (one process per node) in the same run, "
                     f'≤ {ONBOARD_GOAL_PERCENT:g} %',
                     measured, verdict,
                     'the 1-fish fleet runs below: every process but the virtual fish ('
                     + ', '.join(_onboard_names(one_fish)) + '; the tuner idle, the planner '
                     'without cmd_vel); psutil over the 10 s window'))
    capacity: dict[tuple[bool, str], int] = {}
    for (single, fish), pair in grouped.items():
        for executor, r in pair.items():
            if _fleet_ok(r):
                key = (single, executor)
                capacity[key] = max(capacity.get(key, 0), fish)
    if grouped:
        rows.append(('Fish at default rates on this machine (servo_cmd ≥ 95 Hz, imu ≥ 95 Hz '
                     'each, nothing crashed; one fish_sim for all)', '8',
                     '<br>'.join(f'**{e}**, '
                                 f'{"one process per fish" if single else "one per node"}: '
                                 f'{capacity.get((single, e), 0)}'
                                 for single in (False, True) for e in EXECUTORS),
                     'met' if max(capacity.values(), default=0) >= 8 else 'missed',
                     'largest fleet of the rows below that met the rates (sizes 1, 2, 4, 8)'))
    for (single, fish), pair in sorted(grouped.items()):
        mode = 'one process per fish' if single else 'one process per node'
        processes = next(iter(pair.values()))['processes']

        def describe(r) -> str:
            return (f'servo_cmd min {r["servo_cmd_hz_min"]:.1f} Hz, imu min '
                    f'{r["imu_hz_min"]:.1f} Hz, CPU {r["cpu_percent_total"]:.0f} % '
                    f'(of {results["machine"]["cores"]} cores × 100), onboard '
                    f'{r["onboard_cpu_percent_per_fish"]:.1f} % per fish'
                    + (f', crashed: {r["crashed"]}' if r['crashed'] else ''))
        ready = '/'.join(f'{pair[e].get("ready_s", float("nan")):.0f}'
                         for e in EXECUTORS if e in pair)
        rows.append((f'{fish} fish, {mode}, {processes} processes',
                     '8 at default rates' if fish == 8 else '—', _side_by_side(pair, describe),
                     _verdicts(pair, _fleet_ok), FLEET_HOW.format(ready=ready)
                     + ' (ready: classic/events)'))
    return rows


LIBRARY_GOAL_S = 0.020  # the same wave twice, the second from the library


def _library_rows(results: dict) -> list[Row]:
    table = []
    lib = results.get('retune_library')
    figure = 'Retune goal answered from the gait library (the same wave again): round trip'
    if lib is not None and 'error' in lib:
        table.append((figure, '< 20 ms', lib['error'], 'failed', ''))
    elif lib is not None:
        median = lib['library_round_trip_s_median']
        table.append((
            figure, '< 20 ms',
            f'median {1e3 * median:.1f} ms, max {1e3 * lib["library_round_trip_s_max"]:.1f} '
            f'ms (the tuner itself: {1e3 * lib["library_tuner_s_median"]:.2f} ms); every answer '
            f'from the library: {lib["all_from_library"]}; the first goal (a fit of '
            f'{lib["fit_iterations"]} iterations): {1e3 * lib["fit_round_trip_s"]:.0f} ms',
            _verdict(median, median < LIBRARY_GOAL_S and lib['all_from_library']),
            lib['how']))
    build = results.get('gaits_build')
    figure = '`wirefish gaits build`, default grid: wall time'
    if build is not None and 'error' in build:
        table.append((figure, 'finishes with a table', build['error'], 'failed', ''))
    elif build is not None:
        table.append((figure, 'finishes with a table',
                      f'{build["wall_s"]:.1f} s; {build["summary"]}',
                      'met' if build['returncode'] == 0 else
                      f'failed (exit {build["returncode"]})', build['how']))
    return table


def _retune_rows(results: dict) -> list[Row]:
    table: list[Row] = []
    retune = results.get('retune')
    if retune is not None and 'error' in retune:
        table.append(('Retune of the §5.2 case', '≤ 0.2 s, ≥ 50× baseline', retune['error'],
                      'not measured', ''))
    elif retune is not None:
        wall, ratio = retune.get('wall_s_median'), retune.get('ratio')
        table.append(('Retune of the §5.2 case: wall time, ratio vs pyswarms + per-particle ODE',
                      '≤ 0.2 s, ≥ 50×',
                      f'{_fmt(wall)} s (loss {_fmt(retune.get("loss"))}); baseline '
                      f'{_fmt(retune.get("baseline_wall_s"))} s (loss '
                      f'{_fmt(retune.get("baseline_loss"))}); ratio {_fmt(ratio)}×',
                      _verdict(wall, wall is not None and ratio is not None and wall <= 0.2
                               and ratio >= 50),
                      _fmt(retune.get('how', 'see bench_retune.py'))))
    return table + _library_rows(results)


def _recording_rows(results: dict) -> list[Row]:
    rec = results.get('recording', {})
    if 'error' in rec:
        return [('Recording, 60 s at default rates', '0 lost', rec['error'], 'failed', '')]
    if not rec:
        return []
    missing = rec.get('missing_from_sequences')
    return [('Recording, 60 s at default rates: messages in the bag, lost',
             '0 lost', f'{rec["messages"]} messages; lost {missing} (numbers missing '
             "from the publishers' sequences); "
             f'{rec.get("skipped_ticks")} publisher '
             'ticks skipped (gaps in the header stamps: nothing sent, nothing lost)',
             _verdict(rec, missing == 0),
             "wirefish up --duration; the recorder counts each publisher's DDS "
             'sequence numbers; skipped ticks from the stamps at the median period '
             '(report.py)')]


# The sweep's goal: at most a third of the old wall time on the same machine, in the same run.
SWEEP_OF_OLD = 1.0 / 3.0
# Each point's fish in the school swims the physics it swims alone (the same speeds to the bit):
# a difference above this is a change of the figures, not rounding (they print to 1 mm/s).
SWEEP_SAME_SPEED_M_S = 1e-6


def _sim_clock_rows(results: dict) -> list[Row]:
    if 'sim_clock' not in results:
        return []
    sim = results['sim_clock']
    sweep_figure = ("`wirefish sweep` over the paper's grid (virtual fish): wall and CPU time, "
                    'old (a point after another) vs new (the points as one school)')
    sweep_goal = ('wall ≤ ⅓ of old in the same run; the same speeds '
                  f'(≤ {SWEEP_SAME_SPEED_M_S:g} m/s)')
    clock_figure = ("One fish's graph on simulated time at --speed max: real-time factor, and "
                    "CPU per simulated second against the wall clock's")
    clock_goal = "— (the factor printed beside the wall clock's CPU per simulated s)"
    table: list[Row] = []
    sweep = sim.get('sweep', sim)
    if 'error' in sweep:
        table.append((sweep_figure, sweep_goal, sweep['error'], 'not measured', ''))
    else:
        old, new = sweep['old'], sweep['new']
        ratio = new['median_wall_s'] / old['median_wall_s']
        old_cpu, new_cpu = float(np.median(old['cpu_s'])), float(np.median(new['cpu_s']))
        difference = sweep['largest_speed_difference_m_s']

        def runs(values: list[float]) -> str:
            return ' / '.join(f'{v:.1f}' for v in values)
        table.append((
            sweep_figure, sweep_goal,
            f"wall old {old['median_wall_s']:.1f} s (runs {runs(old['wall_s'])}), new "
            f"{new['median_wall_s']:.1f} s (runs {runs(new['wall_s'])}): {ratio:.2f} of old; "
            f'CPU old {old_cpu:.1f} s, new {new_cpu:.1f} s: {new_cpu / old_cpu:.2f} of old; '
            f"largest speed difference {difference:.1e} m/s over {sweep['points']} points",
            'met' if ratio <= SWEEP_OF_OLD and difference <= SWEEP_SAME_SPEED_M_S else 'missed',
            'run_sweep in a fresh interpreter each, old and new alternated '
            f"{len(old['wall_s'])} times, medians; old = src/wirefish_analysis before the points "
            'swam as schools, from git (bench_sim_clock.SWEEP_COMMIT)'))
    wall, fast = sim.get('wall_clock', sim), sim.get('speed_max', sim)
    failed = next((r['error'] for r in (wall, fast) if 'error' in r), None)
    if failed is not None:
        table.append((clock_figure, clock_goal, failed, 'not measured', ''))
    else:
        table.append((
            clock_figure, clock_goal,
            f"--speed max: {fast['real_time_factor']:.2f} simulated s per wall s, "
            f"{fast['cpu_s_per_simulated_s']:.2f} CPU s per simulated s; wall clock: "
            f"{wall['real_time_factor']:.2f} simulated s per wall s, "
            f"{wall['cpu_s_per_simulated_s']:.2f} CPU s per simulated s (--speed max "
            f"{fast['cpu_s_per_simulated_s'] / wall['cpu_s_per_simulated_s']:.2f} of it); "
            f"{wall['processes']} processes",
            '—',
            f"wirefish up --sim's graph (one process per node) on the wall clock, then at "
            f"--speed max (graph.on_simulated_time); {wall['wall_s']:.0f} s wall windows once "
            'imu/data streams; simulated time from the /clock topic; psutil CPU of the '
            "graph's processes (bench_sim_clock.graph_clock)"))
    return table


def _one(key: str, row_of: Callable[[dict], Row]) -> Callable[[dict], list[Row]]:
    """Return the rows of a section whose result ``key`` makes one row."""
    return lambda results: [row_of(results[key])] if key in results else []


class Section(StrEnum):
    """A section of a run, in run_all's order: `bench --only` names these."""

    CPG_RATE = 'cpg-rate'
    LINKS = 'links'
    RETUNE = 'retune'
    RADIO_LINK = 'radio-link'
    FIRMWARE = 'firmware'
    KINEMATICS = 'kinematics'
    RECORDING = 'recording'
    RECORDER = 'recorder'
    VIEW = 'view'
    OLD_NEW = 'old-new'
    SIM_CLOCK = 'sim-clock'
    FLEET = 'fleet'


SECTION_ROWS: dict[Section, Callable[[dict], list[Row]]] = {
    Section.CPG_RATE: _cpg_rows,
    Section.LINKS: _link_rows,
    Section.RETUNE: _retune_rows,
    Section.RADIO_LINK: _one('radio_link', radio_row),
    Section.FIRMWARE: _one('firmware', firmware_row),
    Section.KINEMATICS: _kinematics_rows,
    Section.RECORDING: _recording_rows,
    Section.RECORDER: _one('recorder_cpu', recorder_row),
    Section.VIEW: _one('view_cpu', view_row),
    Section.OLD_NEW: lambda results: (old_new_rows(results['old_new'])
                                      if 'old_new' in results else []),
    Section.SIM_CLOCK: _sim_clock_rows,
    Section.FLEET: _fleet_rows,
}


def rows(results: dict) -> list[Row]:
    """Return (figure, goal, measured, verdict, how) rows of every section, in order."""
    return [row for section in Section for row in SECTION_ROWS[section](results)]


# BENCHMARKS.md: a table per section, each naming its run; the runs, each with its machine and
# load, in the header. A run of some sections (--only) rewrites those sections' tables and
# keeps every other row as the file had it, byte for byte: the markdown is the record of the
# earlier runs (their raw JSON stays on the machine that ran them).
HISTORY_HEADING = '## History'
TABLE_HEAD = ('| figure | goal | measured | verdict | how |', '|---|---|---|---|---|')
WHOLE_RUN = 'whole run'
QUICK = ', --quick (short windows)'
_DATE = r'\d{4}-\d\d-\d\d \d\d:\d\d(?::\d\d)? UTC'
_NAME = r'[a-z0-9-]+'
_RUN_LINE = re.compile(rf'^- (?P<date>{_DATE}), '
                       rf'(?P<what>(?:{WHOLE_RUN}|`--only {_NAME}(?:,{_NAME})*`)'
                       rf'(?:{re.escape(QUICK)})?): '
                       rf'(?P<machine>.+)\. Its rows: {_NAME}(?:, {_NAME})*\.$')
_SECTION_HEADING = re.compile(rf'^## `(?P<name>{_NAME})`, run of (?P<date>{_DATE})$')
# The file before it had sections: one table from one run under a "Machine:" line.
_LEGACY_MACHINE = re.compile(rf'^Machine: (?P<machine>.+); (?P<date>{_DATE})'
                             r'(?:, load average (?P<load>[\d.]+) at the start)?\. ')
_LEGACY_FIGURES: dict[Section, tuple[str, ...]] = {
    Section.CPG_RATE: ('CPG node at ', 'CPG node rate'),
    Section.LINKS: ('servo_cmd publish → frame bytes', 'telemetry bytes written → imu/data'),
    Section.RETUNE: ('Retune of the §5.2 case', 'Retune goal answered', '`wirefish gaits build`'),
    Section.RADIO_LINK: ('Fish-shore radio link',),
    Section.FIRMWARE: ('Firmware:',),
    Section.KINEMATICS: ('Kinematics node CPU',),
    Section.RECORDING: ('Recording, 60 s',),
    Section.RECORDER: ('Recorder CPU',),
    Section.VIEW: ('View server',),
    Section.OLD_NEW: ('CPG period error at the source', 'Virtual fish of a fleet of ',
                      'Servo intakes at ', "planner_node's imu/data intake"),
    Section.FLEET: ("One fish's onboard graph", 'Fish at default rates on this machine',
                    'Fish graphs on one machine', r'\d+ fish, one process per '),
}


class MergeError(ValueError):
    """A previous BENCHMARKS.md whose rows cannot be told apart by section and run."""


@dataclass(frozen=True)
class Run:
    """One run of `make bench`: when (its key), what it ran, the machine and its load."""

    date: str
    what: str  # WHOLE_RUN or '`--only a,b`', and QUICK after it for short windows
    machine: str


@dataclass(frozen=True)
class Block:
    """One section's rows (markdown lines, verbatim) and the date of the run they come from."""

    section: str
    run: str
    rows: tuple[str, ...]


@dataclass(frozen=True)
class Document:
    """A BENCHMARKS.md as runs, sections and the History section (verbatim)."""

    runs: dict[str, Run]
    blocks: tuple[Block, ...]
    history: str = ''


def kept_history(previous: str) -> str:
    """Return the History section of a previous BENCHMARKS.md text (to its end), or ''."""
    at = previous.find(f'\n{HISTORY_HEADING}\n')
    return previous[at + 1:] if at >= 0 else ''


def _machine_text(m: dict) -> str:
    return (f'{m["cpu"]}, {m["cores"]} cores, Python {m["python"]}, numpy {m["numpy"]}, '
            f'kernel {m["kernel"]}' + (f'; load average {m["load_average_1min"]:.1f} at the start'
                                       if 'load_average_1min' in m else ''))


def ran_sections(results: dict) -> list[Section]:
    """Return the sections ``results`` ran (results['sections']; every section if unsaid)."""
    return [Section(s) for s in results.get('sections', list(Section))]


def _fresh(results: dict, what: str) -> tuple[Run, list[Block]]:
    run = Run(results['machine']['date'], what + (QUICK if results.get('quick') else ''),
              _machine_text(results['machine']))
    return run, [Block(section, run.date, tuple(
        f'| {figure} | {goal} | {measured} | {verdict} | {how} |'
        for figure, goal, measured, verdict, how in SECTION_ROWS[section](results)))
        for section in ran_sections(results)]


def _legacy(lines: list[str], history: str) -> Document:
    machine = next((m for m in map(_LEGACY_MACHINE.match, lines) if m), None)
    if machine is None:
        raise MergeError('BENCHMARKS.md has neither sections nor a "Machine:" line to date its '
                         'table by')
    date = machine['date']
    load = f'; load average {machine["load"]} at the start' if machine['load'] else ''
    rows: dict[Section, list[str]] = {}
    for line in lines:
        if not line.startswith('| ') or line in TABLE_HEAD:
            continue
        figure = line[2:].split(' | ', 1)[0]
        section = next((s for s, patterns in _LEGACY_FIGURES.items()
                        if any(re.match(p, figure) for p in patterns)), None)
        if section is None:
            raise MergeError(f'a row of BENCHMARKS.md belongs to no section: {figure!r}')
        rows.setdefault(section, []).append(line)
    return Document({date: Run(date, WHOLE_RUN, machine['machine'] + load)},
                    tuple(Block(s, date, tuple(rows[s])) for s in Section if s in rows), history)


def parse_markdown(text: str) -> Document:
    """
    Read a BENCHMARKS.md: its runs, each section's row lines (verbatim) and its History.

    A file from before the sections (one table under a "Machine:" line) is one whole run, its
    rows given to sections by their figure. Raise MergeError when a row cannot be placed.
    """
    history = kept_history(text)
    lines = text[:len(text) - len(history)].splitlines()
    if not any(_SECTION_HEADING.match(line) for line in lines):
        if not text.strip():
            return Document({}, (), history)
        return _legacy(lines, history)
    runs: dict[str, Run] = {}
    blocks: list[Block] = []
    for line in lines:
        if (run := _RUN_LINE.match(line)) is not None:
            runs[run['date']] = Run(run['date'], run['what'], run['machine'])
        elif (heading := _SECTION_HEADING.match(line)) is not None:
            blocks.append(Block(heading['name'], heading['date'], ()))
        elif blocks and line.startswith('| ') and line not in TABLE_HEAD:
            last = blocks[-1]
            blocks[-1] = Block(last.section, last.run, (*last.rows, line))
    for block in blocks:
        if block.run not in runs:
            raise MergeError(f'section {block.section} names the run of {block.run}, which the '
                             "header's runs do not list")
    if len({b.section for b in blocks}) != len(blocks):
        raise MergeError('a section appears twice in BENCHMARKS.md')
    return Document(runs, tuple(blocks), history)


def render_document(document: Document) -> str:
    """Return the BENCHMARKS.md text of ``document``: header with its runs, sections, History."""
    used = [run for date, run in sorted(document.runs.items())
            if any(b.run == date for b in document.blocks)]
    lines = ['# Benchmarks', '',
             'Written by `make bench` (`python -m wirefish_bench.bench`): a whole run rewrites '
             'every section; `make bench ONLY=firmware,sim-clock` (`--only`) runs the named '
             'sections and rewrites their rows, keeping every other row as its run wrote it. '
             'Each section names its run; the runs (machine, load average at the start):', '']
    for run in used:
        names = ', '.join(b.section for b in document.blocks if b.run == run.date)
        lines.append(f'- {run.date}, {run.what}: {run.machine}. Its rows: {names}.')
    lines += ['', 'Shared and noisy: medians and p99 from one run, ratios within that run; rows '
              'of different runs differ by their load too.', '']
    for block in document.blocks:
        lines += [f'## `{block.section}`, run of {block.run}', '', *TABLE_HEAD, *block.rows, '']
    lines += ['Raw numbers: `out/bench/results.json` of each run, on the machine that ran it (a '
              'run of some sections holds those). Why the figures are what they are (py-spy '
              'profiles, what limits each missed goal, what would close it): '
              '[docs/PROFILING.md](docs/PROFILING.md).', '']
    text = '\n'.join(lines)
    return text + ('\n' + document.history if document.history else '')


def render_markdown(results: dict, history: str = '') -> str:
    """Return the whole BENCHMARKS.md text of a whole run, then ``history`` as it was."""
    run, blocks = _fresh(results, WHOLE_RUN)
    return render_document(Document({run.date: run}, tuple(blocks), history))


def merge_markdown(previous: Document, results: dict) -> str:
    """
    Return BENCHMARKS.md with the sections ``results`` ran replaced, every other row kept.

    Kept rows stay byte for byte with their run; a section new to the file is added in
    run_all's order; sections the file has and the tool no longer runs stay after them.
    """
    ran = ran_sections(results)
    run, fresh = _fresh(results, f'`--only {",".join(ran)}`')
    if run.date in previous.runs:
        raise MergeError(f'BENCHMARKS.md already has a run of {run.date}')
    by_section = {b.section: b for b in previous.blocks}
    by_section.update({b.section: b for b in fresh})
    known = [by_section[s] for s in Section if s in by_section]
    others = [b for b in previous.blocks if b.section not in set(Section)]
    return render_document(Document({**previous.runs, run.date: run}, (*known, *others),
                                    previous.history))
