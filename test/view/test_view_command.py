# SPDX-License-Identifier: Apache-2.0
"""`wirefish view` on its own: it binds this machine only unless told, and says so when told."""

import json
import sys
import time
import urllib.request

from foxglove_client import free_port
import psutil
import pytest

pytestmark = pytest.mark.ros


def _listening(pid: int, ports: set[int], timeout_s: float) -> set[str]:
    """Return the addresses ``pid`` listens on at ``ports``, once it listens on all of them."""
    deadline = time.monotonic() + timeout_s
    found: dict[int, str] = {}
    while time.monotonic() < deadline and set(found) != ports:
        for c in psutil.Process(pid).net_connections(kind='tcp'):
            if c.status == psutil.CONN_LISTEN and c.laddr.port in ports:
                found[c.laddr.port] = c.laddr.ip
        time.sleep(0.2)
    return set(found.values())


@pytest.mark.parametrize('options, address, warned', [
    ((), '127.0.0.1', False),
    (('--address', '0.0.0.0'), '0.0.0.0', True)])
def test_the_view_binds_where_it_is_told_and_warns_when_wider(spawn, options, address, warned):
    ws_port, http_port = free_port(), free_port()
    view = spawn([sys.executable, '-m', 'wirefish_cli.cli', 'view', '--namespace',
                  '/view_command', '--port', str(ws_port), '--http-port', str(http_port),
                  *options])
    assert _listening(view.pid, {ws_port, http_port}, 30.0) == {address}
    with urllib.request.urlopen(f'http://127.0.0.1:{http_port}/config.json', timeout=10) as r:
        config = json.loads(r.read())
    assert (config['websocket_port'], config['namespace']) == (ws_port, '/view_command')
    with urllib.request.urlopen(f'http://127.0.0.1:{http_port}/', timeout=10) as r:
        assert b'dashboard.js' in r.read()
    view.send_signal(2)
    output, _ = view.communicate(timeout=20)
    assert view.returncode == 0, output
    assert ('binding 0.0.0.0' in output) == warned, output


def test_a_port_in_use_is_one_fatal_line_not_a_traceback(spawn):
    ws_port, http_port = free_port(), free_port()
    first = spawn([sys.executable, '-m', 'wirefish_cli.cli', 'view', '--namespace', '/view_one',
                   '--port', str(ws_port), '--http-port', str(http_port)])
    assert _listening(first.pid, {ws_port, http_port}, 30.0) == {'127.0.0.1'}
    for ports in ((ws_port, free_port()), (0, http_port)):
        second = spawn([sys.executable, '-m', 'wirefish_cli.cli', 'view', '--namespace',
                        '/view_two', '--port', str(ports[0]), '--http-port', str(ports[1])])
        output, _ = second.communicate(timeout=60)
        assert second.returncode == 1, output
        assert 'Traceback' not in output and output.count('[FATAL]') == 1, output
        assert 'another view' in output and str(ws_port if ports[0] else http_port) in output
    first.send_signal(2)
    first.communicate(timeout=20)
