# SPDX-License-Identifier: Apache-2.0
"""
Start one fish's graph on a full ROS 2 Jazzy install.

    ros2 launch wirefish_bringup wirefish.launch.py sim:=true namespace:=/wirefish speed:=max
    ros2 launch wirefish_bringup wirefish.launch.py sim:=false port:=/dev/ttyUSB0
    ros2 launch wirefish_bringup wirefish.launch.py role:=fish   # on the fish's computer
    ros2 launch wirefish_bringup wirefish.launch.py role:=shore  # on the shore's

The nodes, names, parameters, start order and restart policies come from the registry in
`wirefish_bringup.graph`, the one `wirefish up` (the launcher for machines without ros2 launch)
uses. launch has no back-off: a node is respawned after its policy's first delay, at most
``max_restarts`` times over the run; a required node that exits once more shuts the launch down.

Each process is named after its node in launch's output (``[cpg_node-3]``: ``exec_name``; launch
would name it after the first word of its command, the held start's ``env``). ``ros2 launch
--launch-prefix 'nice -n 7'`` (gdb, valgrind, xterm ...) and ``--launch-prefix-filter`` work as
for any package: the user's prefix follows the held start's (``_UserPrefix``), whereas a
prefix set in a launch file otherwise replaces the user's. Loading the file makes the launch
process signal its nodes without polling them (``wirefish_bringup.launch_signals``): a node
that stopped on a Ctrl-C is reported with its own exit code, not 255, however loaded the machine.
"""

import os
from pathlib import Path
import re

from launch import LaunchDescription, Substitution
from launch.actions import (DeclareLaunchArgument, OpaqueFunction, SetEnvironmentVariable,
                            Shutdown)
from launch.substitutions import EnvironmentVariable, LaunchConfiguration
from launch_ros.actions import Node
from wirefish_bringup.dds_profile import (profile_path, PROFILES_VARIABLE, TRANSPORTS,
                                          TRANSPORTS_VARIABLE)
from wirefish_bringup.graph import (DEFAULT_NAMESPACE, default_params_file, fish_graph,
                                    on_simulated_time, Role)
from wirefish_bringup.launch_signals import signal_children_without_reaping
from wirefish_common.input_checks import parse_speed
from wirefish_common.startup_signals import held_start_prefix


def _shutdown_after_last_retry(spec):
    """Return an on_exit callback: Shutdown once the node's respawn retries are spent."""
    exits = 0

    def on_exit(_event, _context):
        nonlocal exits
        exits += 1
        if exits > spec.restart.max_restarts:
            return [Shutdown(reason=f'{spec.name} (required) exited {exits} times')]
        return None
    return on_exit


class _UserPrefix(Substitution):
    """The ``launch-prefix`` launch configuration, if ``launch-prefix-filter`` lets it apply."""

    def __init__(self, executable):
        """Keep the executable the filter is matched against."""
        super().__init__()
        self._executable = executable

    def describe(self):
        """Say what this substitutes (launch's introspection)."""
        return f'launch-prefix (filtered) of {self._executable}'

    def perform(self, context):
        """Return the user's prefix, or '' where the filter does not match."""
        configurations = context.launch_configurations
        wanted = configurations.get('launch-prefix-filter', '')
        if re.match(wanted, os.path.basename(self._executable)) is None:
            return ''
        return configurations.get('launch-prefix', '')


def _prefix(held, spec):
    """Return the held start (for executables that release it) then the user's prefix."""
    user = _UserPrefix(spec.executable)
    if held is None or not spec.releases_stop_signals:
        return [user]
    return [f'{held} ', user]


def _simulated_time_overrides():
    """Return a parameter file of what simulated time changes in the parameter file's sections."""
    # launch_ros writes a dict of values under /**, which a /**/bridge_node section of the
    # parameter file overrides: a file of its own, after that one, carries the bridge's value.
    # One file per content, named by it and written once: every node of every launch reads the
    # same file, and no launch leaves one more behind.
    import hashlib
    import tempfile

    import yaml
    from wirefish_bringup.graph import SIM_TIME_COMMAND_RATE_HZ

    text = yaml.safe_dump({'/**/bridge_node': {'ros__parameters': {
        'max_command_rate_hz': float(SIM_TIME_COMMAND_RATE_HZ)}}})
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    path = Path(tempfile.gettempdir(), f'wirefish_sim_time_{digest}.yaml')
    if not path.is_file() or path.read_text() != text:
        partial = path.with_name(f'{path.name}.{os.getpid()}')
        partial.write_text(text)
        os.replace(partial, path)  # whole or not at all for a launch reading it meanwhile
    return str(path)


