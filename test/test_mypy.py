"""mypy passes over every package's modules, and the configuration does catch a wrong type."""

from pathlib import Path
import subprocess
import sys

import pytest

WORKSPACE = Path(__file__).resolve().parents[1]
CONFIG = WORKSPACE / 'mypy.ini'


def mypy(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mypy', '--config-file', str(CONFIG), *args],
                          cwd=WORKSPACE, capture_output=True, text=True, timeout=600)


@pytest.mark.linter
@pytest.mark.mypy
def test_mypy_finds_no_type_error_in_src():
    result = mypy()
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.linter
@pytest.mark.mypy
def test_mypy_with_this_configuration_refuses_a_wrong_type(tmp_path):
    module = tmp_path / 'wrong_type.py'
    module.write_text('def rate_hz() -> float:\n    return "fast"\n')
    result = mypy('--cache-dir', str(tmp_path / 'cache'), str(module))
    assert result.returncode == 1, result.stdout + result.stderr
    assert 'Incompatible return value type (got "str", expected "float")' in result.stdout
