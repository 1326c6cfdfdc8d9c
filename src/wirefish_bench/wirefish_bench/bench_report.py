"""Render benchmark results (the dict of `wirefish_bench.bench`) as BENCHMARKS.md."""

from wirefish_bench.bench_firmware import row as firmware_row
from wirefish_bench.bench_old_new import rows as old_new_rows
from wirefish_bench.bench_radio_link import row as radio_row
from wirefish_bench.bench_recorder import row as recorder_row
from wirefish_bench.bench_view import row as view_row
from wirefish_common.executors import ExecutorKind


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


def _cpg_rows(results: dict) -> list[tuple[str, str, str, str, str]]:
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


def _link_rows(results: dict) -> list[tuple[str, str, str, str, str]]:
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


def _kinematics_rows(results: dict) -> list[tuple[str, str, str, str, str]]:
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


def _fleet_rows(results: dict) -> list[tuple[str, str, str, str, str]]:
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


def _library_rows(results: dict) -> list[tuple[str, str, str, str, str]]:
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


def rows(results: dict) -> list[tuple[str, str, str, str, str]]:
    """Return (figure, goal, measured, verdict, how) rows."""
    table = [*_cpg_rows(results), *_link_rows(results)]
    retune = results.get('retune', {})
    if 'error' in retune:
        table.append(('Retune of the §5.2 case', '≤ 0.2 s, ≥ 50× baseline', retune['error'],
                      'not measured', ''))
    else:
        wall, ratio = retune.get('wall_s_median'), retune.get('ratio')
        table.append(('Retune of the §5.2 case: wall time, ratio vs pyswarms + per-particle ODE',
                      '≤ 0.2 s, ≥ 50×',
                      f'{_fmt(wall)} s (loss {_fmt(retune.get("loss"))}); baseline '
                      f'{_fmt(retune.get("baseline_wall_s"))} s (loss '
                      f'{_fmt(retune.get("baseline_loss"))}); ratio {_fmt(ratio)}×',
                      _verdict(wall, wall is not None and ratio is not None and wall <= 0.2
                               and ratio >= 50),
                      _fmt(retune.get('how', 'see bench_retune.py'))))
    table += _library_rows(results)
    if 'radio_link' in results:
        table.append(radio_row(results['radio_link']))
    if 'firmware' in results:
        table.append(firmware_row(results['firmware']))
    table += _kinematics_rows(results)
    rec = results.get('recording', {})
    if 'error' in rec:
        table.append(('Recording, 60 s at default rates', '0 lost', rec['error'], 'failed', ''))
    elif rec:
        missing = rec.get('missing_from_sequences')
        table.append(('Recording, 60 s at default rates: messages in the bag, lost',
                      '0 lost', f'{rec["messages"]} messages; lost {missing} (numbers missing '
                      "from the publishers' sequences); "
                      f'{rec.get("skipped_ticks")} publisher '
                      'ticks skipped (gaps in the header stamps: nothing sent, nothing lost)',
                      _verdict(rec, missing == 0),
                      "wirefish up --duration; the recorder counts each publisher's DDS "
                      'sequence numbers; skipped ticks from the stamps at the median period '
                      '(report.py)'))
    if 'recorder_cpu' in results:
        table.append(recorder_row(results['recorder_cpu']))
    if 'view_cpu' in results:
        table.append(view_row(results['view_cpu']))
    if 'old_new' in results:
        table += old_new_rows(results['old_new'])
    table += _fleet_rows(results)
    return table


HISTORY_HEADING = '## History'


def kept_history(previous: str) -> str:
    """Return the History section of a previous BENCHMARKS.md text (to its end), or ''."""
    at = previous.find(f'\n{HISTORY_HEADING}\n')
    return previous[at + 1:] if at >= 0 else ''


def render_markdown(results: dict, history: str = '') -> str:
    """Return the whole BENCHMARKS.md text: this run's table, then ``history`` as it was."""
    m = results['machine']
    lines = ['# Benchmarks', '',
             'Written by `make bench` (`python -m wirefish_bench.bench`); figures from one '
             'run.',
             f'Machine: {m["cpu"]}, {m["cores"]} cores, Python {m["python"]}, numpy '
             f'{m["numpy"]}, kernel {m["kernel"]}; {m["date"]}'
             + (f', load average {m["load_average_1min"]:.1f} at the start'
                if 'load_average_1min' in m else '')
             + '. Shared and noisy: medians and p99 from one run, ratios within that run.', '',
             '| figure | goal | measured | verdict | how |', '|---|---|---|---|---|']
    for figure, goal, measured, verdict, how in rows(results):
        lines.append(f'| {figure} | {goal} | {measured} | {verdict} | {how} |')
    lines += ['', 'Raw numbers: `out/bench/results.json` of the same run. Why the figures are '
              'what they are (py-spy profiles, what limits each missed goal, what would close '
              'it): [docs/PROFILING.md](docs/PROFILING.md).', '']
    return '\n'.join(lines) + ('\n' + history if history else '')
