# SPDX-License-Identifier: Apache-2.0
"""
`make bench`: run every benchmark once and rewrite BENCHMARKS.md (+ out/bench/results.json).

`make bench ONLY=firmware,sim-clock` (--only) runs the named sections and rewrites their rows,
keeping every other row of BENCHMARKS.md as its run wrote it; the header lists each run.

Figures are medians (and p99 where latency) from one run on this machine; goals come from the
project's issues. A benchmark that fails is reported as such, never left out.
"""

import argparse
from collections.abc import Callable, Iterable
from datetime import datetime, timezone
import json
import os
from pathlib import Path
import platform
import re
import subprocess
import sys
import tempfile
import traceback

import numpy as np
from wirefish_bench.bench_report import (EXECUTORS, kept_history, merge_markdown, MergeError,
                                         parse_markdown, render_markdown, Section)

WORKSPACE = Path(__file__).resolve().parents[3] if (
    Path(__file__).resolve().parents[3] / 'Makefile').is_file() else Path.cwd()
DOMAIN = int(os.environ.get('WIREFISH_BENCH_DOMAIN', '101'))
# The 1-fish rows (the onboard-CPU verdict) are the median of this many alternated runs.
ONE_FISH_REPEATS = 3


def machine() -> dict:
    """Describe the machine the figures come from."""
    cpu = platform.processor() or 'unknown CPU'
    try:
        for line in Path('/proc/cpuinfo').read_text().splitlines():
            if line.startswith('model name'):
                cpu = line.split(':', 1)[1].strip()
                break
    except OSError:
        pass
    return {'cpu': cpu, 'cores': os.cpu_count(), 'python': platform.python_version(),
            'numpy': np.__version__, 'kernel': platform.release(),
            # The run's key in BENCHMARKS.md: to the second, so two runs never share one.
            'date': datetime.now(timezone.utc).strftime('%Y-%m-%d %H:%M:%S UTC'),
            # Other users' load moves every figure on a shared machine: say how busy it was.
            'load_average_1min': os.getloadavg()[0]}


def recording(duration_s: float, domain_id: int) -> dict:
    """Run the whole graph with `wirefish up --duration`, then count what reached the bag."""
    from wirefish_bag.report import write_report

    out = Path(tempfile.mkdtemp(prefix='wirefish_bench_rec_'))
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    subprocess.run([sys.executable, '-m', 'wirefish_cli.cli', 'up', '--sim', '--no-status',
                    '--duration', str(duration_s), '--out', str(out), '--namespace',
                    '/bench_rec'], env=env, check=True, capture_output=True,
                   timeout=duration_s + 120)
    bag = next(out.glob('run_*/bag'))
    stats = write_report(bag, bag.parent / 'report')
    # The supervisor names each log after its registry entry (wirefish_recorder.log).
    recorder_log = next((bag.parent / 'logs').glob('*recorder*.log')).read_text()
    missing = re.search(r"missing from the publishers' sequences: (\d+)", recorder_log)
    return {'duration_s': duration_s,
            'topics': {s.topic: {'count': s.count, 'rate_hz': s.rate_hz, 'drops': s.drops}
                       for s in stats},
            'messages': sum(s.count for s in stats),
            'missing_from_sequences': int(missing.group(1)) if missing else None,
            'skipped_ticks': sum(max(s.drops, 0) for s in stats)}


