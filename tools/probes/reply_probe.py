#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""
Count the answers fresh clients never get, the way the standard tools make them.

Every call is a new DDS participant (its own rclpy context), node and client, then
``wait_for_service`` (``wait_for_server``), one request and no retry: what ``ros2 service
call``, ``ros2 param set`` and ``ros2 action send_goal`` do. A call (a goal: its acceptance or
its result) not answered within ``--deadline`` s is counted unanswered. The server is the
graph's own executable (tuner_node: the ``retune_gait`` service and action; cpg_node:
``set_parameters``), started by the probe in the namespace the Fast DDS profile names and
restarted before every ``--restart-every``-th call (a server that has just started meets
clients it has not discovered yet: where rmw_fastrtps drops answers). A second graph
(``wirefish up`` in ``/load_0``) loads the machine (``--load-graphs``: how many).

    tools/wfenv python tools/probes/reply_probe.py --profile off --calls 200 --goals 100
    tools/wfenv python tools/probes/reply_probe.py --profile on --calls 200 --goals 100

``--profile on`` gives the servers the workspace's Fast DDS profile (config/fastdds.xml:
reply writers wait for the client's reader); ``off`` gives them none.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
import os
from pathlib import Path
import signal
import subprocess
import sys
import tempfile
import time

NAMESPACE = '/wirefish'
LOAD_NAMESPACE = '/load'
PROFILE = Path(__file__).resolve().parents[2] / 'src' / 'wirefish_bringup' / 'config' / \
    'fastdds.xml'
STOP_TIMEOUT_S = 10.0


@dataclass
class Tally:
    """What the calls of one batch got."""

    answered: int = 0
    unanswered: int = 0
    no_service: int = 0
    seconds: list[float] = field(default_factory=list)

    def line(self, label: str) -> str:
        """Return the batch's summary line."""
        calls = self.answered + self.unanswered + self.no_service
        slowest = max(self.seconds, default=float('nan'))
        return (f'{label}: {calls} calls, answered {self.answered}, unanswered '
                f'{self.unanswered}, service never found {self.no_service}; '
                f'slowest answer {slowest:.2f} s')


def server_environment(profile: bool, domain: int) -> dict[str, str]:
    """Return the environment of the probe's servers and load graph (profile on or off)."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), PYTHONUNBUFFERED='1')
    # An empty value: no profile file (Fast DDS then looks only for its default file in cwd).
    env['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(PROFILE) if profile else ''
    return env


def executable(package: str, name: str) -> str:
    """Return the installed executable of a node (as ``ros2 run`` finds it)."""
    from ament_index_python.packages import get_package_prefix
    return str(Path(get_package_prefix(package), 'lib', package, name))


def server_command(name: str) -> list[str]:
    """Return the command of one of the graph's servers (cpg_node, tuner_node) in ``NAMESPACE``."""
    package = 'wirefish_tuner' if name == 'tuner_node' else 'wirefish_cpg'
    return [executable(package, name), '--ros-args', '-r', f'__ns:={NAMESPACE}']


def start(command: list[str], env: dict[str, str], log) -> subprocess.Popen:
    """Start one child in its own session (stopped by its pid only)."""
    return subprocess.Popen(command, env=env, stdin=subprocess.DEVNULL, stdout=log,
                            stderr=subprocess.STDOUT, start_new_session=True)


