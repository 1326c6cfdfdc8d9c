# SPDX-License-Identifier: Apache-2.0
"""`wirefish topic` and `wirefish param` against a node of the test's own, on real DDS."""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

# It mostly waits (0.18 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

NAMESPACE = '/topic_param'
CLI = [sys.executable, '-m', 'wirefish_cli.cli']


@pytest.fixture
def graph(ros_context):
    """Run a node with a 20 Hz stream, a latched topic, a hidden topic and a parameter."""
    import rclpy
    from rcl_interfaces.msg import SetParametersResult
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    node = rclpy.create_node('talker', namespace=NAMESPACE, context=ros_context)
    node.declare_parameter('gain', 0.5)

    def judge(parameters):
        bad = [p for p in parameters if p.name == 'gain' and p.value < 0.0]
        return SetParametersResult(successful=not bad,
                                   reason='gain must be >= 0' if bad else '')

    node.add_on_set_parameters_callback(judge)
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    stream = node.create_publisher(String, 'stream', reliable)
    hidden = node.create_publisher(String, 'goal/_action/status_like', reliable)
    latched = node.create_publisher(String, 'state', QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL))
    latched.publish(String(data='latched once'))
    node.create_timer(0.05, lambda: (stream.publish(String(data='hello')),
                                     hidden.publish(String(data='x'))))
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    yield node
    executor.shutdown()
    spinner.join(timeout=5.0)
    node.destroy_node()


def wirefish(ros_env, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], env=ros_env, capture_output=True, text=True,
                          timeout=120)


def _listed_once_found(ros_env, wanted: str, *options: str) -> subprocess.CompletedProcess:
    """Run `wirefish topic list` until ``wanted`` is listed (30 s at most); return the last."""
    # A list is what its process discovered in its listening window (DISCOVERY_S): on a
    # loaded machine the talker can be found later than that, so ask again until it is.
    deadline = time.monotonic() + 30.0
    while True:
        shown = wirefish(ros_env, 'topic', 'list', *options)
        assert shown.returncode == 0, shown.stderr
        if wanted in shown.stdout or time.monotonic() > deadline:
            return shown


@pytest.mark.ros
def test_topic_list_shows_topics_with_types_and_hides_hidden_ones(graph, ros_env):
    shown = _listed_once_found(ros_env, f'{NAMESPACE}/stream', '-t')
    assert f'{NAMESPACE}/stream [std_msgs/msg/String]' in shown.stdout.splitlines()
    assert '_action' not in shown.stdout
    every = _listed_once_found(ros_env, f'{NAMESPACE}/stream', '--include-hidden-topics')
    assert f'{NAMESPACE}/goal/_action/status_like' in every.stdout.splitlines()


@pytest.mark.ros
@pytest.mark.parametrize('topic, text', [('stream', 'data: hello'),
                                         ('state', 'data: latched once')])
def test_topic_echo_once_prints_a_message_as_yaml(graph, ros_env, topic, text):
    shown = wirefish(ros_env, 'topic', 'echo', topic, '--namespace', NAMESPACE, '--once')
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.splitlines() == [text, '---']


