# SPDX-License-Identifier: Apache-2.0
"""`wirefish record --duration` on a terminal: its bar is not broken by log lines."""

import os
import pty
import subprocess
import sys
import time

import pytest

# It mostly waits (0.19 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine


@pytest.mark.ros
def test_the_record_bar_has_no_log_lines_in_it(ros_env, talker_namespace, tmp_path):
    master, slave = pty.openpty()
    try:
        record = subprocess.Popen(
            [sys.executable, '-m', 'wirefish_cli.cli', 'record', '--namespace',
             talker_namespace, '--duration', '3', '-o', str(tmp_path / 'bag')],
            env=ros_env, stdin=subprocess.DEVNULL, stdout=slave, stderr=slave,
            start_new_session=True)
        os.close(slave)
        slave = -1
        seen = b''
        deadline = time.monotonic() + 90.0
        while record.poll() is None and time.monotonic() < deadline:
            try:
                seen += os.read(master, 4096)
            except OSError:  # the pty's other end closed
                break
        assert record.wait(timeout=30) == 0, seen.decode(errors='replace')
    finally:
        if slave >= 0:
            os.close(slave)
        os.close(master)
    text = seen.decode(errors='replace')
    assert 'record bag: [' in text, text  # the bar was drawn
    assert '[INFO]' not in text, text
    assert f'{talker_namespace}/body_wave' in text  # the summary names what was recorded
