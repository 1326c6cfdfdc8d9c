# SPDX-License-Identifier: Apache-2.0
"""
Benchmarks of the running graph: publish-rate jitter, node CPU, recording loss, many fish.

Each function starts real node processes (own ROS domain), measures from the receiving side
and returns plain figures; `wirefish_bench.bench` runs them all and writes BENCHMARKS.md.
``executor`` ('events' or 'classic', None: the nodes' default) is passed to the node
processes as WIREFISH_EXECUTOR, so one run measures both side by side.
Nothing here asserts: these are measurements, not tests.
"""

from contextlib import contextmanager
import os
from pathlib import Path
import tempfile
import time

import numpy as np
import psutil

from wirefish_bringup.graph import fish_graph, NodeSpec
from wirefish_common.executors import EXECUTOR_VARIABLE, ExecutorKind, make_executor
from wirefish_launcher.supervisor import Supervisor, wait_for_path

READY_TIMEOUT_S = 60.0


def percentiles_ms(values_s: np.ndarray) -> dict[str, float]:
    """Return p50, p99 and max of ``values_s`` in milliseconds."""
    if len(values_s) == 0:
        return {'p50_ms': float('nan'), 'p99_ms': float('nan'), 'max_ms': float('nan')}
    return {'p50_ms': float(np.percentile(values_s, 50) * 1e3),
            'p99_ms': float(np.percentile(values_s, 99) * 1e3),
            'max_ms': float(np.max(values_s) * 1e3)}


@contextmanager
def ros_session(domain_id: int, executor_kind: str | None = None):
    """
    Yield (node, executor) of a benchmark-side rclpy context on ``domain_id``.

    The benchmark's own receiver spins on the executor of the graph it measures (``events``
    unless ``executor_kind`` says ``classic``), as a node of that graph would: a Python
    executor's wake-up on the receiving side (a few hundred us) is part of what a classic
    graph costs, not of what an events graph costs. A receiver always on the classic executor
    would put its own wake-ups into both rows' receiver figures.
    """
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    node = rclpy.create_node('wirefish_bench', context=context)
    executor = make_executor(executor_kind or ExecutorKind.EVENTS, context=context)
    executor.add_node(node)
    try:
        yield node, executor
    finally:
        executor.remove_node(node)
        node.destroy_node()
        executor.shutdown()
        rclpy.try_shutdown(context=context)


