"""
Start one fish's graph on a full ROS 2 Jazzy install.

    ros2 launch wirefish_bringup wirefish.launch.py sim:=true namespace:=/wirefish
    ros2 launch wirefish_bringup wirefish.launch.py sim:=false port:=/dev/ttyUSB0

The nodes, names and arguments come from `wirefish_bringup.graph`, the same description that
`wirefish up` (the launcher for machines without ros2 launch) uses.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from wirefish_bringup.graph import DEFAULT_NAMESPACE, fish_graph


def _nodes(context):
    sim = LaunchConfiguration('sim').perform(context).lower() in ('true', '1', 'yes')
    port = LaunchConfiguration('port').perform(context) or None
    namespace = LaunchConfiguration('namespace').perform(context)
    params_file = LaunchConfiguration('params_file').perform(context) or None
    actions = []
    for spec in fish_graph(namespace, sim=sim, port=port, params_file=params_file):
        # graph.py builds the whole command line (namespace, parameter file and remaps as
        # --ros-args), so launch_ros gets it verbatim and adds nothing of its own.
        actions.append(Node(package=spec.package, executable=spec.executable,
                            arguments=list(spec.arguments), output='screen',
                            emulate_tty=True))
    return actions


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('sim', default_value='true',
                              description='drive the virtual fish (fish_sim) on a pty'),
        DeclareLaunchArgument('port', default_value='',
                              description='serial device of a real fish (sim:=false)'),
        DeclareLaunchArgument('namespace', default_value=DEFAULT_NAMESPACE),
        DeclareLaunchArgument('params_file', default_value='',
                              description='parameter YAML (default: config/wirefish.yaml)'),
        OpaqueFunction(function=_nodes),
    ])
