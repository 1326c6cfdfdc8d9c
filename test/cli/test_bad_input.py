# SPDX-License-Identifier: Apache-2.0
"""
Bad input on the command line: one clear line, a nonzero exit, nothing written.

Each command runs as a user runs it (its own process, in an empty working directory), so a
traceback, a second line or a directory left behind is seen.
"""

import os
import pty
import select
import subprocess
import sys
import time

import pytest

# Short-lived processes that mostly wait on a missing graph: 0.20-0.29 of a core in full runs,
# no timing claim; no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

CLI = [sys.executable, '-m', 'wirefish_cli.cli']
# command -> (exit code, what its one line says)
REFUSED = {
    'up --port /etc/passwd': (['up', '--port', '/etc/passwd'], 2, 'is a regular file'),
    'up --port /dev/null': (['up', '--port', '/dev/null'], 2, 'is a mem device, not a serial'),
    'up --params-file missing': (['up', '--params-file', '/nonexistent.yaml'], 2,
                                 '--params-file /nonexistent.yaml does not exist'),
    "up --namespace ''": (['up', '--namespace', ''], 2, 'an empty namespace'),
    "drive --namespace ''": (['drive', '--namespace', ''], 2, 'an empty namespace'),
    "record --namespace ''": (['record', '--namespace', '', '--duration', '1'], 2,
                              'an empty namespace'),
    "mission --namespace ''": (['mission', 'square', '--namespace', ''], 2,
                               'an empty namespace'),
    "retune --namespace ''": (['retune', '--namespace', '', '--c1', '0.15'], 2,
                              'an empty namespace'),
    'report missing': (['report', '/nonexistent'], 2, '/nonexistent does not exist'),
    'bag reindex missing': (['bag', 'reindex', '/nonexistent'], 2, 'does not exist'),
    'mission circle': (['mission', 'circle'], 2, 'shipped: square'),
    'gaits list --library missing': (['gaits', 'list', '--library', '/nonexistent.yaml'], 1,
                                     'no gait library at /nonexistent.yaml: the file does not '
                                     'exist'),
}
# A misspelled option: the verb's own usage (not the top-level one), and the closest option.
MISSPELLED = {
    'drive --namesapce': (['drive', '--namesapce', '/x'], 'usage: wirefish drive',
                          '(did you mean --namespace?)'),
    'record --durration': (['record', '--durration', '5'], 'usage: wirefish record',
                           '(did you mean --duration?)'),
}


@pytest.mark.parametrize('args, usage, hint', MISSPELLED.values(), ids=MISSPELLED.keys())
def test_a_misspelled_option_prints_the_verbs_usage_and_the_closest(tmp_path, args, usage,
                                                                    hint):
    result = subprocess.run([*CLI, *args], cwd=tmp_path, capture_output=True, text=True,
                            timeout=60, stdin=subprocess.DEVNULL)
    assert result.returncode == 2
    assert result.stderr.startswith(usage), result.stderr
    assert result.stderr.rstrip().endswith(hint), result.stderr


def _one_line_refusal(result: subprocess.CompletedProcess, code: int, says: str) -> None:
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == code, result.stderr
    assert len(lines) == 1 and says in lines[0] and 'Traceback' not in result.stderr, (
        result.stderr)


@pytest.mark.parametrize('args, code, says', REFUSED.values(), ids=REFUSED.keys())
def test_bad_input_is_refused_in_one_line_and_writes_nothing(tmp_path, ros_env, args, code,
                                                             says):
    result = subprocess.run([*CLI, *args], cwd=tmp_path, env=ros_env, capture_output=True,
                            text=True, timeout=60, stdin=subprocess.DEVNULL)
    _one_line_refusal(result, code, says)
    assert list(tmp_path.iterdir()) == []


def test_bag_reindex_of_an_empty_folder_says_there_is_no_bag(tmp_path):
    empty = tmp_path / 'bag'
    empty.mkdir()
    result = subprocess.run([*CLI, 'bag', 'reindex', str(empty)], capture_output=True,
                            text=True, timeout=60)
    _one_line_refusal(result, 2, 'holds no .mcap file: not a rosbag2 bag')
    assert '`wirefish bag reindex' not in result.stderr  # no advice to run itself
    assert list(empty.iterdir()) == []


@pytest.mark.ros
def test_a_mission_without_a_graph_says_so_and_leaves_no_directory(tmp_path, ros_env):
    result = subprocess.run([*CLI, 'mission', 'square', '--namespace', '/no_graph_here',
                             '--wait', '6'], cwd=tmp_path, env=ros_env, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 1, result.stderr
    assert 'waiting for planner_state and sim/ground_truth under /no_graph_here' in result.stderr
    assert 'nothing was written' in result.stderr and 'Traceback' not in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.ros
def test_drive_without_a_graph_says_which_graph_it_waits_for(spawn, tmp_path):
    master, slave = pty.openpty()
    try:
        drive = spawn([*CLI, 'drive', '--namespace', '/no_graph_here'], stdin=slave,
                      stdout=slave, stderr=slave, cwd=tmp_path)
        seen = b''
        deadline = time.monotonic() + 60.0
        # The status line is cut at the terminal's width: wait for its start, not its end.
        while (b'no planner_state in /no_graph_here after' not in seen
               and time.monotonic() < deadline):
            if select.select([master], [], [], 0.5)[0]:
                seen += os.read(master, 4096)
        assert b'no planner_state in /no_graph_here after' in seen, seen[-400:]
        os.write(master, b'q')
        assert drive.wait(timeout=10.0) == 0
    finally:
        os.close(master)
        os.close(slave)


def test_output_into_a_closed_pipe_ends_quietly(tmp_path):
    proc = subprocess.Popen([*CLI, 'gaits', 'list', '--library', str(tmp_path / 'gaits.yaml')],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.stdout.close()  # the reader left before anything was written (`| head -0`)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 1 and 'Traceback' not in stderr and 'BrokenPipe' not in stderr, (
        stderr)


@pytest.mark.ros
def test_a_mission_interrupted_before_its_first_leg_exits_130_and_leaves_nothing(
        tmp_path, ros_env):
    import signal

    proc = subprocess.Popen([*CLI, 'mission', 'square', '--namespace', '/no_graph_here',
                             '--wait', '60'], cwd=tmp_path, env=ros_env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        assert 'waiting for planner_state' in proc.stderr.readline()  # after HINT_AFTER_S
        os.killpg(proc.pid, signal.SIGINT)
        _, stderr = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, stderr
    assert stderr.strip() == ('wirefish mission: interrupted (Ctrl-C) before the first leg; '
                              'nothing was written')
    assert list(tmp_path.iterdir()) == []
