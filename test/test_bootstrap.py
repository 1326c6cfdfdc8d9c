# SPDX-License-Identifier: Apache-2.0
"""
The bootstrap (`make setup`) says what is missing in one line and redoes only what changed.

A missing system tool stops it with one line naming the package; nothing changed, nothing is
rebuilt; new requirements are installed into the existing venv (not a new one).
"""

import os
from pathlib import Path
import subprocess
import sys

import pytest

WORKSPACE = Path(__file__).resolve().parents[1]
BOOTSTRAP = WORKSPACE / 'tools' / 'bootstrap.sh'


def path_without(tmp_path: Path, missing: str) -> str:
    """Return a PATH holding every executable of the current PATH except ``missing``."""
    bin_dir = tmp_path / 'bin'
    bin_dir.mkdir()
    for directory in os.environ['PATH'].split(os.pathsep):
        if not os.path.isdir(directory):
            continue
        for entry in os.scandir(directory):
            target = bin_dir / entry.name
            if entry.name == missing or target.exists():
                continue
            if entry.is_file() and os.access(entry.path, os.X_OK):
                target.symlink_to(entry.path)
    return str(bin_dir)


def run_bootstrap(env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(['bash', str(BOOTSTRAP)], env=env, capture_output=True, text=True,
                          timeout=120)


@pytest.mark.parametrize('tool, install_hint', [
    ('cmake', 'apt-get install cmake'),
    ('c++', 'apt-get install g++'),
    ('make', 'apt-get install make'),
    ('npm', 'apt-get install npm'),
])
def test_missing_system_tool_gives_one_line_naming_the_package(tmp_path, tool, install_hint):
    env = dict(os.environ, PATH=path_without(tmp_path, tool),
               WIREFISH_VENV=str(tmp_path / 'venv'))
    env.pop('ROS_DISTRO', None)
    result = run_bootstrap(env)
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert f"'{tool}' not found" in lines[0] and install_hint in lines[0]
    assert 'Traceback' not in result.stdout + result.stderr
    assert not (tmp_path / 'venv').exists()  # it stopped before touching anything


def test_missing_python_gives_one_line_naming_the_version(tmp_path):
    env = dict(os.environ, WIREFISH_PYTHON='python3.99-missing',
               WIREFISH_VENV=str(tmp_path / 'venv'))
    env.pop('ROS_DISTRO', None)
    result = run_bootstrap(env)
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "'python3.99-missing' not found" in lines[0]
    assert not (tmp_path / 'venv').exists()


def test_second_setup_with_nothing_changed_rebuilds_nothing():
    result = run_bootstrap(dict(os.environ))
    assert result.returncode == 0, result.stderr
    assert 'is up to date' in result.stdout
    assert 'install/ is up to date' in result.stdout
    assert 'colcon build' not in result.stdout


def test_changed_requirements_are_installed_into_the_venv_in_place(tmp_path):
    # A venv made by an earlier setup with other requirements: its python runs the workspace
    # venv's (whose packages already satisfy every requirement, so pip installs nothing).
    venv = tmp_path / 'venv'
    (venv / 'bin').mkdir(parents=True)
    python = venv / 'bin' / 'python'
    python.write_text(f'#!/bin/sh\nexec {sys.executable} "$@"\n')
    python.chmod(0o755)
    keep = venv / 'kept-by-an-update'
    keep.write_text('')
    interpreter = os.environ.get('WIREFISH_PYTHON', 'python3.11')
    version = subprocess.run([interpreter, '-c', 'import sys; print(sys.version)'],
                             capture_output=True, text=True, check=True).stdout.strip()
    (venv / '.wirefish-stamp').write_text(f'wheels {version} an-older-requirements-hash  -\n')
    env = dict(os.environ, WIREFISH_VENV=str(venv))
    env.pop('ROS_DISTRO', None)
    result = run_bootstrap(env)
    assert result.returncode == 0, result.stderr
    assert 'updating' in result.stdout and 'creating' not in result.stdout, result.stdout
    assert keep.exists()  # the venv was not recreated
    assert 'an-older-requirements-hash' not in (venv / '.wirefish-stamp').read_text()
