# SPDX-License-Identifier: Apache-2.0
"""
The recorder's CPU for one fish's full graph, the recorder before the move to ``mcap`` and now.

Both recorders record the same graph (`wirefish up --sim`, every node at its default rate) in
the same window, side by side, so the load of the moment weighs on both alike. The old one is
the recorder as it was before (hand-written MCAP encoder, rclpy's SingleThreadedExecutor
calling one callback per message): its package is taken from git at OLD_COMMIT into a
temporary directory that goes first on its PYTHONPATH (nothing of it stays importable in the
workspace). A second figure is the encoders alone: CPU per message written of the old
hand-written writer, ``mcap``'s Writer (the recorder's) and foxglove-sdk's, on the same
serialised servo_cmd and imu/data messages with a flush every 200 messages (why the recorder
does not use the cheapest one: wirefish_bag.bag_writer). ``python -m
wirefish_bench.bench_recorder`` prints the JSON.
"""

from __future__ import annotations

import importlib
import json
import os
from pathlib import Path
import re
import signal
import subprocess
import sys
import tempfile
import time
from typing import Any

# The last commit with the hand-written encoder (mcap_records, mcap_writer).
OLD_COMMIT = '3f49806d7555d7fb28b1c37dc11ec565136f5ede'
OLD_COMMAND = 'wirefish_bringup.cli'  # the `wirefish` command of that commit
OLD_PACKAGE = 'wirefish_bringup'  # where the recorder was at OLD_COMMIT
NAMESPACE = '/bench_recorder'
WARM_UP_S = 10.0  # graph started, every topic discovered and subscribed by both recorders
WINDOW_S = 30.0
GOAL_RATIO = 0.5
WRITER_MESSAGES = 40000
WRITER_FLUSH_EVERY = 200
MODULE = 'wirefish_bench.bench_recorder'


def _old_package(into: Path) -> str:
    """Extract the old recorder's package from git into ``into``; return its PYTHONPATH entry."""
    from wirefish_bench.bench_old_new import old_package  # rclpy: not in the writer probes

    return old_package(OLD_COMMIT, OLD_PACKAGE, into)


def _cpu_s(pid: int) -> float:
    import psutil

    times = psutil.Process(pid).cpu_times()
    return times.user + times.system


def _stop(proc: subprocess.Popen, timeout_s: float = 15.0) -> str:
    """SIGINT ``proc`` (SIGKILL after ``timeout_s``); return what it printed."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
    return out or ''


def _summary(text: str) -> dict:
    wrote = re.search(r'wrote (\d+) messages', text)
    missing = re.search(r"missing from the publishers' sequences: (\d+)", text)
    return {'messages': int(wrote.group(1)) if wrote else None,
            'missing': int(missing.group(1)) if missing else None}


def recorders(domain_id: int, warm_up_s: float = WARM_UP_S,
              window_s: float = WINDOW_S) -> dict:
    """Record one fish's graph with the old and the new recorder at once; return their CPU."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    with tempfile.TemporaryDirectory(prefix='wirefish_bench_recorder_') as tmp:
        tmp_path = Path(tmp)
        old_env = dict(env, PYTHONPATH=os.pathsep.join(
            [str(_old_package(tmp_path)), env.get('PYTHONPATH', '')]))
        procs: dict[str, subprocess.Popen] = {}

        def start(name: str, args: list[str], proc_env: dict,
                  command: str = 'wirefish_cli.cli') -> None:
            procs[name] = subprocess.Popen(
                [sys.executable, '-m', command, *args], env=proc_env,
                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                start_new_session=True)
        try:
            start('graph', ['up', '--sim', '--no-status', '--namespace', NAMESPACE, '--out',
                            str(tmp_path / 'graph')], env)
            # Today's `wirefish record` verb is wirefish_bag's, whatever the path says: the old
            # recorder runs from the old package's own command.
            for name, proc_env, command in (('old', old_env, OLD_COMMAND),
                                            ('new', env, 'wirefish_cli.cli')):
                start(name, ['record', '-o', str(tmp_path / f'{name}_bag'), '--namespace',
                             NAMESPACE], proc_env, command)
            time.sleep(warm_up_s)
            start_cpu = {n: _cpu_s(procs[n].pid) for n in ('old', 'new')}
            time.sleep(window_s)
            used = {n: _cpu_s(procs[n].pid) - start_cpu[n] for n in ('old', 'new')}
        finally:
            printed = {n: _stop(p) for n, p in reversed(list(procs.items()))}
    result: dict = {'window_s': window_s, 'old_commit': OLD_COMMIT}
    for name in ('old', 'new'):
        result[name] = {'cpu_percent': 100.0 * used[name] / window_s, **_summary(printed[name])}
    result['ratio'] = result['new']['cpu_percent'] / result['old']['cpu_percent']
    return result


def _serialised_messages() -> list[tuple[str, bytes]]:
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import Imu, JointState

    servo = JointState(name=['servo_1', 'servo_2'], position=[0.1, 0.2], velocity=[0.0, 0.0])
    return [('sensor_msgs/msg/JointState', serialize_message(servo)),
            ('sensor_msgs/msg/Imu', serialize_message(Imu()))]


