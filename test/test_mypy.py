# SPDX-License-Identifier: Apache-2.0
"""
mypy passes over every package's modules, strict on the pure ones; the configuration says why not.

mypy.ini gives mypy --strict's checks to every module of the packages its strict section names,
but the ROS-facing ones (rclpy and the ROS messages have no types) and the exceptions it lists
with a reason. Read from mypy.ini and the modules' imports, so a new package, a new pure module
in a relaxed section, or a ROS-facing module that stopped importing ROS fails here.
"""

import ast
import configparser
from pathlib import Path
import re
import subprocess
import sys

import pytest

WORKSPACE = Path(__file__).resolve().parents[1]
CONFIG = WORKSPACE / 'mypy.ini'
SRC = WORKSPACE / 'src'
# Imports that make a module ROS-facing: rclpy, ROS libraries and every message package.
ROS = re.compile(r'rclpy|ament_index_python|rosbags|mcap|foxglove|tf2_ros|rpyutils'
                 r'|rosidl_\w+|\w+_msgs|std_srvs|rcl_interfaces|launch(_ros)?')


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


def imports_ros(path: Path) -> bool:
    """Whether the module at ``path`` imports rclpy, a ROS library or a message package."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
        if isinstance(node, ast.Import):
            names |= {alias.name.split('.')[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module.split('.')[0])
    return any(ROS.fullmatch(name) for name in names)


def sections(text: str) -> dict[str, dict[str, str]]:
    """Return each ``[mypy-...]`` section of a mypy.ini text: its patterns -> its options."""
    parser = configparser.ConfigParser()
    parser.read_string(text)
    return {name[len('mypy-'):]: dict(parser[name]) for name in parser.sections()
            if name.startswith('mypy-')}


def listed_with_reasons(text: str) -> set[str]:
    """Return the names of the comment lines ``# - name[, name]: reason`` of a mypy.ini text."""
    return {name.strip() for line in re.findall(r'(?m)^# - ([\w., ]+):\s*\S', text)
            for name in line.split(',')}


def strict_packages(config: dict[str, dict[str, str]]) -> set[str]:
    """Return the packages of the sections that disallow untyped definitions by wildcard."""
    return {pattern[:-2] for patterns, options in config.items()
            if options.get('disallow_untyped_defs') == 'True' and options.get(
                'warn_return_any') == 'True'
            for pattern in patterns.split(',') if pattern.endswith('.*')}


def relaxed_modules(config: dict[str, dict[str, str]]) -> set[str]:
    """Return the modules named one by one in a section that turns strict checks back off."""
    return {pattern for patterns, options in config.items()
            if options.get('warn_return_any') == 'False'
            for pattern in patterns.split(',')}


def modules(package: str) -> dict[str, Path]:
    """Return every module of a package and its subpackages by dotted name, ``__init__`` aside."""
    root = SRC / package / package
    return {'.'.join((package, *path.relative_to(root).with_suffix('').parts)): path
            for path in sorted(root.rglob('*.py')) if path.name != '__init__.py'}


def packages() -> list[str]:
    """Return the workspace's Python packages."""
    return sorted(p.parent.name for p in SRC.glob('*/setup.py')
                  if (p.parent / p.parent.name).is_dir())


TEXT = CONFIG.read_text(encoding='utf-8')
CONFIGURED = sections(TEXT)


def test_every_package_is_strict_or_listed_with_its_reason():
    strict, reasons = strict_packages(CONFIGURED), listed_with_reasons(TEXT)
    neither = [p for p in packages() if p not in strict and p not in reasons]
    assert strict and not neither, f'mypy.ini: make {neither} strict, or say why not'


@pytest.mark.parametrize('package', sorted(strict_packages(CONFIGURED)))
def test_a_strict_packages_pure_modules_are_strict_but_the_listed_exceptions(package):
    relaxed, reasons = relaxed_modules(CONFIGURED), listed_with_reasons(TEXT)
    found = modules(package)
    unreasoned = [m for m in sorted(relaxed & set(found))
                  if not imports_ros(found[m]) and m not in reasons]
    stale = [m for m in sorted(relaxed) if m.split('.')[0] == package and m not in found]
    assert not unreasoned and not stale, (
        f'mypy.ini relaxes pure modules without a reason {unreasoned}, or names modules that '
        f'do not exist {stale}')


def test_a_relaxed_pure_module_and_an_unlisted_package_are_found(tmp_path):
    text = ('# - wirefish_x.excused: its reason\n[mypy-wirefish_x.*,wirefish_y.*]\n'
            'disallow_untyped_defs = True\nwarn_return_any = True\n\n'
            '[mypy-wirefish_x.node,wirefish_x.excused]\nwarn_return_any = False\n')
    config = sections(text)
    assert strict_packages(config) == {'wirefish_x', 'wirefish_y'}
    assert relaxed_modules(config) == {'wirefish_x.node', 'wirefish_x.excused'}
    assert listed_with_reasons(text) == {'wirefish_x.excused'}
    pure, node = tmp_path / 'pure.py', tmp_path / 'node.py'
    pure.write_text('import numpy as np\n')
    node.write_text('from sensor_msgs.msg import Imu\nimport os\n')
    assert (imports_ros(pure), imports_ros(node)) == (False, True)
