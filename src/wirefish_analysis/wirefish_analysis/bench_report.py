"""Render benchmark results (the dict of `wirefish_analysis.bench`) as BENCHMARKS.md."""

import json


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


def rows(results: dict) -> list[tuple[str, str, str, str, str]]:
    """Return (figure, goal, measured, verdict, how) rows."""
    table = []
    for r in results.get('cpg_rate', []):
        if 'error' in r:
            table.append(('CPG node rate', '', r['error'], 'failed', ''))
            continue
        goal = 'p99 ≤ 0.2 ms, CPU ≤ 25 %' if r['rate_hz'] == 1000.0 else '—'
        ok = r['period_error_p99_ms'] <= 0.2 and r['cpu_percent'] <= 25.0
        table.append((
            f'CPG node at {r["rate_hz"]:g} Hz: achieved rate, period error p50/p99/max, CPU',
            goal,
            f'{r["achieved_hz"]:.1f} Hz; {r["period_error_p50_ms"]:.3f} / '
            f'{r["period_error_p99_ms"]:.3f} / {r["period_error_max_ms"]:.2f} ms; '
            f'{r["cpu_percent"]:.1f} % of a core',
            _verdict(r, ok) if r['rate_hz'] == 1000.0 else '—',
            '10 s; receive intervals of servo_cmd in a separate process; psutil CPU'))
    links = results.get('links', {})
    if 'error' in links:
        table.append(('Command / telemetry path latency', 'p99 ≤ 1 ms', links['error'],
                      'not measured', ''))
    else:
        for key, label in (('command', 'servo_cmd publish → frame bytes on the fish side'),
                           ('telemetry', 'telemetry bytes written → imu/data received')):
            p50, p99 = _get(links, key, 'p50_ms'), _get(links, key, 'p99_ms')
            table.append((label, 'p99 ≤ 1 ms',
                          f'p50 {_fmt(p50)} ms, p99 {_fmt(p99)} ms' if p99 is not None
                          else json.dumps(links.get(key)),
                          _verdict(p99, p99 is not None and p99 <= 1.0),
                          _fmt(links.get('how', 'see bench_links.py'))))
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
    for r in results.get('kinematics_cpu', []):
        if 'error' in r:
            table.append(('Kinematics node CPU', '—', r['error'], 'failed', ''))
            continue
        table.append((f'Kinematics node CPU, {r["stations"]} stations × {r["rate_hz"]:g} Hz',
                      '—', f'{r["cpu_percent"]:.1f} % of a core', '—',
                      '10 s with the CPG feeding servo_cmd; psutil'))
    rec = results.get('recording', {})
    if 'error' in rec:
        table.append(('Recording, 60 s at default rates', '0 lost', rec['error'], 'failed', ''))
    elif rec:
        missing = rec.get('missing_from_sequences')
        table.append(('Recording, 60 s at default rates: messages in the bag, lost',
                      '0 lost', f'{rec["messages"]} messages; lost {missing} (numbers missing '
                      "from the publishers' sequences; DDS lost count "
                      f'{rec.get("lost_in_transport")}); {rec.get("skipped_ticks")} publisher '
                      'ticks skipped (gaps in the header stamps: nothing sent, nothing lost)',
                      _verdict(rec, missing == 0),
                      "wirefish up --duration; the recorder counts each publisher's DDS "
                      'sequence numbers; skipped ticks from the stamps at the median period '
                      '(report.py)'))
    for r in results.get('fleet', []):
        if 'error' in r:
            table.append(('Fish graphs on one machine', '8 at default rates', r['error'],
                          'failed', ''))
            continue
        ok = (not r['crashed'] and r['servo_cmd_hz_min'] >= 0.95 * 200
              and r['imu_hz_min'] >= 0.95 * 100)
        mode = 'one process per fish' if r.get('single_process') else 'one process per node'
        table.append((f'{r["fish"]} fish graph(s), {mode}, {r["processes"]} processes',
                      '8 at default rates' if r['fish'] == 8 else '—',
                      f'servo_cmd min {r["servo_cmd_hz_min"]:.1f} Hz, imu min '
                      f'{r["imu_hz_min"]:.1f} Hz, CPU {r["cpu_percent_total"]:.0f} % '
                      f'(of {results["machine"]["cores"]} cores × 100)'
                      + (f', crashed: {r["crashed"]}' if r['crashed'] else ''),
                      _verdict(r, ok),
                      f'all streaming after {r.get("ready_s", float("nan")):.0f} s; then 3 s '
                      'warm-up, 10 s window'))
    return table


def render_markdown(results: dict) -> str:
    """Return the whole BENCHMARKS.md text."""
    m = results['machine']
    lines = ['# Benchmarks', '',
             'Written by `make bench` (`python -m wirefish_analysis.bench`); figures from one '
             'run.',
             f'Machine: {m["cpu"]}, {m["cores"]} cores, Python {m["python"]}, numpy '
             f'{m["numpy"]}, kernel {m["kernel"]}; {m["date"]}. Shared and noisy: medians and '
             'p99 from one run, ratios within that run.', '',
             '| figure | goal | measured | verdict | how |', '|---|---|---|---|---|']
    for figure, goal, measured, verdict, how in rows(results):
        lines.append(f'| {figure} | {goal} | {measured} | {verdict} | {how} |')
    lines += ['', 'Raw numbers: `out/bench/results.json` of the same run. Why the figures are '
              'what they are (py-spy profiles, what limits each missed goal, what would close '
              'it): [docs/PROFILING.md](docs/PROFILING.md).', '']
    return '\n'.join(lines)
