# SPDX-License-Identifier: Apache-2.0
"""
launch/wirefish.launch.py, checked without the launch packages (pure: stand-ins, no ROS).

`launch` and `launch_ros` are not on PyPI, so stand-ins installed into ``sys.modules`` record
what the launch file builds: every ``Node(...)`` and its parameters. Each value is checked
against the type the node declares for it, since launch_ros writes a ``parameters`` dict into
YAML as it is and a node refuses a string where it declares a bool (rclpy does not convert).
Loading the file also changes how the launch process's asyncio signals its children: that is
checked on real child processes, through asyncio as launch drives them.
"""

import asyncio
from asyncio.base_subprocess import BaseSubprocessTransport
import asyncio.unix_events
from dataclasses import dataclass, field
import importlib
import importlib.util
import os
from pathlib import Path
import signal
import sys
import threading
import types

from declared_parameters import declared_specs
import pytest
from wirefish_bringup.graph import default_params_file, entry
from wirefish_common.frames import FRAME_PREFIX
from wirefish_common.parameter_table import ParameterSpec
from wirefish_common.startup_signals import held_start_prefix
import yaml

LAUNCH_FILE = (Path(__file__).resolve().parents[2] / 'src' / 'wirefish_bringup' / 'launch'
               / 'wirefish.launch.py')


@dataclass
class Recorded:
    """What the stand-ins saw: every Node(...)'s keyword arguments, every declared argument."""

    nodes: list[dict] = field(default_factory=list)
    arguments: dict[str, str] = field(default_factory=dict)
    environment: dict[str, object] = field(default_factory=dict)


class _Context:
    def __init__(self, values: dict[str, str]) -> None:
        self.launch_configurations = values


def _stand_ins(recorded: Recorded) -> dict[str, types.ModuleType]:
    launch = types.ModuleType('launch')
    actions = types.ModuleType('launch.actions')
    substitutions = types.ModuleType('launch.substitutions')
    launch_ros = types.ModuleType('launch_ros')
    ros_actions = types.ModuleType('launch_ros.actions')

    class LaunchDescription:
        def __init__(self, entities):
            self.entities = list(entities)

    class Substitution:
        def __init__(self):
            pass

    class DeclareLaunchArgument:
        def __init__(self, name, default_value='', description='', choices=None):
            assert description, f'launch argument {name} has no description'
            recorded.arguments[name] = default_value
            self.name, self.choices = name, choices

    class OpaqueFunction:
        def __init__(self, function):
            self.function = function

    class Shutdown:
        def __init__(self, reason=''):
            self.reason = reason

    class LaunchConfiguration:
        def __init__(self, name):
            self.name = name

        def perform(self, context):
            return context.launch_configurations[self.name]

    class SetEnvironmentVariable:
        def __init__(self, name, value):
            recorded.environment[name] = value

    class EnvironmentVariable:
        def __init__(self, name, default_value=''):
            self.name, self.default_value = name, default_value

    def node(**kwargs):
        recorded.nodes.append(kwargs)
        return kwargs

    launch.LaunchDescription = LaunchDescription
    launch.Substitution = Substitution
    actions.DeclareLaunchArgument = DeclareLaunchArgument
    actions.OpaqueFunction = OpaqueFunction
    actions.Shutdown = Shutdown
    actions.SetEnvironmentVariable = SetEnvironmentVariable
    substitutions.EnvironmentVariable = EnvironmentVariable
    substitutions.LaunchConfiguration = LaunchConfiguration
    ros_actions.Node = node
    launch.actions, launch.substitutions, launch_ros.actions = actions, substitutions, ros_actions
    return {'launch': launch, 'launch.actions': actions, 'launch.substitutions': substitutions,
            'launch_ros': launch_ros, 'launch_ros.actions': ros_actions}


