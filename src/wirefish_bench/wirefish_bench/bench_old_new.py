# SPDX-License-Identifier: Apache-2.0
"""
Four levers of the fish's CPU and timing, the old source against today's in one run.

- The CPG's period error at the source at its default rate (100 Hz, events executor): cpg_node
  of the package before the loop thread's real-time scheduling (``CPG_COMMIT``) and today's,
  alternated ``repeats`` times (``bench_graph.cpg_rate``); medians.
- The virtual fish of an 8-fish fleet: 8 fish_sim processes of the package before the fleet
  simulator (``SIM_COMMIT``) against one of today's fish_sim simulating all 8, side by side in
  the same window, no host (the firmware in failsafe, the physics and telemetry running).
- kinematics_node's servo intake: a callback per sample beside its 50 Hz tick (before) against
  the tick taking a batch (today), and the bridge's: a servo pair read from each message
  against from the raw bytes; subscriber CPU at 200 Hz (``message_cost``'s probes).
- planner_node's imu/data intake: a callback per sample (``PLANNER_COMMIT``) against its
  control tick taking a batch (today), in one fish's whole graph (``bench_graph.fleet``, one
  process per node, events), alternated ``repeats`` times: the planner's CPU and the onboard
  graph's; medians.

Old packages come from git (``git archive``), first on their process's PYTHONPATH. Nothing here
asserts: these are measurements.
"""

from __future__ import annotations

from collections.abc import Callable
import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np
from wirefish_common.executors import ExecutorKind

CPG_COMMIT = '821c50c'  # before FixedRateLoop's SCHED_FIFO and GIL switch interval
SIM_COMMIT = 'de0bafa'  # before fish_sim simulated N fish in one process
PLANNER_COMMIT = '254dba5'  # before the planner took imu/data in batches at its control tick
DEFAULT_RATE_HZ = 100.0  # servo_cmd's default
FLEET = 8
WINDOW_S = 10.0
WARM_UP_S = 5.0
CPG_GOAL_MS = 0.2


def _workspace() -> Path:
    return Path(__file__).resolve().parents[3]


def old_package(commit: str, package: str, into: Path) -> str:
    """Extract ``src/<package>/<package>`` at ``commit`` into ``into``; return its path entry."""
    path = f'src/{package}/{package}'
    archive = subprocess.run(['git', '-C', str(_workspace()), 'archive', commit, path],
                             capture_output=True, check=True).stdout
    subprocess.run(['tar', '-x', '-C', str(into)], input=archive, check=True)
    return str(into / 'src' / package)


def _with_path(entry: str | None) -> dict[str, str]:
    env = dict(os.environ)
    if entry:
        env['PYTHONPATH'] = os.pathsep.join([entry, env.get('PYTHONPATH', '')])
    return env


def _alternated(commit: str, package: str, repeats: int,
                measure: Callable[[], dict]) -> dict[str, list[dict]]:
    """Run ``measure`` ``repeats`` times with ``package`` at ``commit`` and today's, alternated."""
    runs: dict[str, list[dict]] = {'old': [], 'new': []}
    saved = os.environ.get('PYTHONPATH', '')
    with tempfile.TemporaryDirectory(prefix=f'wirefish_bench_{package}_') as tmp:
        old = old_package(commit, package, Path(tmp))
        try:
            for _ in range(repeats):
                for which in ('old', 'new'):
                    # the measured node processes inherit this environment
                    os.environ['PYTHONPATH'] = (os.pathsep.join([old, saved])
                                                if which == 'old' else saved)
                    runs[which].append(measure())
        finally:
            os.environ['PYTHONPATH'] = saved
    return runs