def _parameter_files(params_file: str) -> list[str]:
    """
    Return a node's parameter files: the installed defaults, then the user's over them.

    A user's params_file names only what it changes (the fish's geometry, one gain), as under
    `wirefish up --params-file`: ROS applies the files in order, value by value, so what it does
    not name keeps the installed default.
    """
    defaults = str(default_params_file())
    return [defaults] if params_file == defaults else [defaults, params_file]


def _nodes(context):
    sim = LaunchConfiguration('sim').perform(context).lower() in ('true', '1', 'yes')
    port = LaunchConfiguration('port').perform(context) or None
    namespace = LaunchConfiguration('namespace').perform(context)
    params_file = LaunchConfiguration('params_file').perform(context) or None
    role = LaunchConfiguration('role').perform(context)
    frame_prefix = LaunchConfiguration('frame_prefix').perform(context)
    speed = LaunchConfiguration('speed').perform(context)
    actions = []
    # A Ctrl-C while a node's interpreter starts waits for the node's own handler (every
    # registry executable unblocks the stop signals once it is in place), not a trace.
    prefix = held_start_prefix()
    if not sim and not port:  # fish_graph's own words name wirefish up's --port
        raise ValueError('sim:=false drives a real fish: give its serial port, e.g. '
                         'port:=/dev/ttyUSB0')
    specs = fish_graph(namespace, sim=sim, port=port, params_file=params_file, role=role,
                       frame_prefix=frame_prefix)
    # The virtual fish on one host owns the graph's clock, as under `wirefish up --sim`; a
    # real fish and two hosts run on the wall clock.
    simulated = sim and role == Role.ALL
    if simulated:
        parse_speed(speed)  # a clear error for a speed that is none
        specs = on_simulated_time(specs, speed)
    for spec in specs:
        # The recorder (the only entry that parses its own options) runs with --duration
        # under `wirefish up` only: fish_graph adds it only when given a bag.
        actions.append(Node(
            package=spec.package, executable=spec.executable, name=spec.name,
            exec_name=spec.name,
            namespace=spec.namespace, arguments=list(spec.arguments),
            parameters=[*_parameter_files(spec.params_file),
                        *([_simulated_time_overrides()] if simulated else []),
                        spec.typed_parameters()],
            remappings=list(spec.remaps.items()),
            respawn=spec.restart.respawn, respawn_delay=spec.restart.delay_s,
            respawn_max_retries=spec.restart.max_restarts,
            on_exit=_shutdown_after_last_retry(spec) if spec.restart.required else None,
            prefix=_prefix(prefix, spec),
            output='screen', emulate_tty=True))
    return actions


def generate_launch_description():
    # launch's SIGINT/SIGTERM to a node that a Ctrl-C has already ended must leave its exit
    # code to asyncio's watcher: a loaded machine would otherwise see it "died" with 255.
    signal_children_without_reaping()
    return LaunchDescription([
        # The reply writers' wait for a new client (config/fastdds.xml); a profile file the
        # user set is kept.
        SetEnvironmentVariable(PROFILES_VARIABLE, EnvironmentVariable(
            PROFILES_VARIABLE, default_value=str(profile_path()))),
        # No shared memory: a killed subscriber would stall its publishers (dds_profile).
        SetEnvironmentVariable(TRANSPORTS_VARIABLE, EnvironmentVariable(
            TRANSPORTS_VARIABLE, default_value=TRANSPORTS)),
        DeclareLaunchArgument('sim', default_value='true',
                              description='drive the virtual fish (fish_sim) on a pty'),
        DeclareLaunchArgument('port', default_value='',
                              description='serial device of a real fish (sim:=false)'),
        DeclareLaunchArgument('namespace', default_value=DEFAULT_NAMESPACE,
                              description='ROS namespace of every node and topic of the fish'),
        DeclareLaunchArgument('params_file', default_value='',
                              description='parameter YAML over the defaults (config/'
                              'wirefish.yaml): it names only what it changes'),
        DeclareLaunchArgument('role', default_value=Role.ALL.value,
                              choices=[role.value for role in Role],
                              description='fish: the nodes that keep the fish swimming (and '
                              'the link relay to shore); shore: tuner (and recorder); all: both'),
        DeclareLaunchArgument('frame_prefix', default_value='',
                              description='prefix of frame ids (fish_1 -> fish_1/base_link)'),
        DeclareLaunchArgument('speed', default_value='1',
                              description='sim:=true on one host: the virtual fish owns the '
                              'clock, every node on simulated time at this factor on real time '
                              '(1; max: as fast as the graph answers)'),
        OpaqueFunction(function=_nodes),
    ])
