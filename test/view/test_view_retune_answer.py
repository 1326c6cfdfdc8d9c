# SPDX-License-Identifier: Apache-2.0
"""
A retune from a Foxglove client is answered even when the tuner answers before it is filed.

rclpy's ActionClient sends a goal's request, then files the goal's future under the request's
number. The view's service handler runs on the Foxglove server's thread and the executor that
takes the answer on the node's: an answer taken between the two was dropped ("Ignoring
unexpected goal response"), and the dashboard waited for a fit that never reported. Here the
filing is slowed by a quarter of a second, so that gap is always there. The view node and a
tuner stand-in (it accepts and succeeds at once) run in this process on the nodes' executor.
"""

from collections.abc import Iterator
import json
import threading
import time

from foxglove_client import FoxgloveClient
import pytest
from rclpy.action import ActionServer
from rclpy.node import Node
from rclpy.parameter import Parameter
from wirefish_common.executors import executor_kind, make_executor, spin_until_stopped
from wirefish_msgs.action import RetuneGait
from wirefish_view.view_node import ViewNode

pytestmark = pytest.mark.ros

NAMESPACE = '/fish'
FILING_DELAY_S = 0.25


class _SlowFiling(dict):
    """A goal-request table whose filing waits: the window of the race, held open."""

    def __setitem__(self, key, value) -> None:
        time.sleep(FILING_DELAY_S)
        super().__setitem__(key, value)


def _succeed_at_once(handle) -> RetuneGait.Result:
    handle.succeed()
    result = RetuneGait.Result()
    result.success = True
    result.message = 'fitted'
    return result


@pytest.fixture
def view(ros_context) -> Iterator[ViewNode]:
    """Yield a view node (WebSocket on a free port) and a tuner stand-in, spun in a thread."""
    view = ViewNode(context=ros_context, namespace=NAMESPACE, parameter_overrides=[
        Parameter('port', value=0), Parameter('http_port', value=-1)])
    tuner = Node('tuner_node', context=ros_context, namespace=NAMESPACE)
    server = ActionServer(tuner, RetuneGait, 'retune_gait', execute_callback=_succeed_at_once)
    executor = make_executor(executor_kind(), context=ros_context)
    executor.add_node(view)
    executor.add_node(tuner)
    stopped = threading.Event()
    spinner = threading.Thread(target=spin_until_stopped, args=(executor, stopped.is_set))
    spinner.start()
    try:
        yield view
    finally:
        stopped.set()
        spinner.join(10.0)
        server.destroy()
        for node in (view, tuner):
            executor.remove_node(node)
            node.destroy_node()


def test_a_retune_whose_answer_beats_its_filing_reports_done(view):
    assert hasattr(view._retune, '_pending_goal_requests')  # rclpy's table, slowed below
    view._retune._pending_goal_requests = _SlowFiling()
    client = FoxgloveClient(f'ws://127.0.0.1:{view._front.port}')
    try:
        service = f'{NAMESPACE}/retune_gait'
        assert client.wait(lambda: service in client.services and client.channel_of(
            f'{NAMESPACE}/view/retune') is not None, 20.0)
        progress = client.subscribe(client.channel_of(f'{NAMESPACE}/view/retune')['id'])

        def reports() -> list[dict]:
            return [json.loads(payload) for _, payload in client.messages.get(progress, [])]

        for attempt in (1, 2):  # the second is accepted: the first left the view free
            call = client.call(service, b'{"max_iterations": 1}')
            assert client.wait(lambda: call in client.responses, 20.0)
            assert json.loads(client.responses[call])['success'] is True, client.responses[call]
            assert client.wait(lambda: sum(r['state'] == 'done' for r in reports()) == attempt,
                               10.0), reports()
        done = [r for r in reports() if r['state'] == 'done']
        assert all(r['success'] and r['message'] == 'fitted' for r in done), done
    finally:
        client.close()