def one_fish(repeats: int, duration_s: float, domain_id: int, single_process: bool) -> list[dict]:
    """
    Run the 1-fish fleet ``repeats`` times per executor, alternated; return each one's median.

    One 10 s window moved by 10-20 % between runs on this shared machine, enough to turn the
    onboard-CPU verdict (the ratio of the two executors); the median of alternated windows
    does not drift with the load of the moment. The median run carries every run's figure.
    """
    from wirefish_bench import bench_graph

    runs: dict[str, list[dict]] = {e: [] for e in EXECUTORS}
    for _ in range(repeats):
        for executor in EXECUTORS:
            runs[executor].append(bench_graph.fleet(1, duration_s, domain_id, single_process,
                                                    executor))
    medians = []
    for results in runs.values():
        ordered = sorted(results, key=lambda r: r['onboard_cpu_percent_per_fish'])
        median = dict(ordered[len(ordered) // 2])
        median['onboard_cpu_percent_runs'] = [r['onboard_cpu_percent_per_fish'] for r in results]
        medians.append(median)
    return medians


def _run(name: str, func, *args, **kwargs):
    print(f'bench: {name} ...', flush=True)
    try:
        return func(*args, **kwargs)
    except Exception as error:  # a failed benchmark is a figure too: say what failed
        traceback.print_exc()
        return {'error': f'{type(error).__name__}: {error}'}


def _cpg_rate(scale: float) -> dict:
    from wirefish_bench import bench_graph
    return {'cpg_rate': [_run(f'cpg at {r} Hz ({e})', bench_graph.cpg_rate, r, 10.0 * scale,
                              DOMAIN, e)
                         for r in (100.0, 200.0, 500.0, 1000.0) for e in EXECUTORS]}


def _links(scale: float) -> dict:
    try:
        from wirefish_bench import bench_links
    except ImportError as error:
        return {'links_by_executor': {e: {'error': f'not available: {error}'}
                                      for e in EXECUTORS}}
    return {'links_by_executor': {
        e: _run(f'command/telemetry latency ({e})', bench_links.run, domain_id=DOMAIN,
                executor=e)
        for e in EXECUTORS}}


def _retune(scale: float) -> dict:
    try:
        from wirefish_bench import bench_retune
    except ImportError as error:
        return {'retune': {'error': f'not available: {error}'}}
    return {'retune': _run('retune', bench_retune.run),
            # The same wave again comes from the gait library; the default gait family.
            'retune_library': _run('retune answered from the library',
                                   bench_retune.library_answer, domain_id=DOMAIN),
            'gaits_build': _run('wirefish gaits build', bench_retune.gaits_build)}


def _radio_link(scale: float) -> dict:
    from wirefish_bench import bench_radio_link
    # What crosses fish -> shore, two network namespaces (root only; else the reason).
    return {'radio_link': _run('radio link', bench_radio_link.run, domain_id=DOMAIN)}


def _firmware(scale: float) -> dict:
    from wirefish_bench import bench_firmware  # cycles per frame and CPG step, flash and RAM
    return {'firmware': _run('firmware cycles, CPG step and size', bench_firmware.run)}


def _kinematics(scale: float) -> dict:
    from wirefish_bench import bench_graph
    return {'kinematics_cpu': [
        _run(f'kinematics {s} x {r} ({e})', bench_graph.kinematics_cpu, s, r, 10.0 * scale,
             DOMAIN, e)
        for s, r in ((50, 50.0), (500, 200.0)) for e in EXECUTORS]}


def _recording(scale: float) -> dict:
    return {'recording': _run('recording', recording, 60.0 * scale, DOMAIN)}


def _recorder(scale: float) -> dict:
    from wirefish_bench import bench_recorder  # the recorder before and after its mcap rewrite
    return {'recorder_cpu': _run('recorder CPU, old and new', bench_recorder.run, DOMAIN)}


def _view(scale: float) -> dict:
    from wirefish_bench import bench_view  # the view server with one browser connected
    return {'view_cpu': _run('view server with one browser', bench_view.run, DOMAIN)}


def _old_new(scale: float) -> dict:
    from wirefish_bench import bench_old_new  # CPG timing, virtual fish, intakes: old vs new
    return {'old_new': _run('old vs new: CPG timing, virtual fish, servo intakes',
                            bench_old_new.run, domain_id=DOMAIN)}


def _sim_clock(scale: float) -> dict:
    from wirefish_bench import bench_sim_clock  # the sweep old vs new, simulated time's cost
    window = 20.0 * scale
    return {'sim_clock': {
        'sweep': _run('sim clock: wirefish sweep, old vs new', bench_sim_clock.sweep_old_new,
                      2 if scale >= 1.0 else 1),
        'wall_clock': _run("sim clock: one fish's graph on the wall clock",
                           bench_sim_clock.graph_clock, None, window, DOMAIN),
        'speed_max': _run("sim clock: one fish's graph at --speed max",
                          bench_sim_clock.graph_clock, 'max', window, DOMAIN)}}


def _fleet(scale: float) -> dict:
    from wirefish_bench import bench_graph
    fleet: list = []
    for mode in ('per-node', 'single'):
        one = _run(f'1 fish ({mode}, both executors, {ONE_FISH_REPEATS} alternated runs)',
                   one_fish, ONE_FISH_REPEATS, 10.0 * scale, DOMAIN, mode == 'single')
        fleet += one if isinstance(one, list) else [one]
        fleet += [_run(f'{n} fish ({mode}, {e})', bench_graph.fleet, n, 10.0 * scale, DOMAIN,
                       mode == 'single', e)
                  for n in (2, 4, 8) for e in EXECUTORS]
    return {'fleet': fleet}


# Each section of a run: what --help says of it, and what runs it (given the windows' scale).
SECTIONS: dict[Section, tuple[str, Callable[[float], dict]]] = {
    Section.CPG_RATE: ('the CPG node at 100-1000 Hz, both executors: rate, period error, CPU',
                       _cpg_rate),
    Section.LINKS: ('servo_cmd -> frame and telemetry -> imu/data latency through bridge_node',
                    _links),
    Section.RETUNE: ('the §5.2 retune vs pyswarms, the gait library answer, gaits build',
                     _retune),
    Section.RADIO_LINK: ('bytes/s crossing the fish-shore link, two network namespaces (root)',
                         _radio_link),
    Section.FIRMWARE: ('firmware cycles (frames, CPG step), the CPG step on the M4, flash, RAM',
                       _firmware),
    Section.KINEMATICS: ('kinematics_node CPU at two sizes, both executors', _kinematics),
    Section.RECORDING: ('60 s of wirefish up --duration: messages in the bag, lost',
                        _recording),
    Section.RECORDER: ("the recorder's CPU, old vs new", _recorder),
    Section.VIEW: ('the view server with one browser on the dashboard', _view),
    Section.OLD_NEW: ('CPG timing, virtual fish, servo and planner intakes: old vs new',
                      _old_new),
    Section.SIM_CLOCK: ('the sweep old vs new; one graph at --speed max vs the wall clock',
                        _sim_clock),
    Section.FLEET: ('1 to 8 fish, a process per node and per fish, both executors', _fleet),
}


def run_all(quick: bool = False, sections: Iterable[Section] | None = None) -> dict:
    """
    Run the benchmarks of ``sections`` (every one when None) in run_all's order.

    ``quick`` shortens the windows (for trying the harness).
    """
    chosen = set(SECTIONS if sections is None else sections)
    results: dict = {'machine': machine(), 'quick': quick,
                     'sections': [s.value for s in SECTIONS if s in chosen]}
    for section, (_, runner) in SECTIONS.items():
        if section in chosen:
            results.update(runner(0.2 if quick else 1.0))
    return results


def parse_sections(text: str) -> list[Section]:
    """Return the sections a comma-separated ``text`` names, in run_all's order."""
    names = [name.strip() for name in text.split(',') if name.strip()]
    known = {section.value: section for section in SECTIONS}
    unknown = [name for name in names if name not in known]
    if not names or unknown:
        raise argparse.ArgumentTypeError(
            (f'unknown section {", ".join(map(repr, unknown))}' if unknown else 'no section')
            + f' (the sections: {", ".join(known)})')
    return [section for section in SECTIONS if section.value in names]


def main(argv: list[str] | None = None) -> int:
    """Run the benchmarks, write the JSON and BENCHMARKS.md."""
    parser = argparse.ArgumentParser(
        prog='wirefish-bench', description=__doc__.strip(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog='sections, in the order a run takes them:\n' + '\n'.join(
            f'  {section.value:<12} {text}' for section, (text, _) in SECTIONS.items()))
    parser.add_argument('--quick', action='store_true', help='short windows (harness check)')
    parser.add_argument('--only', type=parse_sections, metavar='SECTION[,SECTION...]',
                        help='run these sections only and rewrite their rows of BENCHMARKS.md, '
                        'keeping every other row as it is (make bench ONLY=...)')
    parser.add_argument('--out', type=Path, default=WORKSPACE / 'out' / 'bench')
    parser.add_argument('--markdown', type=Path, default=WORKSPACE / 'BENCHMARKS.md')
    args = parser.parse_args(argv)
    previous = args.markdown.read_text() if args.markdown.exists() else ''
    try:
        # Before anything runs: a file whose rows cannot be kept stops here, untouched.
        kept = parse_markdown(previous) if args.only else None
    except MergeError as error:
        print(f'wirefish-bench: {args.markdown}: {error}', file=sys.stderr)
        return 1
    results = run_all(quick=args.quick, sections=args.only)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / 'results.json').write_text(json.dumps(results, indent=2, default=str))
    try:
        text = (render_markdown(results, kept_history(previous)) if kept is None
                else merge_markdown(kept, results))
    except MergeError as error:
        print(f'wirefish-bench: {args.markdown} left as it was: {error}', file=sys.stderr)
        return 1
    args.markdown.write_text(text)
    print(f'wrote {args.markdown} and {args.out / "results.json"}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
