# SPDX-License-Identifier: Apache-2.0
"""
planner_node drives cpg_node by its control topic (in-process, one context of the test's own).

One owner of the gait: a parameter set on the CPG (a retune applied, ``ros2 param set``) is a
manual override; the planner then sends nothing, says so in planner_state and /diagnostics, and
drives again once the CPG's follow_commands service hands the targets back. A command the CPG
refuses is said there too.
"""

from dataclasses import dataclass, field
import math
import subprocess
import sys

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from ros_utils import spin_until

NAMESPACE = '/h24_topic'
WAIT_S = 20.0
FIT = {'frequency_hz': 1.2, 'amplitude_1': 0.3, 'amplitude_2': 0.35}


@dataclass
class Heard:
    """What the peer node heard."""

    states: list = field(default_factory=list)
    params: list = field(default_factory=list)
    statuses: list = field(default_factory=list)
    diagnostics: list = field(default_factory=list)


@pytest.fixture
def graph(ros_context):
    """Yield (cpg node, planner node, peer, executor, heard, cmd_vel publisher)."""
    import rclpy
    from wirefish_common.qos import LATCHED
    from wirefish_cpg.cpg_node import CpgNode
    from wirefish_msgs.msg import CpgParams, CpgStatus, PlannerState
    from wirefish_planner.planner_node import PlannerNode

    cpg = CpgNode(context=ros_context, namespace=NAMESPACE)
    planner = PlannerNode(context=ros_context, namespace=NAMESPACE)
    peer = rclpy.create_node('peer', namespace=NAMESPACE, context=ros_context)
    heard = Heard()
    peer.create_subscription(PlannerState, 'planner_state', heard.states.append, 10)
    peer.create_subscription(CpgParams, 'cpg_params', heard.params.append, LATCHED)
    peer.create_subscription(CpgStatus, 'cpg_status', heard.statuses.append, LATCHED)
    peer.create_subscription(
        DiagnosticArray, '/diagnostics',
        lambda msg: heard.diagnostics.extend(
            s for s in msg.status if s.name.endswith('/planner_node')), 10)
    publisher = peer.create_publisher(Twist, 'cmd_vel', 10)
    executor = SingleThreadedExecutor(context=ros_context)
    for node in (cpg, planner, peer):
        executor.add_node(node)
    try:
        yield cpg, planner, peer, executor, heard, publisher
    finally:
        executor.shutdown()
        for node in (peer, planner, cpg):
            node.destroy_node()


def _drive(publisher, heard, predicate):
    """Return a predicate that publishes cmd_vel 0.2 m/s straight, then asks ``predicate``."""
    msg = Twist()
    msg.linear.x = 0.2

    def check() -> bool:
        publisher.publish(msg)
        return predicate()

    return check


def _runs_the_planners_gait(heard) -> bool:
    if not heard.states or not heard.params:
        return False
    state, running = heard.states[-1], heard.params[-1]
    return state.mode != 'rest' and state.tail_beat_hz > 0.0 and \
        running.amplitude[0] > 0.0 and running.frequency_hz != FIT['frequency_hz'] and \
        state.cpg_frequency_hz == pytest.approx(running.frequency_hz)


@pytest.mark.ros
def test_the_planner_drives_the_cpg_by_topic(graph):
    _, _, _, executor, heard, publisher = graph
    # cpg_params and the latched cpg_status are two topics: the gait can be heard first.
    assert spin_until(executor, _drive(publisher, heard, lambda: _runs_the_planners_gait(heard)
                                       and bool(heard.statuses)), WAIT_S)
    assert heard.statuses[-1].source == 'command' and heard.statuses[-1].refused == ''