@pytest.mark.ros
def test_topic_hz_prints_the_rate_until_ctrl_c(graph, ros_env):
    proc = subprocess.Popen([*CLI, 'topic', 'hz', f'{NAMESPACE}/stream'], env=ros_env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        lines = []
        while not any(line.startswith('average rate:') for line in lines[-3:]) or \
                len([line for line in lines if line.startswith('average rate:')]) < 2:
            line = proc.stdout.readline()
            assert line, proc.stderr.read()
            lines.append(line.rstrip('\n'))
        rate = float([line for line in lines if line.startswith('average rate:')][-1].split()[2])
        assert 5.0 < rate < 40.0  # a 20 Hz timer, on a shared machine
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.wait(timeout=20) == 130
        # Discovery may be slow on a loaded machine: then a waiting line comes first.
        said = proc.stderr.read().strip().splitlines()
        assert said[-1] == 'wirefish topic: interrupted (Ctrl-C)'
        assert all(line.startswith('wirefish topic hz: waiting up to') for line in said[:-1])
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        proc.stdout.close()
        proc.stderr.close()


@pytest.mark.ros
def test_param_list_get_set_and_a_refusal(graph, ros_env):
    listed = wirefish(ros_env, 'param', 'list', f'{NAMESPACE}/talker')
    assert listed.returncode == 0 and '  gain' in listed.stdout.splitlines(), listed.stderr
    got = wirefish(ros_env, 'param', 'get', 'talker', 'gain', '--namespace', NAMESPACE)
    assert got.stdout.strip() == 'Double value is: 0.5', got.stderr
    put = wirefish(ros_env, 'param', 'set', 'talker', 'gain', '0.7', '--namespace', NAMESPACE)
    assert put.returncode == 0 and put.stdout.strip() == 'Set parameter successful'
    assert graph.get_parameter('gain').value == 0.7
    refused = wirefish(ros_env, 'param', 'set', f'{NAMESPACE}/talker', 'gain', '-1.0')
    assert refused.returncode == 1
    assert refused.stderr.strip() == 'Setting parameter failed: gain must be >= 0'
    assert graph.get_parameter('gain').value == 0.7


@pytest.mark.ros
def test_a_node_that_is_not_there_is_one_line(ros_env):
    missing = wirefish(ros_env, 'param', 'get', '/nobody_here', 'gain')
    assert missing.returncode == 1 and len(missing.stderr.strip().splitlines()) == 1
    assert 'no node /nobody_here' in missing.stderr


@pytest.mark.ros
def test_a_misspelled_topic_is_said_at_once_with_the_closest_name(graph, ros_env):
    _listed_once_found(ros_env, f'{NAMESPACE}/stream')  # the graph is discovered by now
    shown = wirefish(ros_env, 'topic', 'echo', 'strem', '--namespace', NAMESPACE, '--once')
    assert shown.returncode == 1, shown.stdout
    # Said once this process has heard the graph: at its first answer, or after a waiting line
    # when its own discovery took longer than the first window (a loaded machine).
    lines = shown.stderr.strip().splitlines()
    assert lines[-1].startswith(
        f'wirefish topic echo: topic {NAMESPACE}/strem does not exist; did you mean '
        f'{NAMESPACE}/stream'), shown.stderr
    assert all(line.startswith('wirefish topic echo: waiting up to') for line in lines[:-1])


@pytest.mark.ros
def test_param_set_takes_an_integer_for_a_double_and_says_what_to_type(graph, ros_env):
    put = wirefish(ros_env, 'param', 'set', 'talker', 'gain', '2', '--namespace', NAMESPACE)
    assert put.returncode == 0, put.stderr
    assert graph.get_parameter('gain').value == 2.0
    wrong = wirefish(ros_env, 'param', 'set', 'talker', 'gain', 'abc', '--namespace', NAMESPACE)
    assert wrong.returncode == 2
    assert wrong.stderr.strip() == ("wirefish param set: gain is a Double, 'abc' is a String: "
                                    'give a number such as 0.3'), wrong.stderr
    assert graph.get_parameter('gain').value == 2.0


@pytest.mark.ros
def test_a_misspelled_parameter_or_node_names_the_closest(graph, ros_env):
    name = wirefish(ros_env, 'param', 'set', 'talker', 'gian', '1.0', '--namespace', NAMESPACE)
    assert name.returncode == 1
    assert name.stderr.strip() == (f'wirefish param set: {NAMESPACE}/talker has no parameter '
                                   'gian; did you mean gain?'), name.stderr
    started = time.monotonic()
    node = wirefish(ros_env, 'param', 'get', 'talkr', 'gain', '--namespace', NAMESPACE)
    # Said once the graph shows its other nodes (NODE_DISCOVERY_S), not after the services'
    # 10 s wait: a bound of the message's kind, not of the machine's speed.
    assert node.returncode == 1
    assert node.stderr.strip() == (f'wirefish param get: no node {NAMESPACE}/talkr; did you '
                                   f'mean {NAMESPACE}/talker?'), node.stderr
    assert 'within' not in node.stderr and time.monotonic() - started < 30.0
