"""
The workspace's own Python outside the packages (tests, tools) follows the same lint rules.

The packages lint themselves (each package's test_flake8.py / test_pep257.py).
"""

from pathlib import Path

from ament_flake8.main import main_with_errors
from ament_pep257.main import main as pep257_main
import pytest

WORKSPACE = Path(__file__).resolve().parents[1]
PATHS = [str(WORKSPACE / 'test'), str(WORKSPACE / 'tools')]


@pytest.mark.linter
def test_flake8_on_tests_and_tools():
    rc, errors = main_with_errors(argv=PATHS)
    assert rc == 0, '\n'.join(errors)


@pytest.mark.linter
def test_pep257_on_tests_and_tools():
    assert pep257_main(argv=PATHS) == 0
