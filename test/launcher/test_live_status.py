# SPDX-License-Identifier: Apache-2.0
"""LiveStatus on real DDS: rates of what is published, latched state, hidden topics left out."""

import time

import pytest

NAMESPACE = '/live_status'


@pytest.mark.ros
def test_the_status_counts_streams_shows_latched_state_and_hides_action_topics(ros_context):
    import rclpy
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String
    from wirefish_launcher.status_view import LiveStatus

    publisher_node = rclpy.create_node('publishers', namespace=NAMESPACE, context=ros_context)
    watcher = rclpy.create_node('watcher', namespace=NAMESPACE, context=ros_context)
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    stream = publisher_node.create_publisher(String, 'stream', reliable)
    state = publisher_node.create_publisher(String, 'state', latched)
    hidden = publisher_node.create_publisher(String, 'goal/_action/feedback', reliable)
    state.publish(String(data='once'))
    try:
        deadline = time.monotonic() + 20.0
        live = LiveStatus(watcher, NAMESPACE)
        while time.monotonic() < deadline and not all(
                f'{NAMESPACE}/{t}' in ' '.join(live.lines()) for t in ('stream', 'state')):
            time.sleep(0.1)
            live.refresh()
        for _ in range(40):  # 20 messages a refresh: what is taken is counted
            for _ in range(20):
                stream.publish(String(data='x'))
                hidden.publish(String(data='x'))
            time.sleep(0.05)
            live.refresh()
        # /diagnostics is watched too, whoever publishes it on this domain: not counted here.
        rows = {line.split()[0]: line for line in live.lines()[2:]
                if line.startswith(f'{NAMESPACE}/')}
        assert set(rows) == {f'{NAMESPACE}/stream', f'{NAMESPACE}/state'}, rows
        assert rows[f'{NAMESPACE}/state'].endswith('latched'), rows
        assert rows[f'{NAMESPACE}/stream'].endswith(' Hz'), rows
        assert float(rows[f'{NAMESPACE}/stream'].split()[-2]) > 0.0, rows
        assert live.header().endswith('| battery: no battery yet | planner: no planner_state yet')
        live.close()
        assert live.lines()[2:] == [] and not list(watcher.subscriptions)
    finally:
        watcher.destroy_node()
        publisher_node.destroy_node()
