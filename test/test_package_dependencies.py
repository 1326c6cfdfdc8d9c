# SPDX-License-Identifier: Apache-2.0
"""
Every package.xml declares what its package uses, and nothing it does not.

``rosdep install`` on a full ROS install reads only the manifests, so an undeclared import is a
node that dies of ModuleNotFoundError on a machine set up by the book, and a stale declaration
installs what nothing uses. The imports are read with ``ast`` (module code, launch files and
tests, imports inside functions included) and mapped to ROS package names or rosdep keys:

- standard library: ignored (``sys.stdlib_module_names``);
- third-party modules: the explicit ``THIRD_PARTY`` table (a module missing from it fails, so a
  new dependency is decided once, with its key);
- anything else must be a ROS package of that name (the ament index, or ``ROS_ONLY``).

Module code and launch files need an ``exec_depend`` (or ``depend``); tests need a
``test_depend`` or an ``exec_depend``. A declared dependency must be imported, or named in a
string (a package whose executables or files the code uses, e.g. the launcher's node table).
An interface package (CMake, .msg/.srv/.action) must depend on each package its fields name.
"""

import ast
from collections.abc import Iterable
from pathlib import Path
import re
import sys
import xml.etree.ElementTree as ElementTree

from ament_index_python.packages import get_packages_with_prefixes
import pytest

pytestmark = pytest.mark.linter
WORKSPACE = Path(__file__).resolve().parents[1]
PACKAGES = sorted(p.parent for p in (WORKSPACE / 'src').glob('*/package.xml'))

# Import name -> rosdep key. Real keys where rosdep has one; '-pip' keys (rosdep's convention for
# packages installed from PyPI) where it has none.
THIRD_PARTY = {
    'cobs': 'python3-cobs-pip',
    'foxglove': 'python3-foxglove-sdk-pip',
    'hypothesis': 'python3-hypothesis',
    'matplotlib': 'python3-matplotlib',
    'mcap': 'python3-mcap-pip',
    'numpy': 'python3-numpy',
    'psutil': 'python3-psutil',
    'pyswarms': 'python3-pyswarms-pip',
    'pytest': 'python3-pytest',
    'rosbags': 'python3-rosbags-pip',
    'scipy': 'python3-scipy',
    'selenium': 'python3-selenium',
    'serial': 'python3-serial',
    'websockets': 'python3-websockets',
    'yaml': 'python3-yaml',
}
# ROS Python packages that the PyPI-wheels road does not install (used by the launch file only,
# which runs on a full install), so the ament index here does not list them.
ROS_ONLY = {'launch', 'launch_ros'}
# Declared for build or test tooling that no code imports.
TOOLING = {'ament_cmake', 'ament_copyright', 'ament_lint_auto', 'ament_lint_common',
           'rosidl_default_generators', 'rosidl_default_runtime'}
RUNTIME_TAGS = ('exec_depend', 'depend')
TEST_TAGS = ('test_depend', 'exec_depend', 'depend')
# A field type naming another interface package: 'std_msgs/Header', 'geometry_msgs/Point[]'.
INTERFACE_REFERENCE = re.compile(r'^\s*([a-z][a-z0-9_]*)/[A-Za-z]')


def declared(package: Path) -> dict[str, set[str]]:
    """Return {tag: dependency names} of ``package``'s manifest."""
    root = ElementTree.parse(package / 'package.xml').getroot()
    tags: dict[str, set[str]] = {}
    for element in root:
        if element.tag.endswith('depend') and element.text:
            tags.setdefault(element.tag, set()).add(element.text.strip())
    return tags


def declared_under(tags: dict[str, set[str]], kinds: Iterable[str]) -> set[str]:
    return set().union(*(tags.get(kind, set()) for kind in kinds))


def imported_modules(paths: Iterable[Path]) -> dict[str, set[Path]]:
    """Return {top-level module name: files importing it} of absolute imports in ``paths``."""
    modules: dict[str, set[Path]] = {}
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                modules.setdefault(name.split('.')[0], set()).add(path)
    return modules


def named_in_strings(paths: Iterable[Path], candidates: set[str]) -> set[str]:
    """Return the ``candidates`` that some string constant in ``paths`` names."""
    named = set()
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                head = re.split(r'[.:/]', node.value, maxsplit=1)[0]
                if head in candidates:
                    named.add(head)
    return named


def ros_packages() -> set[str]:
    return set(get_packages_with_prefixes()) | ROS_ONLY


def dependency_key(module: str, known_ros: set[str]) -> str | None:
    """Return the ROS package / rosdep key behind ``module``; None for the standard library."""
    if module in sys.stdlib_module_names or module == '__future__':
        return None
    if module in THIRD_PARTY:
        return THIRD_PARTY[module]
    if module in known_ros:
        return module
    raise LookupError(f'{module}: neither standard library, nor in THIRD_PARTY, nor a ROS '
                      'package: add it to THIRD_PARTY with its rosdep key')


