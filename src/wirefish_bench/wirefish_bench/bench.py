"""
`make bench`: run every benchmark once and rewrite BENCHMARKS.md (+ out/bench/results.json).

Figures are medians (and p99 where latency) from one run on this machine; goals come from the
project's issues. A benchmark that fails is reported as such, never left out.
"""

import argparse
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
from wirefish_bench.bench_report import EXECUTORS

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
            'date': datetime.now(timezone.utc).strftime('%Y-%m-%d %H:%M UTC'),
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


def run_all(quick: bool = False) -> dict:
    """Run every benchmark; ``quick`` shortens the windows (for trying the harness)."""
    from wirefish_bench import bench_graph

    scale = 0.2 if quick else 1.0
    results: dict = {'machine': machine()}
    results['cpg_rate'] = [_run(f'cpg at {r} Hz ({e})', bench_graph.cpg_rate, r, 10.0 * scale,
                                DOMAIN, e)
                           for r in (100.0, 200.0, 500.0, 1000.0) for e in EXECUTORS]
    try:
        from wirefish_bench import bench_links
        results['links_by_executor'] = {
            e: _run(f'command/telemetry latency ({e})', bench_links.run, domain_id=DOMAIN,
                    executor=e)
            for e in EXECUTORS}
    except ImportError as error:
        results['links_by_executor'] = {e: {'error': f'not available: {error}'}
                                        for e in EXECUTORS}
    try:
        from wirefish_bench import bench_retune
        results['retune'] = _run('retune', bench_retune.run)
        # The same wave again comes from the gait library; the default gait family.
        results['retune_library'] = _run('retune answered from the library',
                                         bench_retune.library_answer, domain_id=DOMAIN)
        results['gaits_build'] = _run('wirefish gaits build', bench_retune.gaits_build)
    except ImportError as error:
        results['retune'] = {'error': f'not available: {error}'}
    from wirefish_bench import bench_radio_link
    # What crosses fish -> shore, two network namespaces (root only; else the reason).
    results['radio_link'] = _run('radio link', bench_radio_link.run, domain_id=DOMAIN)
    from wirefish_bench import bench_firmware  # cycles per frame, flash and RAM
    results['firmware'] = _run('firmware cycles and size', bench_firmware.run)
    results['kinematics_cpu'] = [
        _run(f'kinematics {s} x {r} ({e})', bench_graph.kinematics_cpu, s, r, 10.0 * scale,
             DOMAIN, e)
        for s, r in ((50, 50.0), (500, 200.0)) for e in EXECUTORS]
    results['recording'] = _run('recording', recording, 60.0 * scale, DOMAIN)
    from wirefish_bench import bench_recorder  # the recorder before and after its mcap rewrite
    results['recorder_cpu'] = _run('recorder CPU, old and new', bench_recorder.run, DOMAIN)
    from wirefish_bench import bench_view  # the view server with one browser connected
    results['view_cpu'] = _run('view server with one browser', bench_view.run, DOMAIN)
    from wirefish_bench import bench_old_new  # CPG timing, virtual fish, intakes: old vs new
    results['old_new'] = _run('old vs new: CPG timing, virtual fish, servo intakes',
                              bench_old_new.run, domain_id=DOMAIN)
    results['fleet'] = []
    for mode in ('per-node', 'single'):
        one = _run(f'1 fish ({mode}, both executors, {ONE_FISH_REPEATS} alternated runs)',
                   one_fish, ONE_FISH_REPEATS, 10.0 * scale, DOMAIN, mode == 'single')
        results['fleet'] += one if isinstance(one, list) else [one]
        results['fleet'] += [_run(f'{n} fish ({mode}, {e})', bench_graph.fleet, n, 10.0 * scale,
                                  DOMAIN, mode == 'single', e)
                             for n in (2, 4, 8) for e in EXECUTORS]
    return results


def main(argv: list[str] | None = None) -> int:
    """Run the benchmarks, write the JSON and BENCHMARKS.md."""
    from wirefish_bench.bench_report import kept_history, render_markdown

    parser = argparse.ArgumentParser(prog='wirefish-bench', description=__doc__.strip())
    parser.add_argument('--quick', action='store_true', help='short windows (harness check)')
    parser.add_argument('--out', type=Path, default=WORKSPACE / 'out' / 'bench')
    parser.add_argument('--markdown', type=Path, default=WORKSPACE / 'BENCHMARKS.md')
    args = parser.parse_args(argv)
    results = run_all(quick=args.quick)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / 'results.json').write_text(json.dumps(results, indent=2, default=str))
    previous = args.markdown.read_text() if args.markdown.exists() else ''
    args.markdown.write_text(render_markdown(results, kept_history(previous)))
    print(f'wrote {args.markdown} and {args.out / "results.json"}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
