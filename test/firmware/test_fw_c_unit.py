"""The C unit tests of the core (firmware/test/test_core.c: link, failsafe, servo output)."""

import subprocess

from firmware_host import BUILD
import pytest


@pytest.mark.parametrize('build', ['host', 'asan'])
def test_c_unit_tests_pass(firmware_build: None, build: str):
    # asan: the same tests under AddressSanitizer and UBSan, any report fatal.
    result = subprocess.run([str(BUILD / build / 'test_core')], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stderr == ''
    assert 'checks passed' in result.stdout
