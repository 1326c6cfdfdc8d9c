# SPDX-License-Identifier: Apache-2.0
"""SIGINT and SIGTERM stop every node of the registry with exit code 0 and no trace."""

import dataclasses
import os
from pathlib import Path
import shlex
import signal
import subprocess

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until, stop_signals_blocked_soon
from wirefish_bringup.graph import composable_entries, COMPOSED_NAME, fish_graph, Role
from wirefish_common.startup_signals import held_start_prefix
from wirefish_launcher.supervisor import Supervisor

pytestmark = pytest.mark.ros
# Every ROS node of the registry (those with a node class), as the launcher starts it: its name,
# namespace, the default parameter file and its extra parameters. The bridge's device does not
# exist: the bridge keeps retrying it, which is the state a real fish's bridge waits in.
NAMESPACE = '/h_signals'
DEVICE = '/tmp/wirefish-h-signals-no-such-device'
NODES = [spec for spec in fish_graph(NAMESPACE, sim=False, port=DEVICE)
         if spec.name in {e.name for e in composable_entries()}]
# Extra load for a node whose rate is a parameter: a busy CPG is 1 kHz of callbacks.
BUSY = {'cpg_node': ('-p', 'publish_rate_hz:=1000.0')}


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize('spec', NODES, ids=[spec.name for spec in NODES])
def test_a_signal_stops_the_node_cleanly(spawn, ros_context, spec, signum):
    proc = spawn([str(spec.executable_path()), *spec.command_arguments(),
                  *BUSY.get(spec.name, ())])
    probe = rclpy.create_node('signal_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)
    try:
        assert spin_until(executor, lambda: (spec.name, NAMESPACE)
                          in probe.get_node_names_and_namespaces(), timeout_s=30.0)
    finally:
        executor.shutdown()
        probe.destroy_node()
    proc.send_signal(signum)
    code = proc.wait(timeout=20.0)
    output = proc.stdout.read()
    assert code == 0, output
    assert 'Traceback' not in output


def _every_process_wirefish_up_starts(out: Path) -> list:
    """Each executable of the registry once (the emulated board aside: it needs QEMU)."""
    namespace = '/h_signals_start'
    specs = {}
    for graph in (fish_graph(namespace, sim=True, bag=out / 'bag', view=True),
                  fish_graph(namespace, sim=True, role=Role.FISH),
                  fish_graph(namespace + '_one', sim=True, single_process=True)):
        for spec in graph:
            specs.setdefault(spec.executable, spec)
    view = specs['view_node']  # any free port, no dashboard: other modules' views may run
    specs['view_node'] = dataclasses.replace(
        view, parameters={**view.parameters, 'port': '0', 'http_port': '-1'})
    assert {'fish_sim', 'bridge_node', 'cpg_node', 'kinematics_node', 'tf_node',
            'planner_node', 'tuner_node', 'link_relay', 'recorder', 'view_node',
            'compose'} <= set(specs), sorted(specs)
    assert specs['compose'].name == COMPOSED_NAME
    return list(specs.values())


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
def test_a_stop_sent_as_the_launcher_starts_a_process_ends_it_with_0_and_no_trace(
        ros_env, tmp_path, signum):
    # Sent the moment the process exists: its interpreter is starting, nothing of ours runs yet.
    # The launcher started it with the stop signals blocked; its handler, once installed,
    # receives the one that waited (the launcher's own SIGINT at stop() follows it).
    supervisor = Supervisor(tmp_path / 'logs', env=ros_env)
    for spec in _every_process_wirefish_up_starts(tmp_path):
        os.killpg(supervisor.start(spec).pid, signum)
    codes = supervisor.stop(timeout_s=30.0)
    assert not supervisor.overran
    logs = {key: (tmp_path / 'logs' / f'{key}.log').read_text() for key in codes}
    assert codes == dict.fromkeys(codes, 0), {k: logs[k][-800:] for k, c in codes.items() if c}
    for key, log in logs.items():
        assert 'Traceback' not in log and 'KeyboardInterrupt' not in log, (key, log[-800:])


def test_a_stop_sent_as_ros2_launch_starts_a_process_ends_it_with_0_and_no_trace(
        ros_env, tmp_path):
    # The launch file's way: each node through held_start_prefix (env blocking the signals),
    # in a session of its own; SIGINT as soon as env has blocked them (before that, env's own
    # first instructions are the one window left, a millisecond or so, against the
    # interpreter's start and imports without the prefix: tens to hundreds of milliseconds).
    prefix = shlex.split(held_start_prefix())
    procs = {}
    for spec in _every_process_wirefish_up_starts(tmp_path):
        with open(tmp_path / f'{spec.name}.log', 'w') as log:
            procs[spec.name] = subprocess.Popen(
                [*prefix, str(spec.executable_path()), *spec.command_arguments()],
                env=ros_env, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                start_new_session=True)
        assert stop_signals_blocked_soon(procs[spec.name].pid), spec.name
        os.killpg(procs[spec.name].pid, signal.SIGINT)
    try:
        codes = {name: proc.wait(timeout=30.0) for name, proc in procs.items()}
    finally:
        for proc in procs.values():
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
    logs = {name: (tmp_path / f'{name}.log').read_text() for name in procs}
    assert codes == dict.fromkeys(codes, 0), {k: logs[k][-800:] for k, c in codes.items() if c}
    for name, log in logs.items():
        assert 'Traceback' not in log and 'KeyboardInterrupt' not in log, (name, log[-800:])
