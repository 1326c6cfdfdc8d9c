# SPDX-License-Identifier: Apache-2.0
"""
Long commands show their progress with an estimate, and Ctrl-C stops each in one line, exit 130.

Each runs as its own process group, and the SIGINT goes to the whole group, as a terminal's
Ctrl-C does: a process pool's workers get it too and must not print a traceback of their own.
"""

import os
import signal
import subprocess
import sys
import threading

import pytest

CLI = [sys.executable, '-m', 'wirefish_cli.cli']
LONG = {
    'sweep': ['sweep', '-o', '{tmp}/sweep'],
    'identify-geometry': ['identify-geometry', '--out', '{tmp}/geometry.yaml', '--starts', '2'],
    'gaits build': ['gaits', 'build', '--library', '{tmp}/gaits.yaml', '--workers', '2',
                    '--frequencies', '0.5,1,1.5,2', '--scales', '0.5,1,1.5'],
}


def _lines(stream, into: list[str], first: threading.Event) -> None:
    for line in stream:
        into.append(line.rstrip('\n'))
        if ' left' in line:
            first.set()
    first.set()


@pytest.mark.parametrize('command', LONG.values(), ids=LONG.keys())
def test_progress_then_ctrl_c_stops_with_one_line_and_exit_130(tmp_path, command):
    args = [part.replace('{tmp}', str(tmp_path)) for part in command]
    proc = subprocess.Popen([*CLI, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, cwd=tmp_path)
    lines: list[str] = []
    progressed = threading.Event()
    reader = threading.Thread(target=_lines, args=(proc.stderr, lines, progressed))
    reader.start()
    try:
        assert progressed.wait(timeout=240), lines
        assert proc.poll() is None, f'ended before it could be interrupted: {lines}'
        estimate = next(line for line in lines if ' left' in line)
        assert estimate.startswith(f'{command[0]}') and '/' in estimate, estimate
        os.killpg(proc.pid, signal.SIGINT)
        code = proc.wait(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        reader.join(timeout=10)
        proc.stdout.close()
        proc.stderr.close()
    assert code == 130, lines
    assert lines[-1] == f'wirefish {command[0]}: interrupted (Ctrl-C)', lines
    assert not any('Traceback' in line or 'KeyboardInterrupt' in line for line in lines), lines
