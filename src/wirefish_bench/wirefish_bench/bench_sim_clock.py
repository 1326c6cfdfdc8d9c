# SPDX-License-Identifier: Apache-2.0
"""
The virtual fish's clock, measured: the sweep old against new, and simulated time's cost.

- ``wirefish sweep`` (the paper's grid, Figs 9-11, with the virtual fish): the package before
  the grid's fish swam as schools (``SWEEP_COMMIT``) against today's, alternated ``repeats``
  times in fresh interpreters; wall and CPU time of ``run_sweep`` and the largest difference of
  a point's virtual-fish speed between the two (the figures must not move).
- One fish's whole graph (`wirefish up --sim` as registered, one process per node) on the
  wall clock (fish_sim without --speed: the road before) and on simulated time at
  ``--speed max`` (``graph.on_simulated_time``): simulated seconds per wall second (the
  real-time factor; 1 on the wall clock by construction) and the graph's CPU per simulated
  second.

``python -m wirefish_bench.bench_sim_clock [--repeats N] [--window S]`` prints JSON and the
rows BENCHMARKS.md keeps; ``--lockstep S`` only counts one graph's streams over S simulated
seconds at --speed 1 (``lockstep_counts``; pinned to a core beside two CPU hogs it shows a
starved graph computing the same experiment). Nothing here asserts: these are measurements.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
import json
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time

import numpy as np

SWEEP_COMMIT = 'ca0a4d8'  # before the sweep's grid swam as schools (fig11.run_steady_school)
DOMAIN = 87
NAMESPACE = '/bench_clock'
READY_TIMEOUT_S = 120.0

_SWEEP_SCRIPT = """
import json, resource, sys, time
from wirefish_analysis.sweep import run_sweep
started = time.monotonic()
grid, line = run_sweep()
wall = time.monotonic() - started
usage = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({'wall_s': wall, 'cpu_s': usage.ru_utime + usage.ru_stime,
                  'speeds': [p.fish_speed for p in grid + line]}))
