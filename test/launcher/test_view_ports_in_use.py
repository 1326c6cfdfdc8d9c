# SPDX-License-Identifier: Apache-2.0
"""`wirefish up --view` beside another dashboard: one line naming the port and the flag."""

import socket
import subprocess
import sys


def test_a_view_port_in_use_is_one_line_naming_the_flag(tmp_path, ros_env):
    with socket.socket() as taken:  # another dashboard's WebSocket server, as the OS sees it
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = subprocess.run(
            [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--view', '--no-status',
             '--namespace', '/second_view', '--view-port', str(port), '--view-http-port', '0',
             '--out', str(tmp_path / 'out')],
            env=ros_env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stdout + result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines == [f'wirefish up: the live view cannot bind 127.0.0.1:{port} (Address already '
                     'in use; another `wirefish view` or `wirefish up --view`?): give '
                     '--view-port another port (0: any free one)'], result.stderr
    assert not (tmp_path / 'out').exists()  # nothing started, nothing written
