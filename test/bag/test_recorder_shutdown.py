# SPDX-License-Identifier: Apache-2.0
"""A recorder in a process that shuts rclpy down before closing it stops without an error."""

import subprocess

import pytest

pytestmark = pytest.mark.ros

# As `wirefish mission` does when its graph never comes: rclpy shut down, then the recorder
# closed; in between its scan thread looks for topics on a context that is gone.
_SHUT_DOWN_FIRST = """
import sys
import time
from pathlib import Path
import rclpy
from wirefish_bag.recorder import BagRecorder, RESCAN_PERIOD_S
rclpy.init()
recorder = BagRecorder(Path(sys.argv[1]), '/nothing_here', announce=False)
recorder.start_thread()
time.sleep(RESCAN_PERIOD_S)
rclpy.try_shutdown()
time.sleep(3 * RESCAN_PERIOD_S)  # scans come due on the shut-down context
recorder.close()
print('closed')
"""


def test_a_recorder_closed_after_rclpy_shut_down_says_no_error(tmp_path, python, ros_env):
    result = subprocess.run([python, '-c', _SHUT_DOWN_FIRST, str(tmp_path / 'bag')],
                            env=ros_env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout.strip() == 'closed', result.stderr
    assert 'Traceback' not in result.stderr, result.stderr
    assert (tmp_path / 'bag' / 'metadata.yaml').exists()
