"""
The wirefish node graph as data: which executables, with which names and arguments.

One description serves both roads: the `wirefish up` launcher (pip-only machines) and the
`wirefish.launch.py` launch file (full ROS 2 installs) build their processes from it, so the two
start exactly the same nodes with exactly the same parameters.
"""

from dataclasses import dataclass, field
from pathlib import Path
import re

from ament_index_python.packages import get_package_prefix, get_package_share_directory

DEFAULT_NAMESPACE = '/wirefish'
PARAMS_FILE_NAME = 'wirefish.yaml'
_NAMESPACE_PATTERN = re.compile(r'^(/[A-Za-z][A-Za-z0-9_]*)+$|^/$')


@dataclass(frozen=True)
class NodeSpec:
    """One process of the graph: `ros2 run <package> <executable> <arguments>`."""

    package: str
    executable: str
    name: str
    arguments: tuple[str, ...] = field(default=())

    def executable_path(self) -> Path:
        """Return the installed executable, where `ros2 run` finds it (lib/<package>/)."""
        return Path(get_package_prefix(self.package), 'lib', self.package, self.executable)


def validate_namespace(namespace: str) -> str:
    """Return ``namespace`` normalised to an absolute ROS namespace, or raise ValueError."""
    if not namespace.startswith('/'):
        namespace = '/' + namespace
    namespace = namespace.rstrip('/') or '/'
    if not _NAMESPACE_PATTERN.match(namespace):
        raise ValueError(f'invalid ROS namespace {namespace!r}: use letters, digits and _, '
                         'each token starting with a letter (e.g. /wirefish or /tank/fish_1)')
    return namespace


def default_params_file() -> Path:
    """Return the installed default parameter file of the graph."""
    return Path(get_package_share_directory('wirefish_bringup'), 'config', PARAMS_FILE_NAME)


def sim_tty_link(namespace: str) -> Path:
    """Return the symlink path under which the virtual fish publishes its pseudo-terminal."""
    token = validate_namespace(namespace).strip('/').replace('/', '_') or 'root'
    return Path('/tmp', f'wirefish-{token}-tty')


def fish_graph(namespace: str = DEFAULT_NAMESPACE, *, sim: bool = True,
               port: str | None = None, params_file: Path | None = None,
               single_process: bool = False) -> list[NodeSpec]:
    """
    Return the processes of one fish's graph, in start order (the virtual fish first).

    ``namespace`` holds every node and (relative) topic; ``sim`` starts the virtual fish and
    points the bridge at its pseudo-terminal, otherwise ``port`` names the real fish's serial
    device; ``params_file`` is the parameter YAML (the installed default when None);
    ``single_process`` runs the four ROS nodes in one process (`wirefish compose`).

    """
    namespace = validate_namespace(namespace)
    if not sim and not port:
        raise ValueError('a real fish needs its serial port (e.g. --port /dev/ttyUSB0)')
    if sim and port:  # e.g. `ros2 launch ... port:=/dev/ttyUSB0` without sim:=false
        raise ValueError(f'a serial port ({port}) was given for the virtual fish: '
                         'choose sim or a port (sim:=false port:=...)')
    params = str(params_file or default_params_file())
    tty = str(sim_tty_link(namespace)) if sim else port

    def ros_args(*extra: str) -> tuple[str, ...]:
        return ('--ros-args', '-r', f'__ns:={namespace}', '--params-file', params, *extra)

    specs: list[NodeSpec] = []
    if sim:
        specs.append(NodeSpec('wirefish_sim', 'fish_sim', 'fish_sim',
                              ('--link', tty, '--ros', *ros_args())))
    if single_process:
        specs.append(NodeSpec('wirefish_bringup', 'wirefish', 'fish_nodes', (
            'compose', '--namespace', namespace, '--port', tty, '--params-file', params)))
        return specs
    specs += [
        NodeSpec('wirefish_bridge', 'bridge_node', 'bridge_node',
                 ros_args('-p', f'port:={tty}')),
        NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node', ros_args()),
        NodeSpec('wirefish_kinematics', 'kinematics_node', 'kinematics_node', ros_args()),
        NodeSpec('wirefish_cpg', 'tuner_node', 'tuner_node', ros_args()),
    ]
    return specs
