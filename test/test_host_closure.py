# SPDX-License-Identifier: Apache-2.0
"""
What each host installs: the dependency closure of its role's packages, from the manifests.

`wirefish_fish` and `wirefish_shore` name what runs on each side of the radio link (the
registry's roles, plus the launcher, the command and the registry itself); `rosdep install` or
`colcon build --packages-up-to` of one of them installs its closure. The fish's closure holds no
tuner, plotting, bag library or analysis; the shore's no serial stack. A manifest that grows
one of them fails here. Conditions are evaluated as rosdep and colcon do, with the host's
``WIREFISH_HOST`` (fish or shore).
"""

from collections.abc import Mapping
from pathlib import Path

from catkin_pkg.package import parse_package
import pytest
from wirefish_bringup.graph import NODES, Role

pytestmark = pytest.mark.linter
WORKSPACE = Path(__file__).resolve().parents[1]
RUN_DEPENDENCIES = ('exec_depends', 'build_export_depends', 'buildtool_export_depends')
# What `wirefish up --role ...` needs besides the registry's nodes: the registry, the launcher
# and the command.
LAUNCHING = {'wirefish_bringup', 'wirefish_launcher', 'wirefish_cli'}
KEPT_OFF = {
    'fish': {'wirefish_tuner', 'wirefish_analysis', 'wirefish_bag', 'wirefish_operator',
             'wirefish_view', 'python3-matplotlib', 'python3-rosbags-pip',
             'python3-pyswarms-pip'},
    'shore': {'wirefish_bridge', 'wirefish_sim', 'python3-serial', 'python3-cobs-pip'},
}
ROLE_PACKAGE = {'fish': 'wirefish_fish', 'shore': 'wirefish_shore'}
# The operator's verbs (drive, retune, missions, the gait library) run where the operator sits.
TOOLS = {'fish': set(), 'shore': {'wirefish_operator'}}


def workspace_manifests() -> dict[str, Path]:
    """Return {package name: package.xml} of every package in the workspace."""
    return {parse_package(path).name: path
            for path in sorted((WORKSPACE / 'src').glob('*/package.xml'))}


def run_dependencies(manifest: Path, host: str) -> set[str]:
    """Return what ``manifest``'s package needs at run time on ``host`` (conditions applied)."""
    package = parse_package(manifest)
    package.evaluate_conditions({'WIREFISH_HOST': host})
    return {dependency.name for kind in RUN_DEPENDENCIES for dependency in getattr(package, kind)
            if dependency.evaluated_condition is not False}


def closure(roots: set[str], manifests: Mapping[str, Path], host: str) -> set[str]:
    """Return ``roots`` and everything they need, transitively, on ``host``."""
    seen: set[str] = set()
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        if name in manifests:  # a workspace package: follow it (others are leaves: keys)
            todo.extend(run_dependencies(manifests[name], host))
    return seen


def role_packages(role: str) -> set[str]:
    """Return the packages of the registry's processes on one side of the link, and launching."""
    return {entry.package for entry in NODES if entry.role == Role(role)} | LAUNCHING | TOOLS[role]


@pytest.mark.parametrize('role', ['fish', 'shore'])
def test_the_role_package_installs_what_the_registry_runs_on_that_side(role):
    manifests = workspace_manifests()
    assert run_dependencies(manifests[ROLE_PACKAGE[role]], role) == role_packages(role)


@pytest.mark.parametrize('role', ['fish', 'shore'])
def test_a_hosts_closure_keeps_the_other_sides_packages_off(role):
    installed = closure({ROLE_PACKAGE[role]}, workspace_manifests(), role)
    assert installed & KEPT_OFF[role] == set()


def test_a_shore_dependency_added_to_a_fish_package_is_caught(tmp_path):
    manifests = workspace_manifests()
    grown = tmp_path / 'package.xml'
    grown.write_text(manifests['wirefish_cpg'].read_text().replace(
        '<exec_depend>rclpy</exec_depend>',
        '<exec_depend>rclpy</exec_depend>\n  <exec_depend>python3-matplotlib</exec_depend>'))
    installed = closure({'wirefish_fish'}, {**manifests, 'wirefish_cpg': grown}, 'fish')
    assert 'python3-matplotlib' in installed


def test_a_condition_keeps_the_bag_library_off_the_fish_only():
    manifests = workspace_manifests()
    assert 'wirefish_bag' not in run_dependencies(manifests['wirefish_launcher'], 'fish')
    assert 'wirefish_bag' in run_dependencies(manifests['wirefish_launcher'], 'shore')