def python_files(package: Path) -> tuple[list[Path], list[Path]]:
    """Return (module and launch files, test files) of an ament_python package."""
    code = sorted((package / package.name).rglob('*.py')) + sorted(package.glob('launch/*.py'))
    tests = sorted(package.glob('test/**/*.py'))
    return code, tests


def undeclared_imports(package: Path) -> list[str]:
    """Return one line per import of ``package`` that its manifest does not declare."""
    tags = declared(package)
    code, tests = python_files(package)
    known_ros = ros_packages()
    local_test_modules = {path.stem for path in tests}
    problems = []
    for files, kinds, what in ((code, RUNTIME_TAGS, 'exec_depend'),
                               (tests, TEST_TAGS, 'test_depend')):
        allowed = declared_under(tags, kinds)
        for module, users in sorted(imported_modules(files).items()):
            if module == package.name or module in local_test_modules:
                continue
            try:
                key = dependency_key(module, known_ros)
            except LookupError as error:
                problems.append(f'{package.name}: {error} (in {_shown(users)})')
                continue
            if key is not None and key not in allowed:
                problems.append(f'{package.name}: imports {module} in {_shown(users)} but does '
                                f'not declare <{what}>{key}</{what}>')
    return problems


def used_dependencies(files: list[Path], known_ros: set[str]) -> set[str]:
    """Return the dependency keys that ``files`` import or name in a string."""
    used = set()
    for module in imported_modules(files):
        try:
            used.add(dependency_key(module, known_ros))
        except LookupError:
            pass  # reported by test_every_import_is_declared
    return used | named_in_strings(files, known_ros)


def unused_declarations(package: Path) -> list[str]:
    """Return one line per declared dependency that ``package`` never imports nor names."""
    tags = declared(package)
    code, tests = python_files(package)
    known_ros = ros_packages()
    used_by_code = used_dependencies(code, known_ros)
    used_by_tests = used_dependencies(tests, known_ros)
    runtime = declared_under(tags, RUNTIME_TAGS) - TOOLING
    test_only = tags.get('test_depend', set()) - TOOLING
    problems = []
    for name in sorted(runtime - used_by_code):
        problems.append(f'{package.name}: declares <exec_depend>{name}</exec_depend> but '
                        + ('only its tests use it: make it a test_depend'
                           if name in used_by_tests else 'never imports it'))
    problems += [f'{package.name}: declares <test_depend>{name}</test_depend> but never '
                 'imports it' for name in sorted(test_only - used_by_tests - used_by_code)]
    return problems


def interface_problems(package: Path) -> list[str]:
    """Return the interface packages named by ``package``'s fields but not declared, and back."""
    tags = declared(package)
    files = sorted(package.glob('msg/*.msg')) + sorted(package.glob('srv/*.srv')) + \
        sorted(package.glob('action/*.action'))
    named = {match[1] for path in files for line in path.read_text().splitlines()
             if (match := INTERFACE_REFERENCE.match(line.split('#')[0]))} - {package.name}
    if any(path.suffix == '.action' for path in files):
        named.add('action_msgs')  # every action's goal and status types come from it
    depends = tags.get('depend', set()) - TOOLING
    return [f'{package.name}: its interfaces use {name} but it does not declare '
            f'<depend>{name}</depend>' for name in sorted(named - depends)] + \
        [f'{package.name}: declares <depend>{name}</depend> but no interface uses it'
         for name in sorted(depends - named)]


def _shown(paths: set[Path]) -> str:
    return ', '.join(str(path.relative_to(WORKSPACE)) for path in sorted(paths))


def is_python_package(package: Path) -> bool:
    return (package / 'setup.py').exists()


PYTHON_PACKAGES = [p for p in PACKAGES if is_python_package(p)]
INTERFACE_PACKAGES = [p for p in PACKAGES if not is_python_package(p)]


@pytest.mark.parametrize('package', PYTHON_PACKAGES, ids=lambda p: p.name)
def test_every_import_is_declared(package):
    problems = undeclared_imports(package)
    assert not problems, '\n'.join(problems)


@pytest.mark.parametrize('package', PYTHON_PACKAGES, ids=lambda p: p.name)
def test_every_declared_dependency_is_used(package):
    problems = unused_declarations(package)
    assert not problems, '\n'.join(problems)


@pytest.mark.parametrize('package', INTERFACE_PACKAGES, ids=lambda p: p.name)
def test_interface_dependencies_match_the_fields(package):
    problems = interface_problems(package)
    assert not problems, '\n'.join(problems)
