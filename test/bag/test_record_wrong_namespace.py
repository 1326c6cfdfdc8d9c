# SPDX-License-Identifier: Apache-2.0
"""`wirefish record --namespace <a typo>`: a warning, and no word of a killed recorder."""

import subprocess
import sys
import threading

import pytest

# It mostly waits (0.15 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine


@pytest.mark.ros
def test_a_namespace_without_topics_is_warned_about(ros_env, ros_context, talker_namespace,
                                                    tmp_path):
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray

    # /diagnostics is shared by every graph of the domain: it is recorded whatever the namespace.
    node = rclpy.create_node('diagnostics_talker', context=ros_context)
    publisher = node.create_publisher(DiagnosticArray, '/diagnostics', 10)
    done = threading.Event()

    def publish() -> None:
        while not done.wait(0.2):
            publisher.publish(DiagnosticArray())

    thread = threading.Thread(target=publish)
    thread.start()
    try:
        result = subprocess.run(
            [sys.executable, '-m', 'wirefish_cli.cli', 'record', '--namespace', '/nope',
             '--duration', '5', '-o', str(tmp_path / 'bag')],
            env=ros_env, capture_output=True, text=True, timeout=90)
    finally:
        done.set()
        thread.join()
        node.destroy_node()
    assert result.returncode == 0, result.stderr
    assert 'warning: no topic under /nope' in result.stderr, result.stderr
    assert talker_namespace in result.stderr, result.stderr  # where the nodes are
    assert 'killed' not in result.stdout, result.stdout
    assert result.stdout.splitlines()[-1] == (
        'recording: no topic under /nope (only /diagnostics): is the namespace right?'), \
        result.stdout