def _cpu_per_message_us(write, flush, messages: list[tuple[Any, bytes]]) -> float:
    started = time.process_time()
    for i in range(WRITER_MESSAGES):
        channel, data = messages[i % len(messages)]
        write(channel, 1_000_000_000 + i, data, i)
        if i % WRITER_FLUSH_EVERY == 0:
            flush()
    return (time.process_time() - started) / WRITER_MESSAGES * 1e6


def _writer_costs(directory: Path) -> dict[str, float]:
    """Return CPU us per message of the writers this path holds (the old one, or the others)."""
    from wirefish_bag.bag_storage import add_topic
    from wirefish_bag.bagfile import wirefish_typestore

    store = wirefish_typestore()
    typed = _serialised_messages()
    costs = {}
    try:
        # Importable only on the old package's path (the module is gone from the workspace).
        old = importlib.import_module('wirefish_bringup.mcap_writer').McapWriter(
            directory / 'old.mcap')
        old_messages = [(add_topic(old, store, f'/t{i}', t, ''), d)
                        for i, (t, d) in enumerate(typed)]
        costs['hand-written (old)'] = _cpu_per_message_us(old.write, old.flush, old_messages)
        old.close()
    except ImportError:
        from wirefish_bag.bag_writer import BagFileWriter
        new = BagFileWriter(directory / 'mcap.mcap')
        new_messages = [(add_topic(new, store, f'/t{i}', t, ''), d)
                        for i, (t, d) in enumerate(typed)]
        costs['mcap (new)'] = _cpu_per_message_us(new.write, new.flush, new_messages)
        new.close()
        costs.update(_foxglove_cost(directory, typed))
    return costs


def _foxglove_cost(directory: Path, typed: list[tuple[str, bytes]]) -> dict[str, float]:
    import foxglove
    from foxglove.mcap import MCAPWriteOptions

    writer = foxglove.open_mcap(directory / 'foxglove.mcap',
                                writer_options=MCAPWriteOptions(compression=None,
                                                                profile='ros2'))
    channels = [foxglove.Channel(f'/t{i}', message_encoding='cdr', schema=foxglove.Schema(
        name=t, encoding='ros2msg', data=b'')) for i, (t, _) in enumerate(typed)]

    def write(channel, time_ns: int, data: bytes, _sequence: int) -> None:
        channel.log(data, log_time=time_ns)  # no sequence number: the SDK numbers itself
    cost = _cpu_per_message_us(write, writer.flush,
                               [(c, d) for c, (_, d) in zip(channels, typed)])
    writer.close()
    return {'foxglove-sdk (no sequence numbers)': cost}


def writers() -> dict[str, float]:
    """Return CPU us per message of the old, the mcap and the foxglove-sdk writers."""
    costs: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix='wirefish_bench_writers_') as tmp:
        tmp_path = Path(tmp)
        old_path = str(_old_package(tmp_path))
        for path in (old_path, None):
            env = dict(os.environ)
            if path:
                env['PYTHONPATH'] = os.pathsep.join([path, env.get('PYTHONPATH', '')])
            out = subprocess.run([sys.executable, '-m', MODULE, '--writers-here', tmp],
                                 env=env, capture_output=True, text=True, check=True).stdout
            costs.update(json.loads(out))
    return costs


def run(domain_id: int = 101) -> dict:
    """Run both figures; return them (the bench's JSON)."""
    return {'recorders': recorders(domain_id), 'writers_us_per_message': writers()}


def row(result: dict) -> tuple[str, str, str, str, str]:
    """Return the BENCHMARKS.md row: (figure, goal, measured, verdict, how)."""
    figure = ("Recorder CPU for one fish's full graph: old (hand-written MCAP, one callback per "
              'message) vs new (mcap, take loop)')
    goal = f'≤ {GOAL_RATIO:g} × old in the same run; 0 lost'
    if 'error' in result:
        return figure, goal, result['error'], 'not measured', ''
    rec = result['recorders']
    old, new = rec['old'], rec['new']
    writers_text = ', '.join(f'{name} {us:.1f} µs' for name, us in
                             result.get('writers_us_per_message', {}).items())
    measured = (f'old {old["cpu_percent"]:.1f} %, new {new["cpu_percent"]:.1f} % of a core '
                f'(ratio {rec["ratio"]:.2f}); missing from the sequences: old {old["missing"]}, '
                f'new {new["missing"]}; encoders alone per message: {writers_text}')
    met = rec['ratio'] <= GOAL_RATIO and new['missing'] == 0
    return (figure, goal, measured, 'met' if met else 'missed',
            f'both recorders on one wirefish up --sim graph at once, psutil CPU over '
            f'{rec["window_s"]:g} s after {WARM_UP_S:g} s; old = '
            f'src/{OLD_PACKAGE}/{OLD_PACKAGE} at {OLD_COMMIT[:7]} from git (bench_recorder.py)')


def main(argv: list[str] | None = None) -> int:
    """Print the JSON of ``run`` (or, with --writers-here DIR, of this path's writers)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ['--writers-here']:
        directory = Path(tempfile.mkdtemp(dir=argv[1]))
        print(json.dumps(_writer_costs(directory)))
        return 0
    print(json.dumps(run(), indent=2))
    return 0


if __name__ == '__main__':
    sys.exit(main())
