# SPDX-License-Identifier: Apache-2.0
"""
The C unit tests of the core (firmware/test/test_core.c).

Link, failsafe and its slew, servo output, and protocol v2: GAIT accepted and refused, ACK,
LINK_CONFIG, the gap's coast and rest without a step, compact telemetry, HEALTH, the CPG;
SERVO_TRIM (every refusal and its code, gait mode, the reports) and the calibration storage
(append, newest wins, a damaged record skipped, the full unit erased, reload, FACTORY, a failed
write).
"""

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
