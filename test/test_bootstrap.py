"""The bootstrap (`make setup`) stops with one clear line when a system tool is missing."""

import os
from pathlib import Path
import subprocess

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
