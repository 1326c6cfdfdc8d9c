# SPDX-License-Identifier: Apache-2.0
"""`wirefish retune` against a tuner_node process: the fit, refusals, Ctrl-C, bad options."""

import signal
import subprocess

import pytest

pytestmark = pytest.mark.ros
NAMESPACE = '/wf_cli'


def command(python: str, *options: str) -> list[str]:
    return [python, '-m', 'wirefish_cli.cli', 'retune', '--namespace', NAMESPACE,
            '--timeout', '60', *options]


def retune(python: str, env: dict[str, str], *options: str) -> subprocess.CompletedProcess:
    return subprocess.run(command(python, *options), env=env, capture_output=True, text=True,
                          timeout=120)


def test_retune_prints_the_fit_and_a_line_per_iteration(tuner, python, ros_env):
    tuner('-r', f'__ns:={NAMESPACE}')
    result = retune(python, ros_env, '--iterations', '20', '--swarm', '20')
    assert result.returncode == 0, result.stderr
    assert 'success                     True' in result.stdout
    assert 'RMSE theta1 / theta2 (deg)' in result.stdout
    assert 'from library                False' in result.stdout
    # Not a terminal: plain lines from the action's feedback, one per iteration.
    lines = [line for line in result.stderr.splitlines() if line.startswith('iteration ')]
    assert lines[0].startswith('iteration 0/20 best loss ') and 'RMSE theta' in lines[0]
    assert lines[-1].startswith('iteration 20/20 ') and lines[-1].endswith(' s')  # 'done in'
    assert any(line.endswith(' left') for line in lines[1:-1])  # the estimate of what is left
    assert len(lines) == 21


def test_the_same_wave_again_comes_from_the_library(tuner, python, ros_env):
    tuner('-r', f'__ns:={NAMESPACE}')
    assert retune(python, ros_env, '--iterations', '20', '--swarm', '20').returncode == 0
    again = retune(python, ros_env)
    assert again.returncode == 0, again.stderr
    assert 'from library                True' in again.stdout


@pytest.mark.parametrize('options, reason', [
    (('--c1', 'nan'), 'wave.c1 must be finite'),
    (('--freq', '12'), 'wave.frequency_hz must be in (0, 10] Hz'),
    (('--c1', '1e6'), 'beyond any bend of the tail'),
])
def test_a_refused_goal_prints_the_reason_and_fails(tuner, python, ros_env, options, reason):
    tuner('-r', f'__ns:={NAMESPACE}')
    result = retune(python, ros_env, *options)
    assert result.returncode == 1
    assert 'wirefish retune: rejected: ' in result.stderr and reason in result.stderr, \
        result.stderr
    assert result.stdout == ''  # no table of zeros


def test_ctrl_c_cancels_the_goal_and_the_tuner_is_free_again(tuner, python, ros_env):
    tuner('-r', f'__ns:={NAMESPACE}', '-p', 'stall_iterations:=5000')
    long_fit = subprocess.Popen(command(python, '--iterations', '5000', '--swarm', '2000'),
                                env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
    try:
        assert long_fit.stderr.readline().startswith('iteration 0/5000')  # the fit runs
        long_fit.send_signal(signal.SIGINT)
        _, stderr = long_fit.communicate(timeout=60)
    finally:
        long_fit.kill()
    assert long_fit.returncode == 130
    assert 'wirefish retune: canceled (nothing applied)' in stderr
    assert 'Traceback' not in stderr
    after = retune(python, ros_env, '--iterations', '5', '--no-library')
    assert 'busy' not in after.stderr  # the canceled fit no longer holds the tuner


@pytest.mark.parametrize('option', ['--seed', '--iterations', '--swarm'])
def test_a_count_outside_uint32_is_an_option_error(python, ros_env, option):
    result = retune(python, ros_env, option, '-1')
    assert result.returncode == 2
    assert 'must be in [0, 4294967295]' in result.stderr
    assert 'Traceback' not in result.stderr


def test_on_a_terminal_the_progress_is_one_live_bar(tuner, python, ros_env):
    import os
    import pty

    tuner('-r', f'__ns:={NAMESPACE}')
    controller, terminal = pty.openpty()
    # Read after the run: 21 redraws (~1.5 kB) fit the pty's buffer, so the writer never blocks.
    try:
        done = subprocess.run(command(python, '--iterations', '20', '--swarm', '20'),
                              env=ros_env, stdout=subprocess.PIPE, stderr=terminal, text=True,
                              timeout=120)
        os.close(terminal)
        terminal = None
        shown = b''
        while True:
            try:
                chunk = os.read(controller, 65536)
            except OSError:  # the pty is drained and closed
                break
            if not chunk:
                break
            shown += chunk
    finally:
        if terminal is not None:
            os.close(terminal)
        os.close(controller)
    assert done.returncode == 0
    text = shown.decode()
    # Redrawn in place once per iteration: back to the line's start, clear it, draw.
    assert text.count('\r\x1b[K[') == 21
    assert '[##############################] iteration 20/20  best loss ' in text
    assert 'RMSE theta' not in text  # the plain lines are for non-terminals