def launched_nodes(monkeypatch, recorded: Recorded | None = None, **overrides: str
                   ) -> list[dict]:
    """Return the Node(...) keyword arguments of `ros2 launch ... key:=value ...`."""
    recorded = Recorded() if recorded is None else recorded
    # Loading the file changes the signalling of asyncio's subprocess transports: undone after.
    for name in ('send_signal', 'terminate', 'kill'):
        monkeypatch.setattr(BaseSubprocessTransport, name, getattr(BaseSubprocessTransport, name))
    for name, module in _stand_ins(recorded).items():
        monkeypatch.setitem(sys.modules, name, module)
    spec = importlib.util.spec_from_file_location('wirefish_launch_under_test', LAUNCH_FILE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    unknown = set(overrides) - set(recorded.arguments)
    assert not unknown, f'the launch file declares no {sorted(unknown)}'
    context = _Context({**recorded.arguments, **overrides})
    for entity in description.entities:
        if hasattr(entity, 'function'):
            entity.function(context)
    return recorded.nodes


def declared(node_name: str) -> dict[str, ParameterSpec]:
    """Return every parameter node ``node_name`` declares, by name."""
    specs = {s.name: s for s in declared_specs(entry(node_name))}
    if entry(node_name).frames:
        specs[FRAME_PREFIX] = ParameterSpec(FRAME_PREFIX, '', 'frame id prefix')
    # rclpy's own, on every node: simulated time (the virtual fish's clock).
    specs['use_sim_time'] = ParameterSpec('use_sim_time', False, 'follow /clock')
    return specs


def type_problems(node: dict) -> list[str]:
    """Return each parameter of one Node(...) whose value is not of the declared type."""
    problems = []
    for values in node['parameters']:
        if not isinstance(values, dict):
            continue  # the parameter file: its values are typed by YAML itself
        specs = declared(node['name'])
        for key, value in values.items():
            if key not in specs:
                problems.append(f'{node["name"]}: {key} is not declared')
            elif type(value) is not type(specs[key].default):
                problems.append(f'{node["name"]}: {key} = {value!r} is a {type(value).__name__},'
                                f' declared {type(specs[key].default).__name__}')
    return problems


LAUNCHES = {
    'sim': {'sim': 'true', 'namespace': '/rt'},
    'real fish': {'sim': 'false', 'port': '/dev/ttyUSB0'},
    'fish role, prefixed': {'role': 'fish', 'frame_prefix': 'fish_1'},
    'shore role': {'role': 'shore'},
}


def test_the_stand_ins_record_the_graph(monkeypatch):
    names = [n['name'] for n in launched_nodes(monkeypatch, **LAUNCHES['sim'])]
    assert {'fish_sim', 'bridge_node', 'cpg_node', 'planner_node', 'tuner_node'} <= set(names)


@pytest.mark.parametrize('overrides', LAUNCHES.values(), ids=LAUNCHES.keys())
def test_every_parameter_the_launch_file_passes_has_its_declared_type(monkeypatch, overrides):
    nodes = launched_nodes(monkeypatch, **overrides)
    problems = [p for node in nodes for p in type_problems(node)]
    assert nodes and not problems, problems


def test_a_string_where_a_bool_is_declared_is_found():
    node = {'name': 'planner_node', 'parameters': ['wirefish.yaml', {'rest_at_start': 'false'}]}
    assert type_problems(node) == [
        "planner_node: rest_at_start = 'false' is a str, declared bool"]


def test_a_parameter_no_node_declares_is_found():
    node = {'name': 'cpg_node', 'parameters': [{'no_such_parameter': 1.0}]}
    assert type_problems(node) == ['cpg_node: no_such_parameter is not declared']


def test_the_launch_gives_its_nodes_the_fast_dds_profile_unless_one_is_set(monkeypatch):
    recorded = Recorded()
    launched_nodes(monkeypatch, recorded)
    value = recorded.environment['FASTRTPS_DEFAULT_PROFILES_FILE']
    assert value.name == 'FASTRTPS_DEFAULT_PROFILES_FILE'  # the user's own value wins
    assert Path(value.default_value).name == 'fastdds.xml'
    assert Path(value.default_value).is_file()


def test_the_launch_leaves_shared_memory_out_unless_the_user_set_the_transports(monkeypatch):
    recorded = Recorded()
    launched_nodes(monkeypatch, recorded)
    value = recorded.environment['FASTDDS_BUILTIN_TRANSPORTS']
    assert value.name == 'FASTDDS_BUILTIN_TRANSPORTS'  # the user's own value wins
    assert value.default_value == 'UDPv4'


@pytest.mark.parametrize('overrides', LAUNCHES.values(), ids=LAUNCHES.keys())
def test_every_node_starts_with_its_stop_signals_held(monkeypatch, overrides):
    # ros2 launch starts each through env, which blocks SIGINT/SIGTERM until the node's handler
    # unblocks them: a Ctrl-C during the interpreter's start is not a trace.
    nodes = launched_nodes(monkeypatch, **overrides)
    assert nodes and {performed_prefix(node) for node in nodes} == {held_start_prefix()}
    assert held_start_prefix() is not None


class _StarvedWatcher:
    """asyncio's ``os`` with the child watcher's thread kept off the CPU until ``release``."""

    def __init__(self) -> None:
        self.release = threading.Event()

    def __getattr__(self, name: str) -> object:
        return getattr(os, name)

    def waitpid(self, pid: int, options: int) -> tuple[int, int]:
        if threading.current_thread() is not threading.main_thread():
            self.release.wait(timeout=30.0)
        return os.waitpid(pid, options)


class _Exit(asyncio.SubprocessProtocol):
    def __init__(self) -> None:
        self.exited = asyncio.get_running_loop().create_future()

    def process_exited(self) -> None:
        self.exited.set_result(None)


def _zombie(pid: int) -> bool:
    """Whether ``pid`` has exited and is waiting to be collected by its parent."""
    stat = Path(f'/proc/{pid}/stat').read_text()
    return stat[stat.rindex(')') + 2] == 'Z'


async def _signalled_exit_code(command: list[str], stop, *, after_exit: bool) -> int:
    """Return the exit code asyncio reports for ``command`` stopped with ``stop(transport)``."""
    loop = asyncio.get_running_loop()
    transport, protocol = await loop.subprocess_exec(_Exit, *command, stdin=None, stdout=None,
                                                     stderr=None)
    try:
        if after_exit:  # a Ctrl-C ended it; launch's own signal comes before the watcher looks
            deadline = loop.time() + 10.0
            while not _zombie(transport.get_pid()):
                assert loop.time() < deadline, 'the child did not exit'
                await asyncio.sleep(0.01)
        stop(transport)
        asyncio.unix_events.os.release.set()
        await asyncio.wait_for(protocol.exited, timeout=30.0)
        return transport.get_returncode()
    finally:
        transport.close()


STOPS = {
    'SIGINT': lambda transport: transport.send_signal(signal.SIGINT),
    'SIGTERM': lambda transport: transport.send_signal(signal.SIGTERM),
    'SIGKILL': lambda transport: transport.kill(),
}


@pytest.mark.parametrize('stop', STOPS.values(), ids=STOPS.keys())
def test_launch_signalling_a_node_that_already_exited_reports_its_own_exit_code(
        monkeypatch, stop):
    # A Ctrl-C reaches the whole process group: a node ends on it while launch, on a loaded
    # machine, still sends its own SIGINT (noninteractive), SIGTERM or SIGKILL. That signal
    # must not collect the exit itself, or asyncio's watcher finds no child: exit code 255.
    launched_nodes(monkeypatch, **LAUNCHES['sim'])
    monkeypatch.setattr(asyncio.unix_events, 'os', _StarvedWatcher())
    code = asyncio.run(_signalled_exit_code(['sh', '-c', 'exit 3'], stop, after_exit=True))
    assert code == 3


def test_launch_still_stops_a_running_node(monkeypatch):
    launched_nodes(monkeypatch, **LAUNCHES['sim'])
    monkeypatch.setattr(asyncio.unix_events, 'os', _StarvedWatcher())
    code = asyncio.run(_signalled_exit_code(['sleep', '30'], STOPS['SIGINT'], after_exit=False))
    assert code == -signal.SIGINT


def performed_prefix(node: dict, **configurations: str) -> str:
    """Return a Node's prefix as launch performs it (``launch-prefix``... as configured)."""
    context = _Context(configurations)
    return ''.join(part if isinstance(part, str) else part.perform(context)
                   for part in node['prefix']).strip()


@pytest.mark.parametrize('overrides', LAUNCHES.values(), ids=LAUNCHES.keys())
def test_each_process_is_named_after_its_node(monkeypatch, overrides):
    # launch names a process after its command's first word unless exec_name says otherwise:
    # with the held start's env first, every process was env-1, env-2 ... in ros2 launch's
    # output, its 'process has died' and 'was required' lines.
    nodes = launched_nodes(monkeypatch, **overrides)
    assert nodes and [node['exec_name'] for node in nodes] == [node['name'] for node in nodes]
    assert len({node['name'] for node in nodes}) == len(nodes)


def test_the_users_launch_prefix_follows_the_held_start(monkeypatch):
    # ros2 launch --launch-prefix 'nice -n 7': a prefix set in a launch file replaces the
    # user's, so the file composes it: env blocks the stops, then execs the user's prefix,
    # which runs the node (gdb and valgrind then see the node, not env).
    nodes = launched_nodes(monkeypatch, **LAUNCHES['sim'])
    held = held_start_prefix()
    assert {performed_prefix(n, **{'launch-prefix': 'nice -n 7'}) for n in nodes} == {
        f'{held} nice -n 7'}
    cpg = next(n for n in nodes if n['name'] == 'cpg_node')
    other = next(n for n in nodes if n['name'] == 'planner_node')
    only_cpg = {'launch-prefix': 'xterm -e', 'launch-prefix-filter': 'cpg_'}
    assert performed_prefix(cpg, **only_cpg) == f'{held} xterm -e'
    assert performed_prefix(other, **only_cpg) == held


def test_a_real_fish_without_a_port_names_the_launch_argument(monkeypatch):
    with pytest.raises(ValueError, match=r'port:=/dev/ttyUSB0') as refused:
        launched_nodes(monkeypatch, sim='false')
    assert '--port' not in str(refused.value)


def test_the_virtual_fish_on_one_host_runs_the_graph_on_its_clock(monkeypatch):
    nodes = {n['name']: n for n in launched_nodes(monkeypatch, **LAUNCHES['sim'],
                                                  speed='max')}
    assert nodes['fish_sim']['arguments'][-2:] == ['--speed', 'max']
    for name, node in nodes.items():
        if name == 'fish_sim':
            continue
        assert node['parameters'][-1]['use_sim_time'] is True, name
        assert ('/clock', '/rt/clock') in node['remappings'], name
    override = yaml.safe_load(Path(nodes['bridge_node']['parameters'][1]).read_text())
    assert override['/**/bridge_node']['ros__parameters']['max_command_rate_hz'] == 1000.0


def test_every_launch_on_the_clock_shares_one_overrides_file(monkeypatch):
    files = {node['parameters'][1] for _ in range(2)
             for node in launched_nodes(monkeypatch, **LAUNCHES['sim'])}
    assert len(files) == 1 and Path(files.pop()).is_file()


def test_a_real_fish_and_two_hosts_run_on_the_wall_clock(monkeypatch):
    for launch in ('real fish', 'fish role, prefixed', 'shore role'):
        for node in launched_nodes(monkeypatch, **LAUNCHES[launch]):
            assert '--speed' not in node['arguments'] and not node['remappings'], launch
            assert all('use_sim_time' not in values for values in node['parameters']
                       if isinstance(values, dict)), launch


def test_a_params_file_goes_over_the_defaults_not_instead_of_them(monkeypatch, tmp_path):
    mine = tmp_path / 'my_fish.yaml'
    mine.write_text('/**/fish_sim:\n  ros__parameters:\n    l1: 0.09\n')
    for node in launched_nodes(monkeypatch, **LAUNCHES['sim'], params_file=str(mine)):
        assert node['parameters'][:2] == [str(default_params_file()), str(mine)], node['name']


def test_without_a_params_file_the_nodes_read_the_defaults_once(monkeypatch):
    for node in launched_nodes(monkeypatch, **LAUNCHES['sim']):
        files = [f for f in node['parameters'] if not isinstance(f, dict)]
        assert files.count(str(default_params_file())) == 1, node['name']