@contextmanager
def processes(specs: list[NodeSpec], domain_id: int, log_dir: Path | None = None,
              executor: str | None = None):
    """
    Start ``specs`` on ``domain_id``; yield the Supervisor; stop them all afterwards.

    The processes get the environment `wirefish up` gives a graph on this machine (the
    workspace's Fast DDS profile: UDPv4 on loopback under LOCALHOST), so a figure measures
    the graph as users run it.
    """
    from wirefish_bringup.dds_profile import graph_environment, write_profile

    log_dir = log_dir or Path(tempfile.mkdtemp(prefix='wirefish_bench_'))
    env, own_profile = graph_environment(
        dict(os.environ, ROS_DOMAIN_ID=str(domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST'),
        {s.namespace for s in specs if s.namespace}, log_dir)
    write_profile(env, own_profile)
    if executor is not None:
        env[EXECUTOR_VARIABLE] = executor
    supervisor = Supervisor(log_dir, env=env)
    try:
        for spec in specs:
            proc = supervisor.start(spec)  # removes a stale device link first
            for link in spec.links:
                wait_for_path(link, [proc], 15.0)
        yield supervisor
    finally:
        supervisor.stop()


def cpu_percent(pids: list[int], window_s: float) -> dict[int, float]:
    """Return each process's CPU use over ``window_s`` seconds, in % of one core."""
    procs = {pid: psutil.Process(pid) for pid in pids}
    start = {pid: p.cpu_times() for pid, p in procs.items()}
    time.sleep(window_s)
    result = {}
    for pid, p in procs.items():
        end = p.cpu_times()
        used = (end.user + end.system) - (start[pid].user + start[pid].system)
        result[pid] = 100.0 * used / window_s
    return result


def spin_for(executor, seconds: float) -> None:
    """Spin ``executor`` for ``seconds`` of wall time."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)


def cpg_rate(rate_hz: float, duration_s: float, domain_id: int,
             executor: str | None = None) -> dict:
    """CPG node at ``rate_hz``: achieved rate, period error at the source and receiver, CPU."""
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState

    spec = NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node',
                    ('--ros-args', '-p', f'publish_rate_hz:={rate_hz}'))
    arrivals: list[int] = []
    stamps: list[int] = []  # header stamps: when the CPG published (the source side)

    def on_servo(msg: JointState) -> None:
        arrivals.append(time.perf_counter_ns())
        stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)

    with processes([spec], domain_id, executor=executor) as supervisor, \
            ros_session(domain_id, executor) as (node, spinner):
        node.create_subscription(JointState, 'servo_cmd', on_servo, qos_profile_sensor_data)
        spin_for(spinner, 2.0)  # discovery and warm-up
        arrivals.clear()
        stamps.clear()
        pid = supervisor.processes['cpg_node'].pid
        start_cpu = psutil.Process(pid).cpu_times()
        started = time.monotonic()
        spin_for(spinner, duration_s)
        elapsed = time.monotonic() - started
        end_cpu = psutil.Process(pid).cpu_times()
    error = np.abs(np.diff(np.array(arrivals)) * 1e-9 - 1.0 / rate_hz)
    source_error = np.abs(np.diff(np.sort(np.array(stamps))) * 1e-9 - 1.0 / rate_hz)
    cpu = 100.0 * ((end_cpu.user + end_cpu.system) - (start_cpu.user + start_cpu.system)) / elapsed
    return {'rate_hz': rate_hz, 'executor': executor, 'achieved_hz': len(arrivals) / elapsed,
            **{f'period_error_{k}': v for k, v in percentiles_ms(error).items()},
            **{f'source_period_error_{k}': v for k, v in percentiles_ms(source_error).items()},
            'cpu_percent': cpu}


def kinematics_cpu(stations: int, rate_hz: float, duration_s: float, domain_id: int,
                   executor: str | None = None) -> dict:
    """Kinematics node CPU with ``stations`` stations published at ``rate_hz``."""
    specs = [NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node', ()),
             NodeSpec('wirefish_kinematics', 'kinematics_node', 'kinematics_node', (
                 '--ros-args', '-p', f'station_count:={stations}',
                 '-p', f'publish_rate_hz:={rate_hz}'))]
    with processes(specs, domain_id, executor=executor) as supervisor:
        time.sleep(3.0)
        pid = supervisor.processes['kinematics_node'].pid
        cpu = cpu_percent([pid], duration_s)[pid]
        alive = not supervisor.exited()
    return {'stations': stations, 'rate_hz': rate_hz, 'executor': executor, 'cpu_percent': cpu,
            'ran': alive}


def fleet(fish: int, duration_s: float, domain_id: int, single_process: bool = False,
          executor: str | None = None, one_simulator: bool = True) -> dict:
    """
    ``fish`` whole graphs (namespaces /bench_fish_N) at default rates: rates and CPU.

    ``single_process`` runs each fish's four ROS nodes in one process (`wirefish compose`).
    ``one_simulator``: every virtual fish in one fish_sim (``fleet.fleet_simulator``, as
    `wirefish up --fleet`), else one fish_sim per fish (before). CPU: the total, the onboard
    part (every process but the virtual fish's) per fish, and the virtual fish's.
    """
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Imu, JointState
    from wirefish_bringup.fleet import fleet_simulator, SIMULATOR

    specs: list[NodeSpec] = []
    for i in range(1, fish + 1):
        specs += fish_graph(f'/bench_fish_{i}', sim=True, single_process=single_process)
    if one_simulator:
        params = str(next(s.params_file for s in specs if s.name == SIMULATOR))
        specs = [fleet_simulator('/', [f'bench_fish_{i}' for i in range(1, fish + 1)], params),
                 *(s for s in specs if s.name != SIMULATOR)]
    counts = {('servo_cmd', i): 0 for i in range(1, fish + 1)}
    counts.update({('imu/data', i): 0 for i in range(1, fish + 1)})
    with processes(specs, domain_id, executor=executor) as supervisor, \
            ros_session(domain_id, executor) as (node, spinner):
        for i in range(1, fish + 1):
            for topic, msg_type in (('servo_cmd', JointState), ('imu/data', Imu)):
                def count(_m, key=(topic, i)) -> None:
                    counts[key] += 1
                node.create_subscription(msg_type, f'/bench_fish_{i}/{topic}', count,
                                         qos_profile_sensor_data)
        # Starting many Python processes on two cores takes a while: wait until every fish
        # streams both topics (the time that takes is a figure too), then warm up 3 s more.
        launched = time.monotonic()
        while time.monotonic() - launched < READY_TIMEOUT_S and not all(counts.values()):
            spin_for(spinner, 0.5)
        ready_s = time.monotonic() - launched if all(counts.values()) else float('nan')
        spin_for(spinner, 3.0)
        for key in counts:
            counts[key] = 0
        procs = {key: psutil.Process(p.pid) for key, p in supervisor.processes.items()}
        cpu_start = {key: sum(p.cpu_times()[:2]) for key, p in procs.items()}
        started = time.monotonic()
        spin_for(spinner, duration_s)
        elapsed = time.monotonic() - started
        cpu = {key: 100.0 * (sum(p.cpu_times()[:2]) - cpu_start[key]) / elapsed
               for key, p in procs.items()}
        crashed = sorted(supervisor.exited())
        onboard = [key for key in procs if supervisor.specs[key].package != 'wirefish_sim']
    servo = [counts[('servo_cmd', i)] / elapsed for i in range(1, fish + 1)]
    imu = [counts[('imu/data', i)] / elapsed for i in range(1, fish + 1)]
    return {'fish': fish, 'single_process': single_process, 'executor': executor,
            'one_simulator': one_simulator, 'processes': len(specs),
            'simulator_cpu_percent': sum(cpu[key] for key in procs if key not in onboard),
            'servo_cmd_hz_min': min(servo), 'servo_cmd_hz_median': float(np.median(servo)),
            'imu_hz_min': min(imu), 'imu_hz_median': float(np.median(imu)),
            'cpu_percent_total': sum(cpu.values()),
            'onboard_cpu_percent_per_fish': sum(cpu[key] for key in onboard) / fish,
            'onboard_processes': onboard, 'cpu_percent_by_process': cpu, 'ready_s': ready_s,
            'crashed': crashed}
