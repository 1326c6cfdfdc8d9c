# SPDX-License-Identifier: Apache-2.0
"""
`wirefish up` stops its graph even when a DDS teardown in its own process never returns.

Seen with eight graphs starting at once: the launcher's main thread sat in
``Node.destroy_node`` -> ``Publisher.destroy`` of its graph probe for good, SIGINT and SIGTERM
caught and never acted on, nothing stopped. Here every ``Node.destroy_node`` in the launcher's
process blocks forever (its graph nodes are processes of their own and stop normally): the
launcher must still get to "running:", and stop everything with exit code 0 on one SIGINT. A
launcher that closed its probe after start-up would hang there and never print "running:".
"""

import signal
import subprocess
import sys

from e2e_utils import descendants, lines_until_running
import pytest

HANGING_TEARDOWN = """
import sys
import threading

import rclpy.node


def destroy_node_that_never_returns(self):
    threading.Event().wait()


rclpy.node.Node.destroy_node = destroy_node_that_never_returns
from wirefish_cli.cli import main  # noqa: E402
sys.exit(main(sys.argv[1:]))
"""
START_TIMEOUT_S = 90.0
STOP_TIMEOUT_S = 30.0


@pytest.mark.ros
def test_a_dds_teardown_that_hangs_never_blocks_the_stop(ros_env, tmp_path):
    launcher = subprocess.Popen(
        [sys.executable, '-c', HANGING_TEARDOWN, 'up', '--sim', '--no-status', '--namespace',
         '/h24_hanging_teardown', '--out', str(tmp_path)],
        env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    seen: list[str] = []
    try:
        seen = lines_until_running(launcher, START_TIMEOUT_S)
        assert seen and seen[-1].startswith('running:'), ''.join(seen)
        children = descendants(launcher.pid)
        launcher.send_signal(signal.SIGINT)
        code = launcher.wait(timeout=STOP_TIMEOUT_S)
        output = ''.join(seen) + launcher.stdout.read()
    finally:
        if launcher.poll() is None:
            launcher.kill()
            launcher.wait()
        launcher.stdout.close()
    assert code == 0, output
    stopped = next(line for line in output.splitlines() if line.startswith('stopped'))
    codes = dict(item.split('=') for item in stopped.split(': ', 1)[1].split(', '))
    assert len(codes) == len(children) and set(codes.values()) == {'0'}, stopped
    assert not [p for p in children if p.is_running() and p.status() != 'zombie']