"""


def sweep_old_new(repeats: int) -> dict:
    """Alternate the old and today's `wirefish sweep` computation; return both sides' runs."""
    from wirefish_bench.bench_old_new import old_package

    runs: dict[str, list[dict]] = {'old': [], 'new': []}
    with tempfile.TemporaryDirectory(prefix='wirefish_bench_sweep_') as tmp:
        old = old_package(SWEEP_COMMIT, 'wirefish_analysis', Path(tmp))
        for _ in range(repeats):
            for which in ('old', 'new'):
                env = dict(os.environ)
                if which == 'old':
                    env['PYTHONPATH'] = os.pathsep.join([old, env.get('PYTHONPATH', '')])
                out = subprocess.run([sys.executable, '-c', _SWEEP_SCRIPT], env=env,
                                     capture_output=True, text=True, check=True).stdout
                runs[which].append(json.loads(out.strip().splitlines()[-1]))
    difference = max(abs(a - b) for old_run in runs['old'] for new_run in runs['new']
                     for a, b in zip(old_run['speeds'], new_run['speeds']))
    result: dict = {which: {'wall_s': [r['wall_s'] for r in rs],
                            'cpu_s': [r['cpu_s'] for r in rs],
                            'median_wall_s': float(np.median([r['wall_s'] for r in rs]))}
                    for which, rs in runs.items()}
    result['largest_speed_difference_m_s'] = difference
    result['points'] = len(runs['new'][0]['speeds'])
    return result


def graph_clock(speed: str | None, window_s: float, domain_id: int = DOMAIN) -> dict:
    """One fish's graph on the wall clock (None) or at ``speed``: real-time factor, CPU."""
    import psutil
    import yaml
    from wirefish_bench.bench_graph import processes, ros_session, spin_for
    from wirefish_bringup.graph import (clock_topic, default_params_file, fish_graph,
                                        on_simulated_time, SIM_TIME_COMMAND_RATE_HZ)
    from rosgraph_msgs.msg import Clock

    specs = fish_graph(NAMESPACE, sim=True)
    directory = Path(tempfile.mkdtemp(prefix='wirefish_bench_clock_'))
    if speed is not None:
        # As `wirefish up` writes the run's parameters on simulated time (launcher).
        values = yaml.safe_load(default_params_file().read_text())
        values['/**/bridge_node']['ros__parameters']['max_command_rate_hz'] = float(
            SIM_TIME_COMMAND_RATE_HZ)
        params = directory / 'params.yaml'
        params.write_text(yaml.safe_dump(values))
        specs = [replace(s, params_file=str(params)) for s in
                 on_simulated_time(specs, speed)]
    latest: list[float] = []
    with processes(specs, domain_id, log_dir=directory) as supervisor, \
            ros_session(domain_id) as (node, spinner):
        from sensor_msgs.msg import Imu
        from rclpy.qos import qos_profile_sensor_data
        imu = [0]

        def on_imu(_msg) -> None:
            imu[0] += 1

        node.create_subscription(Imu, f'{NAMESPACE}/imu/data', on_imu, qos_profile_sensor_data)
        node.create_subscription(Clock, clock_topic(NAMESPACE), lambda m: latest.append(
            m.clock.sec + 1e-9 * m.clock.nanosec), 10)
        launched = time.monotonic()
        while time.monotonic() - launched < READY_TIMEOUT_S and imu[0] < 200:
            spin_for(spinner, 0.5)
        spin_for(spinner, 3.0)
        procs = [psutil.Process(p.pid) for p in supervisor.processes.values()]
        cpu_start = sum(sum(p.cpu_times()[:2]) for p in procs)
        sim_start = latest[-1] if latest else None
        started = time.monotonic()
        spin_for(spinner, window_s)
        wall = time.monotonic() - started
        cpu = sum(sum(p.cpu_times()[:2]) for p in procs) - cpu_start
        sim_end = latest[-1] if latest else None
    simulated = (sim_end - sim_start) if sim_start is not None and sim_end is not None else wall
    return {'speed': speed or 'wall clock', 'wall_s': wall, 'simulated_s': simulated,
            'real_time_factor': simulated / wall, 'cpu_s': cpu,
            'cpu_s_per_simulated_s': cpu / simulated, 'processes': len(procs)}


def lockstep_counts(simulated_s: float, speed: str = '1', domain_id: int = DOMAIN) -> dict:
    """
    One fish's graph on simulated time for ``simulated_s``: what came per simulated second.

    servo_cmd and imu/data are counted by their header stamps over ``simulated_s`` of the
    graph's clock, against their registry rates times that span; the clock's own steps are
    checked for gaps (a dropped step of simulated time). Run it pinned to a core beside CPU
    hogs to see that a starved graph runs slower, not differently.
    """
    import yaml
    from wirefish_bench.bench_graph import processes, ros_session, spin_for
    from wirefish_bringup.graph import (clock_topic, default_params_file, expected_rates,
                                        fish_graph, on_simulated_time,
                                        SIM_TIME_COMMAND_RATE_HZ)
    from rclpy.qos import qos_profile_sensor_data
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import Imu, JointState
    from wirefish_common.qos import reliable

    directory = Path(tempfile.mkdtemp(prefix='wirefish_bench_lockstep_'))
    values = yaml.safe_load(default_params_file().read_text())
    values['/**/bridge_node']['ros__parameters']['max_command_rate_hz'] = float(
        SIM_TIME_COMMAND_RATE_HZ)
    params = directory / 'params.yaml'
    params.write_text(yaml.safe_dump(values))
    specs = [replace(s, params_file=str(params))
             for s in on_simulated_time(fish_graph(NAMESPACE, sim=True), speed)]
    stamps: dict[str, list[float]] = {'servo_cmd': [], 'imu/data': []}
    steps: list[float] = []
    with processes(specs, domain_id, log_dir=directory), \
            ros_session(domain_id) as (node, spinner):
        for topic, msg_type in (('servo_cmd', JointState), ('imu/data', Imu)):
            node.create_subscription(
                msg_type, f'{NAMESPACE}/{topic}', lambda m, t=topic: stamps[t].append(
                    m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec), qos_profile_sensor_data)
        node.create_subscription(Clock, clock_topic(NAMESPACE), lambda m: steps.append(
            m.clock.sec + 1e-9 * m.clock.nanosec), reliable(1000))
        launched = time.monotonic()
        while time.monotonic() - launched < READY_TIMEOUT_S and len(stamps['servo_cmd']) < 200:
            spin_for(spinner, 0.5)
        start = steps[-1] + 1.0
        wall_start = time.monotonic()
        while not steps or steps[-1] < start + simulated_s + 1.0:
            spin_for(spinner, 0.5)
        wall = time.monotonic() - wall_start
    nominal = expected_rates(sim=True)[0]
    window = [t for t in sorted(set(steps)) if start <= t <= start + simulated_s]
    gaps = [round(b - a, 4) for a, b in zip(window, window[1:]) if b - a > 0.0101]
    counts = {topic: sum(start <= t < start + simulated_s for t in values)
              for topic, values in stamps.items()}
    return {'speed': speed, 'simulated_s': simulated_s, 'wall_s': wall,
            'real_time_factor': simulated_s / wall,
            'clock_gaps': gaps, 'clock_steps': len(window),
            **{f'{topic}_count': count for topic, count in counts.items()},
            **{f'{topic}_expected': nominal[topic] * simulated_s for topic in counts},
            **{f'{topic}_error_percent': 100.0 * (count / (nominal[topic] * simulated_s) - 1.0)
               for topic, count in counts.items()}}


