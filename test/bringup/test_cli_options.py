"""The wirefish command refuses bad options with one line, before anything starts."""

import os
import subprocess

import pytest
from wirefish_launcher.supervisor import remove_stale_link


@pytest.mark.parametrize('command', [
    ('record', '-o', 'never_written'),
    ('up', '--sim', '--no-status'),
])
@pytest.mark.parametrize('duration', ['-1', '0', 'nan', 'inf', 'ten'])
def test_a_duration_that_is_not_a_positive_finite_number_is_refused(
        tmp_path, python, ros_env, command, duration):
    result = subprocess.run([python, '-m', 'wirefish_cli.cli', *command, '--duration',
                             duration], env=ros_env, cwd=tmp_path, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 2
    assert 'argument --duration' in result.stderr and 'Traceback' not in result.stderr
    assert list(tmp_path.iterdir()) == []  # nothing started, nothing written


def test_a_stale_pty_link_is_removed_and_a_missing_one_is_fine(tmp_path):
    link = tmp_path / 'wirefish-x-tty'
    os.symlink('/dev/pts/999999', link)  # what a killed virtual fish leaves behind
    remove_stale_link(link)
    assert not link.is_symlink()
    remove_stale_link(link)  # nothing there: nothing to do