def stop(proc: subprocess.Popen) -> None:
    """SIGINT the child, SIGKILL it if it outlives ``STOP_TIMEOUT_S``; reap it."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def tuner_call():
    """Return (service type, name, request) of a small retune order (answered either way)."""
    from wirefish_msgs.msg import BodyWaveSpec
    from wirefish_msgs.srv import RetuneGait
    request = RetuneGait.Request(seed=1, max_iterations=2, swarm_size=8, apply=False)
    request.wave = BodyWaveSpec(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0)
    return RetuneGait, f'{NAMESPACE}/retune_gait', request


def goal_call():
    """Return (action type, name, goal) of a small retune goal (its result comes either way)."""
    from wirefish_msgs.action import RetuneGait
    from wirefish_msgs.msg import BodyWaveSpec
    goal = RetuneGait.Goal(seed=1, max_iterations=2, swarm_size=8, apply=False,
                           use_library=False)
    goal.wave = BodyWaveSpec(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0)
    return RetuneGait, f'{NAMESPACE}/retune_gait', goal


def cpg_call():
    """Return (service type, name, request) of a set_parameters call that changes nothing."""
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter
    request = SetParameters.Request(
        parameters=[Parameter('use_sim_time', Parameter.Type.BOOL, False).to_parameter_msg()])
    return SetParameters, f'{NAMESPACE}/cpg_node/set_parameters', request


class _FreshParticipant:
    """A context, node and executor of their own: one DDS participant, as one CLI call makes."""

    def __enter__(self):
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('reply_probe', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        return self

    def wait(self, future, timeout_s: float) -> bool:
        """Spin until ``future`` is done or ``timeout_s`` passed; return whether it is done."""
        self.executor.spin_until_future_complete(future, timeout_sec=timeout_s)
        return future.done()

    def __exit__(self, *_exc) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()


def fresh_call(kind, name: str, request, deadline_s: float, find_s: float):
    """Make one call as `ros2 service call` does; return its round trip (s), False or None."""
    with _FreshParticipant() as fresh:
        client = fresh.node.create_client(kind, name)
        if not client.wait_for_service(timeout_sec=find_s):
            return None
        sent = time.monotonic()
        answered = fresh.wait(client.call_async(request), deadline_s)
        return time.monotonic() - sent if answered else False


def fresh_goal(kind, name: str, goal, deadline_s: float, find_s: float):
    """
    Send one goal as `ros2 action send_goal` does; return its round trip (s), False or None.

    Two answers must come: the goal's acceptance (send_goal) and its result (get_result), each
    within ``deadline_s``; a rejected goal counts as answered (the server said so).
    """
    from rclpy.action import ActionClient
    with _FreshParticipant() as fresh:
        client = ActionClient(fresh.node, kind, name)
        try:
            if not client.wait_for_server(timeout_sec=find_s):
                return None
            sent = time.monotonic()
            accepted = client.send_goal_async(goal)
            if not fresh.wait(accepted, deadline_s):
                return False
            handle = accepted.result()
            if handle.accepted and not fresh.wait(handle.get_result_async(), deadline_s):
                return False
            return time.monotonic() - sent
        finally:
            client.destroy()


@dataclass(frozen=True)
class Batch:
    """How many calls, how often the server restarts, how long a call may take."""

    calls: int = 200
    restart_every: int = 10
    deadline_s: float = 10.0
    find_s: float = 30.0


def run_batch(server: list[str], call, batch: Batch, env: dict[str, str], log) -> Tally:
    """Run ``batch.calls`` fresh calls, restarting the server before every n-th."""
    tally = Tally()
    proc = None
    try:
        for index in range(batch.calls):
            if index % batch.restart_every == 0:
                if proc is not None:
                    stop(proc)
                proc = start(server, env, log)
            exchange, message = call
            outcome = exchange(*message(), batch.deadline_s, batch.find_s)
            if outcome is None:
                tally.no_service += 1
            elif outcome is False:
                tally.unanswered += 1
                print(f'  call {index} unanswered', flush=True)
            else:
                tally.answered += 1
                tally.seconds.append(outcome)
    finally:
        if proc is not None:
            stop(proc)
    return tally


def main(argv: list[str] | None = None) -> int:
    """Run the batches the options ask for; print one summary line each."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--profile', choices=('on', 'off'), required=True)
    parser.add_argument('--calls', type=int, default=200, help='calls per service')
    parser.add_argument('--restart-every', type=int, default=10)
    parser.add_argument('--deadline', type=float, default=10.0,
                        help='an answer later than this (s) counts as unanswered')
    parser.add_argument('--find-timeout', type=float, default=30.0,
                        help='wait_for_service timeout (s)')
    parser.add_argument('--services', default='tuner,goal,cpg',
                        help='comma-separated batches: tuner (retune_gait service calls), goal '
                        '(retune_gait action goals), cpg (set_parameters on cpg_node)')
    parser.add_argument('--goals', type=int, default=100, help='action goals (goal batch)')
    parser.add_argument('--domain', type=int, default=77)
    parser.add_argument('--out', help="keep the servers' log here (default: a scratch dir)")
    parser.add_argument('--load-graphs', type=int, default=1,
                        help='graphs running beside the servers (0: none)')
    args = parser.parse_args(argv)
    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    env = server_environment(args.profile == 'on', args.domain)
    servers = {'tuner': (server_command('tuner_node'), (fresh_call, tuner_call)),
               'goal': (server_command('tuner_node'), (fresh_goal, goal_call)),
               'cpg': (server_command('cpg_node'), (fresh_call, cpg_call))}
    with tempfile.TemporaryDirectory(prefix='reply_probe_') as scratch:
        out = args.out or scratch
        Path(out).mkdir(parents=True, exist_ok=True)
        return _run(args, env, servers, out)


def _run(args, env: dict[str, str], servers, out: str) -> int:
    with open(Path(out, 'servers.log'), 'w') as log:
        loads = [start(['wirefish', 'up', '--no-status', '--allow-duplicate', '--namespace',
                        f'{LOAD_NAMESPACE}_{index}', '--out', out], env, log)
                 for index in range(args.load_graphs)]
        time.sleep(5.0 if loads else 0.0)  # their processes starting are part of the load
        try:
            for label in args.services.split(','):
                command, call = servers[label]
                calls = args.goals if label == 'goal' else args.calls
                batch = Batch(calls, args.restart_every, args.deadline, args.find_timeout)
                tally = run_batch(command, call, batch, env, log)
                print(tally.line(f'{label} profile {args.profile}'), flush=True)
        finally:
            for load in loads:
                stop(load)
    # What rclpy says when rmw_fastrtps drops an answer (the servers' own stderr).
    dropped = Path(out, 'servers.log').read_text(errors='replace').count(
        'failed to send response')
    print(f'servers said "failed to send response" {dropped} times (log: {out})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
