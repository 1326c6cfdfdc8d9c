"""`wirefish retune` against a tuner_node process: the fit, the tuner's refusals, bad options."""

import subprocess

from cpg_probe import TUNER_NODE
import pytest

pytestmark = pytest.mark.ros
NAMESPACE = '/wf_cli'


def retune(python: str, env: dict[str, str], *options: str) -> subprocess.CompletedProcess:
    return subprocess.run([python, '-m', 'wirefish_bringup.cli', 'retune', '--namespace',
                           NAMESPACE, '--timeout', '60', *options],
                          env=env, capture_output=True, text=True, timeout=120)


def test_retune_prints_the_fit_and_its_progress(spawn, python, ros_env):
    spawn([TUNER_NODE, '--ros-args', '-r', f'__ns:={NAMESPACE}'])
    result = retune(python, ros_env, '--iterations', '20', '--swarm', '20')
    assert result.returncode == 0, result.stderr
    assert 'success                     True' in result.stdout
    assert 'RMSE theta1 / theta2 (deg)' in result.stdout
    assert 'iteration 20/20' in result.stderr  # the bar, fed by retune_progress


@pytest.mark.parametrize('options, reason', [
    (('--c1', 'nan'), 'wave.c1 must be finite'),
    (('--freq', '12'), 'wave.frequency_hz must be in (0, 10] Hz'),
])
def test_a_refused_request_prints_the_reason_and_fails(spawn, python, ros_env, options, reason):
    spawn([TUNER_NODE, '--ros-args', '-r', f'__ns:={NAMESPACE}'])
    result = retune(python, ros_env, *options)
    assert result.returncode == 1
    assert f'wirefish retune: rejected: {reason}' in result.stderr, result.stderr
    assert result.stdout == ''  # no table of zeros


@pytest.mark.parametrize('option', ['--seed', '--iterations', '--swarm'])
def test_a_count_outside_uint32_is_an_option_error(python, ros_env, option):
    result = retune(python, ros_env, option, '-1')
    assert result.returncode == 2
    assert 'must be in [0, 4294967295]' in result.stderr
    assert 'Traceback' not in result.stderr