@pytest.mark.ros
def test_a_fit_set_on_the_cpg_is_a_manual_override_the_planner_says_and_keeps(graph, ros_env):
    cpg, _, peer, executor, heard, publisher = graph
    assert spin_until(executor, _drive(publisher, heard, lambda: _runs_the_planners_gait(heard)),
                      WAIT_S)
    # As tuner_node applies a fit: one atomic set of the CPG's parameters.
    result = cpg.set_parameters_atomically(
        [Parameter(name, value=value) for name, value in FIT.items()])
    assert result.successful

    def says_manual() -> bool:
        return bool(heard.states) and heard.states[-1].mode == 'manual' and \
            bool(heard.diagnostics) and 'manual override' in heard.diagnostics[-1].message

    assert spin_until(executor, _drive(publisher, heard, says_manual), WAIT_S)
    state = heard.states[-1]
    assert 'follow_commands' in state.note and 'cmd_vel is not followed' in state.note
    assert state.cpg_frequency_hz == FIT['frequency_hz']  # the truth: the CPG runs the fit
    assert heard.diagnostics[-1].level == b'\x01'
    # cmd_vel goes on for a while: the fit stays (the planner does not overwrite it).
    spin_until(executor, _drive(publisher, heard, lambda: False), 2.0)
    assert heard.params[-1].frequency_hz == FIT['frequency_hz']
    assert list(heard.params[-1].amplitude) == [FIT['amplitude_1'], FIT['amplitude_2']]

    # `wirefish hand-back` (cpg_node/follow_commands) gives the gait back to the planner.
    hand_back = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'hand-back', '--namespace', NAMESPACE],
        env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert spin_until(executor, lambda: hand_back.poll() is not None, WAIT_S)
    out, err = hand_back.communicate()
    assert hand_back.returncode == 0, err
    assert out.strip() == 'cpg_node: cpg_command sets the targets again'
    assert spin_until(executor, _drive(publisher, heard, lambda: _runs_the_planners_gait(heard)),
                      WAIT_S)


@pytest.mark.ros
def test_a_refused_command_is_said_and_changes_nothing(graph):
    from wirefish_msgs.msg import CpgCommand, CpgParams

    _, planner, peer, executor, heard, _ = graph
    assert spin_until(executor, lambda: bool(heard.params) and bool(heard.statuses), WAIT_S)
    executor.remove_node(planner)  # the peer is the only controller now
    before = heard.params[-1]
    bad = CpgCommand(targets=CpgParams(frequency_hz=math.nan, amplitude=[0.3, 0.3],
                                       offset=[0.0, 0.0], w12=-0.41, w21=0.64, phi12=1.76,
                                       phi21=1.06, alpha=20.0))
    command_pub = peer.create_publisher(CpgCommand, 'cpg_command', 1)

    def refused() -> bool:
        command_pub.publish(bad)
        return bool(heard.statuses[-1].refused)

    assert spin_until(executor, refused, WAIT_S)
    assert 'frequency_hz must be finite' in heard.statuses[-1].refused
    assert heard.params[-1] == before


@pytest.mark.ros
def test_a_command_the_cpg_refused_is_said_by_the_planner(ros_context):
    import rclpy
    from wirefish_common.qos import LATCHED
    from wirefish_msgs.msg import CpgStatus, PlannerState
    from wirefish_planner.planner_node import PlannerNode

    planner = PlannerNode(context=ros_context, namespace=NAMESPACE)
    peer = rclpy.create_node('fake_cpg', namespace=NAMESPACE, context=ros_context)
    heard = Heard()
    peer.create_subscription(PlannerState, 'planner_state', heard.states.append, 10)
    peer.create_subscription(
        DiagnosticArray, '/diagnostics',
        lambda msg: heard.diagnostics.extend(
            s for s in msg.status if s.name.endswith('/planner_node')), 10)
    reason = 'cpg_command refused: amplitude_1 must be <= 1.5708, got 2'
    peer.create_publisher(CpgStatus, 'cpg_status', LATCHED).publish(
        CpgStatus(source='command', refused=reason))
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(planner)
    executor.add_node(peer)
    try:
        assert spin_until(executor, lambda: bool(heard.diagnostics) and bool(heard.states)
                          and heard.states[-1].note == reason
                          and heard.diagnostics[-1].message == reason, WAIT_S)
        assert heard.diagnostics[-1].level == b'\x01'
    finally:
        executor.shutdown()
        peer.destroy_node()
        planner.destroy_node()


def test_hand_back_without_a_graph_says_so(ros_env):
    done = subprocess.run(
        [sys.executable, '-m', 'wirefish_cli.cli', 'hand-back', '--namespace', '/h24_none',
         '--timeout', '1'], env=ros_env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert 'no /h24_none/cpg_node/follow_commands service' in done.stderr