def cpg_period_error(repeats: int, domain_id: int) -> dict:
    """Alternate the old and the new cpg_node at 100 Hz (events); return each one's runs."""
    from wirefish_bench import bench_graph

    runs = _alternated(CPG_COMMIT, 'wirefish_cpg', repeats, lambda: bench_graph.cpg_rate(
        DEFAULT_RATE_HZ, WINDOW_S, domain_id, ExecutorKind.EVENTS))
    return {which: {'source_p99_ms': [r['source_period_error_p99_ms'] for r in rs],
                    'source_p50_ms': [r['source_period_error_p50_ms'] for r in rs],
                    'median_source_p99_ms': float(np.median(
                        [r['source_period_error_p99_ms'] for r in rs])),
                    'cpu_percent': [r['cpu_percent'] for r in rs]}
            for which, rs in runs.items()}


def planner_intake(repeats: int, domain_id: int) -> dict:
    """Alternate one fish's graph with the old and the new planner_node; return their runs."""
    from wirefish_bench import bench_graph

    runs = _alternated(PLANNER_COMMIT, 'wirefish_planner', repeats, lambda: bench_graph.fleet(
        1, WINDOW_S, domain_id, False, ExecutorKind.EVENTS))

    def planner_cpu(run: dict) -> float:
        return next(cpu for name, cpu in run['cpu_percent_by_process'].items()
                    if 'planner' in name)
    return {which: {'planner_cpu_percent': [planner_cpu(r) for r in rs],
                    'onboard_cpu_percent': [r['onboard_cpu_percent_per_fish'] for r in rs],
                    'imu_hz_min': [r['imu_hz_min'] for r in rs],
                    'median_planner_cpu_percent': float(np.median([planner_cpu(r) for r in rs])),
                    'median_onboard_cpu_percent': float(np.median(
                        [r['onboard_cpu_percent_per_fish'] for r in rs]))}
            for which, rs in runs.items()}


def _cpu_s(pids: list[int]) -> float:
    import psutil

    return sum(sum(psutil.Process(pid).cpu_times()[:2]) for pid in pids)


def simulators() -> dict:
    """Return the CPU of 8 old fish_sim processes and of one new fish_sim of 8 fish at once."""
    with tempfile.TemporaryDirectory(prefix='wirefish_bench_sim_') as tmp:
        old_env = _with_path(old_package(SIM_COMMIT, 'wirefish_sim', Path(tmp)))

        def start(links: list[str], env: dict) -> subprocess.Popen:
            args = [a for link in links for a in ('--link', link)]
            return subprocess.Popen([sys.executable, '-m', 'wirefish_sim.fish_sim', *args],
                                    env=env, stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL, start_new_session=True)
        old = [start([f'{tmp}/old_{i}'], old_env) for i in range(FLEET)]
        new = start([f'{tmp}/new_{i}' for i in range(FLEET)], dict(os.environ))
        procs = [*old, new]
        try:
            time.sleep(WARM_UP_S)
            old_start, new_start = _cpu_s([p.pid for p in old]), _cpu_s([new.pid])
            time.sleep(WINDOW_S)
            old_cpu = 100.0 * (_cpu_s([p.pid for p in old]) - old_start) / WINDOW_S
            new_cpu = 100.0 * (_cpu_s([new.pid]) - new_start) / WINDOW_S
        finally:
            for proc in procs:
                if proc.poll() is None:
                    os.killpg(proc.pid, signal.SIGINT)
            for proc in procs:
                try:
                    proc.wait(10.0)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()
    return {'fish': FLEET, 'old_cpu_percent': old_cpu, 'new_cpu_percent': new_cpu,
            'ratio': new_cpu / old_cpu if old_cpu else float('nan')}


def intakes() -> dict:
    """Return each servo intake's subscriber CPU, old and new: message_cost at 200 Hz."""
    from wirefish_bench import message_cost

    probes = {**message_cost.run(WINDOW_S, only='tick')['probes'],
              **message_cost.run(WINDOW_S, only='servo pair')['probes']}
    return {name: p['cpu_percent'][-1] for name, p in probes.items()}  # the subscriber's


def run(repeats: int = 3, domain_id: int = 92) -> dict:
    """Run the four comparisons; return their figures (the bench's JSON)."""
    return {'cpg': cpg_period_error(repeats, domain_id), 'simulators': simulators(),
            'intakes': intakes(), 'planner': planner_intake(repeats, domain_id)}


