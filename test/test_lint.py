# SPDX-License-Identifier: Apache-2.0
"""
The workspace's own Python outside the packages (tests, tools) follows the same lint rules.

The packages lint themselves (each package's test_<package>_flake8.py / _pep257.py). Every test
file's name is its own in the workspace: pytest's default import mode imports a test module by
its file name, and a second file of that name is an error there ("import file mismatch").

flake8 runs in a process of its own: it forks its checkers, and a fork of a test worker that
holds rclpy's DDS threads (an earlier test's context) can copy a lock one of them held, so the
forked checker waits on it for ever (seen once: the test timed out after 300 s in a full run).
"""

from pathlib import Path
import subprocess
import sys

from ament_pep257.main import main as pep257_main
import pytest

WORKSPACE = Path(__file__).resolve().parents[1]
PATHS = [str(WORKSPACE / 'test'), str(WORKSPACE / 'tools')]


def shared_names(paths: list[Path]) -> dict[str, list[str]]:
    """Return each file name that more than one of ``paths`` has, with their directories."""
    where: dict[str, list[str]] = {}
    for path in paths:
        where.setdefault(path.name, []).append(str(path.parent.relative_to(WORKSPACE)))
    return {name: dirs for name, dirs in where.items() if len(dirs) > 1}


@pytest.mark.linter
def test_flake8_on_tests_and_tools():
    run = subprocess.run(
        [sys.executable, '-c', 'import sys; from ament_flake8.main import main; '
         'sys.exit(main(sys.argv[1:]))', *PATHS],
        capture_output=True, text=True, timeout=240.0)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]


@pytest.mark.linter
def test_pep257_on_tests_and_tools():
    assert pep257_main(argv=PATHS) == 0


@pytest.mark.linter
def test_every_test_file_name_is_unique_in_the_workspace():
    tests = sorted(p for top in ('src', 'test') for p in (WORKSPACE / top).rglob('test_*.py'))
    shared = shared_names(tests)
    assert tests and not shared, shared


def test_a_shared_test_file_name_is_found():
    paths = [WORKSPACE / 'src' / 'a' / 'test' / 'test_x.py', WORKSPACE / 'test' / 'test_x.py',
             WORKSPACE / 'test' / 'test_y.py']
    assert shared_names(paths) == {'test_x.py': ['src/a/test', 'test']}