def markdown(sweep: dict, wall: dict, fast: dict) -> str:
    """Return the rows BENCHMARKS.md keeps of one run."""
    old, new = sweep['old'], sweep['new']
    return '\n'.join([
        '| measurement | old | new |',
        '|---|---|---|',
        f"| `wirefish sweep` ({sweep['points']} points, virtual fish), wall s, median of "
        f"{len(old['wall_s'])} alternated | {old['median_wall_s']:.1f} | "
        f"{new['median_wall_s']:.1f} ({new['median_wall_s'] / old['median_wall_s']:.2f} of old; "
        f"largest speed difference {sweep['largest_speed_difference_m_s']:.1e} m/s) |",
        f'| `wirefish sweep`, CPU s of the computation | '
        f"{', '.join(f'{c:.1f}' for c in old['cpu_s'])} | "
        f"{', '.join(f'{c:.1f}' for c in new['cpu_s'])} |",
        f"| one fish's graph: simulated s per wall s | {wall['real_time_factor']:.2f} (wall "
        f"clock) | {fast['real_time_factor']:.2f} (--speed max) |",
        f"| one fish's graph: CPU s per simulated s ({wall['processes']} processes) | "
        f"{wall['cpu_s_per_simulated_s']:.2f} (wall clock) | "
        f"{fast['cpu_s_per_simulated_s']:.2f} (--speed max) |"])


def main(argv: list[str] | None = None) -> int:
    """Measure, print the JSON and the markdown rows."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeats', type=int, default=2, help='alternations of the sweep')
    parser.add_argument('--window', type=float, default=20.0, help='wall s per graph figure')
    parser.add_argument('--lockstep', type=float, default=None, metavar='S',
                        help='only this: one graph at --speed 1 for S simulated seconds, '
                        'servo_cmd and imu/data counted by their stamps (lockstep_counts)')
    args = parser.parse_args(argv)
    if args.lockstep is not None:
        print(json.dumps(lockstep_counts(args.lockstep), indent=1))
        return 0
    load = os.getloadavg()[0]
    sweep = sweep_old_new(args.repeats)
    wall = graph_clock(None, args.window)
    fast = graph_clock('max', args.window)
    print(json.dumps({'load_average_before': load, 'sweep': sweep, 'wall_clock': wall,
                      'speed_max': fast}, indent=1))
    print(markdown(sweep, wall, fast))
    print(f'(load average {load:.1f} before the run)')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