def rows(result: dict) -> list[tuple[str, str, str, str, str]]:
    """Return the BENCHMARKS.md rows: (figure, goal, measured, verdict, how)."""
    if 'error' in result:
        return [('Old vs new source: CPG timing, virtual fish, servo intakes', '',
                 result['error'], 'not measured', '')]
    cpg, sim, intake = result['cpg'], result['simulators'], result['intakes']

    def runs(values: list[float]) -> str:
        return ' / '.join(f'{v:.2f}' for v in values)
    new_p99 = cpg['new']['median_source_p99_ms']
    table = [(
        'CPG period error at the source, p99, at the default rate (100 Hz, events): old vs new',
        f'≤ {CPG_GOAL_MS:g} ms',
        f'old {cpg["old"]["median_source_p99_ms"]:.3f} ms (runs '
        f'{runs(cpg["old"]["source_p99_ms"])}), new {new_p99:.3f} ms (runs '
        f'{runs(cpg["new"]["source_p99_ms"])}); CPU old '
        f'{runs(cpg["old"]["cpu_percent"])} %, new {runs(cpg["new"]["cpu_percent"])} %',
        'met' if new_p99 <= CPG_GOAL_MS else 'missed',
        f'bench_graph.cpg_rate, 10 s each, old and new alternated; old = src/wirefish_cpg at '
        f'{CPG_COMMIT} from git (bench_old_new.py); medians')]
    table.append((
        f'Virtual fish of a fleet of {sim["fish"]}, CPU (% of a core): {sim["fish"]} old '
        'fish_sim processes vs one new fish_sim of all', '— (a fleet run measures the stack)',
        f'old {sim["old_cpu_percent"]:.1f} %, new {sim["new_cpu_percent"]:.1f} % (ratio '
        f'{sim["ratio"]:.2f})', '—',
        f'both at once, no host, psutil over {WINDOW_S:g} s after {WARM_UP_S:g} s; old = '
        f'src/wirefish_sim at {SIM_COMMIT} from git'))
    tick, batch = (intake.get('a callback per message and a 50 Hz tick'),
                   intake.get('a 50 Hz tick taking a batch'))
    msg, raw = (intake.get('servo pair read from each message'),
                intake.get('servo pair read from the raw bytes'))
    table.append((
        'Servo intakes at 200 Hz, subscriber CPU (% of a core): a callback per sample vs a '
        'tick taking a batch (kinematics), the pair from the message vs from the raw bytes '
        '(bridge)', '—',
        f'kinematics: old {tick:.2f} %, new {batch:.2f} %; bridge: old {msg:.2f} %, new '
        f'{raw:.2f} %', '—',
        'python -m wirefish_bench.message_cost probes (one process each, events executor, '
        f'{WINDOW_S:g} s after 4 s)'))
    planner = result.get('planner')
    if planner is not None:
        table.append((
            "planner_node's imu/data intake in one fish's graph, CPU (% of a core): a callback "
            'per sample vs the control tick taking a batch', '—',
            f'planner old {planner["old"]["median_planner_cpu_percent"]:.2f} % (runs '
            f'{runs(planner["old"]["planner_cpu_percent"])}), new '
            f'{planner["new"]["median_planner_cpu_percent"]:.2f} % (runs '
            f'{runs(planner["new"]["planner_cpu_percent"])}); onboard old '
            f'{planner["old"]["median_onboard_cpu_percent"]:.1f} %, new '
            f'{planner["new"]["median_onboard_cpu_percent"]:.1f} %', '—',
            f'bench_graph.fleet of 1 fish, one process per node, events, {WINDOW_S:g} s '
            f'windows, old and new alternated; old = src/wirefish_planner at {PLANNER_COMMIT} '
            'from git; medians'))
    return table


def main(argv: list[str] | None = None) -> int:
    """Print the JSON of ``run``."""
    print(json.dumps(run(), indent=2))
    return 0


if __name__ == '__main__':
    sys.exit(main())
