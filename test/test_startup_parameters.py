# SPDX-License-Identifier: Apache-2.0
"""A node started with values it would refuse in a `ros2 param set` exits with one clear line."""

import os
import subprocess

from ament_index_python.packages import get_package_prefix
import pytest

pytestmark = pytest.mark.ros


def executable(package: str, name: str) -> str:
    return os.path.join(get_package_prefix(package), 'lib', package, name)


@pytest.mark.parametrize('package, node, override, reason', [
    ('wirefish_cpg', 'cpg_node', 'servo_limit_rad:=0.0', 'servo_limit_rad must be > 0'),
    ('wirefish_cpg', 'cpg_node', 'frequency_hz:=0.0', 'frequency_hz must be > 0'),
    ('wirefish_cpg', 'cpg_node', 'amplitude_1:=3.0', 'amplitude_1'),  # beyond the range
    ('wirefish_tuner', 'tuner_node', 'swarm_size:=0', 'swarm_size'),
    ('wirefish_kinematics', 'kinematics_node', 'l1:=-0.08', 'l1'),
    ('wirefish_bridge', 'bridge_node', 'reconnect_backoff_max_s:=0.01',
     'reconnect_backoff_max_s must be >= reconnect_backoff_min_s'),
])
def test_a_node_refuses_to_start_on_invalid_values(ros_env, package, node, override, reason):
    result = subprocess.run([executable(package, node), '--ros-args', '-p', override],
                            env=ros_env, capture_output=True, text=True, timeout=60)
    output = result.stdout + result.stderr
    assert result.returncode == 1, output
    assert reason in output and node in output, output
    assert 'Traceback' not in output, output


@pytest.mark.parametrize('package, node, override, expected, given', [
    ('wirefish_bridge', 'bridge_node', 'baudrate:=fast', 'an integer', "a string 'fast'"),
    ('wirefish_bridge', 'bridge_node', 'baudrate:=115200.0', 'an integer',
     "a double '115200.0'"),
    ('wirefish_cpg', 'cpg_node', 'frequency_hz:=2', 'a double', "an integer '2'"),
    ('wirefish_tuner', 'tuner_node', 'swarm_size:=true', 'an integer', "a bool 'True'"),
    ('wirefish_kinematics', 'kinematics_node', 'l1:=long', 'a double', "a string 'long'"),
    ('wirefish_planner', 'planner_node', 'cmd_vel_timeout_s:=1', 'a double', "an integer '1'"),
])
def test_a_value_of_the_wrong_type_gives_one_fatal_line(
        ros_env, package, node, override, expected, given):
    result = subprocess.run([executable(package, node), '--ros-args', '-p', override],
                            env=ros_env, capture_output=True, text=True, timeout=60)
    lines = (result.stdout + result.stderr).strip().splitlines()
    name = override.split(':=')[0]
    assert result.returncode == 1, lines
    assert len(lines) == 1 and '[FATAL]' in lines[0], lines
    assert f'{node}: parameter {name} must be {expected}' in lines[0], lines
    assert f'given {given}' in lines[0], lines


def test_a_parameter_file_value_of_the_wrong_type_gives_the_same_line(ros_env, tmp_path):
    params = tmp_path / 'params.yaml'
    params.write_text('cpg_node:\n  ros__parameters:\n    frequency_hz: 2\n')
    result = subprocess.run([executable('wirefish_cpg', 'cpg_node'), '--ros-args',
                             '--params-file', str(params)],
                            env=ros_env, capture_output=True, text=True, timeout=60)
    lines = (result.stdout + result.stderr).strip().splitlines()
    assert result.returncode == 1, lines
    assert len(lines) == 1 and '[FATAL]' in lines[0], lines
    assert 'cpg_node: parameter frequency_hz must be a double (default' in lines[0], lines
    assert "given an integer '2' (write 2.0)" in lines[0], lines
