# SPDX-License-Identifier: Apache-2.0
"""
The supervisor tracks, restarts and stops every process it starts.

Even several of the same name are stopped; an exiting one is restarted by its policy: back-off,
a budget, then given up or, if required, an error that stops the graph.
"""

import signal
import sys
import time

import psutil
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from wirefish_bringup.graph import NO_RESTART, NodeSpec, RestartPolicy
from wirefish_launcher.supervisor import ProcessExitedError, Supervisor

pytestmark = pytest.mark.ros


def test_same_named_processes_are_all_stopped_with_exit_code_0(tmp_path, ros_env, ros_context):
    supervisor = Supervisor(tmp_path, env=ros_env)
    procs = [supervisor.start(NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node',
                                       ('--ros-args', '-r', f'__ns:=/fish_{i}')))
             for i in (1, 2)]
    assert sorted(supervisor.processes) == ['cpg_node', 'cpg_node_2']
    assert all(psutil.pid_exists(p.pid) for p in procs)
    # Stop them once they are up (as the launcher does), not while they are still importing.
    node = rclpy.create_node('probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    up = {('cpg_node', '/fish_1'), ('cpg_node', '/fish_2')}
    try:
        assert spin_until(executor, lambda: up <= set(node.get_node_names_and_namespaces()),
                          timeout_s=30.0)
    finally:
        executor.shutdown()
        node.destroy_node()
    codes = supervisor.stop()
    assert codes == {'cpg_node_2': 0, 'cpg_node': 0}
    assert supervisor.overran == []
    assert sorted(p.name for p in tmp_path.glob('*.log')) == ['cpg_node.log', 'cpg_node_2.log']


def _failing_cpg(policy: RestartPolicy) -> NodeSpec:
    # A crash at every start: rcl cannot open the parameter file (a traceback, exit 1).
    return NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node',
                    ('--ros-args', '--params-file', '/nonexistent/wirefish.yaml'),
                    restart=policy)


def test_a_node_refusing_its_parameters_is_given_up_at_once_with_its_reason(tmp_path, ros_env):
    supervisor = Supervisor(tmp_path, env=ros_env)
    # A rate the CPG refuses: one FATAL line and exit 1, at every start alike.
    supervisor.start(NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node',
                              ('--ros-args', '-p', 'publish_rate_hz:=-1.0'),
                              restart=RestartPolicy(delay_s=0.1)))
    try:
        lines = _supervise_until(supervisor, lambda: 'cpg_node' in supervisor.given_up)
    finally:
        supervisor.stop()
    assert len(lines) == 1, lines
    assert lines[0].startswith('cpg_node refused its start-up parameters and is not restarted'), \
        lines
    assert 'publish_rate_hz' in lines[0] and lines[0].endswith('the rest keeps running'), lines
    assert supervisor.budgets['cpg_node'].total == 0


def _supervise_until(supervisor: Supervisor, done, timeout_s: float = 60.0) -> list[str]:
    lines: list[str] = []
    deadline = time.monotonic() + timeout_s
    while not done() and time.monotonic() < deadline:
        lines += supervisor.supervise()
        time.sleep(0.02)
    return lines


def test_an_exiting_process_is_restarted_with_back_off_until_given_up(tmp_path, ros_env):
    supervisor = Supervisor(tmp_path, env=ros_env)
    supervisor.start(_failing_cpg(RestartPolicy(delay_s=0.1, backoff=3.0, max_restarts=2)))
    try:
        lines = _supervise_until(supervisor, lambda: 'cpg_node' in supervisor.given_up)
    finally:
        supervisor.stop()
    restarts = [line for line in lines if 'restarting it in' in line]
    assert [line.split(' in ')[1].split(' s ')[0] for line in restarts] == ['0.1', '0.3']
    assert lines[-1].startswith('cpg_node exited with code 1 after 2 restarts within 60 s: '
                                'given up, the rest keeps running'), lines
    assert supervisor.summary() == ('restarts: cpg_node 2; '
                                    'given up: cpg_node (last exit code 1)')
    log = (tmp_path / 'cpg_node.log').read_text()
    assert log.count('restarted by wirefish up') == 2  # one log, every start in it


def test_a_required_process_that_spends_its_budget_raises(tmp_path, ros_env):
    supervisor = Supervisor(tmp_path, env=ros_env)
    supervisor.start(_failing_cpg(RestartPolicy(delay_s=0.1, max_restarts=1, required=True)))
    try:
        with pytest.raises(ProcessExitedError, match='it is required: stopping the graph'):
            _supervise_until(supervisor, lambda: False)
    finally:
        supervisor.stop()
    assert supervisor.budgets['cpg_node'].total == 1


def test_a_process_whose_policy_does_not_respawn_is_given_up_at_once(tmp_path, ros_env):
    supervisor = Supervisor(tmp_path, env=ros_env)
    supervisor.start(_failing_cpg(NO_RESTART))
    try:
        lines = _supervise_until(supervisor, lambda: bool(supervisor.given_up))
    finally:
        supervisor.stop()
    assert len(lines) == 1 and 'is not restarted (its policy)' in lines[0], lines


# Processes that ignore SIGINT, as one whose stop hangs does; the first one exits at SIGTERM.
_SLOW = 'signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))\n'
_DEAF = 'signal.signal(signal.SIGTERM, signal.SIG_IGN)\n'


@pytest.mark.parametrize('on_sigterm, code', [(_SLOW, 0), (_DEAF, None)])
def test_a_process_still_running_at_the_deadline_is_named_and_escalated(
        tmp_path, monkeypatch, on_sigterm, code):
    script = tmp_path / 'late_node'
    script.write_text(f'#!{sys.executable}\nimport signal, sys, time\n'
                      'signal.signal(signal.SIGINT, signal.SIG_IGN)\n' + on_sigterm
                      + "print('ready', flush=True)\ntime.sleep(60)\n")
    script.chmod(0o755)
    monkeypatch.setattr(NodeSpec, 'executable_path', lambda _spec: script)
    supervisor = Supervisor(tmp_path / 'logs')
    proc = supervisor.start(NodeSpec('wirefish_cpg', 'late_node', 'late_node', ()))
    log = tmp_path / 'logs' / 'late_node.log'
    deadline = time.monotonic() + 30.0
    while 'ready' not in log.read_text() and time.monotonic() < deadline:
        time.sleep(0.02)
    assert supervisor.stop(timeout_s=0.5) == {'late_node': code}
    assert supervisor.overran == ['late_node']
    assert proc.returncode == (0 if code == 0 else -signal.SIGKILL)
