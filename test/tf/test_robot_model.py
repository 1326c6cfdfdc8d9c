# SPDX-License-Identifier: Apache-2.0
"""
The fish's robot model: a URDF whose links are the TF tree's frames, latched on robot_description.

The claims: the shipped urdf/wirefish.urdf is what ``wirefish_tf.model`` makes of the default
params file's geometry and parses with ROS's own URDF parser (urdf-parser-py, from PyPI); its
links are exactly the frames tf_node publishes below ``odom``, with the TF tree's parents; a
tf_node started alone publishes it on ``robot_description`` for a subscriber that comes later
(transient local, as robot_state_publisher); the Foxglove layout and the RViz config show it.
"""

import json
from pathlib import Path
import time

from ament_index_python.packages import get_package_prefix
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_utils import spin_until
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage
from urdf_parser_py.urdf import URDF
from wirefish_bringup.graph import default_params_file
from wirefish_common.qos import SENSOR_DATA, TF_STATIC_LISTENER
from wirefish_kinematics.geometry import FishGeometry
from wirefish_msgs.msg import BodyWave
from wirefish_tf.frames import Frame
from wirefish_tf.model import fish_urdf
import yaml

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / 'src' / 'wirefish_bringup' / 'urdf' / 'wirefish.urdf'
RVIZ = ROOT / 'src' / 'wirefish_bringup' / 'rviz' / 'wirefish.rviz'
LAYOUT = ROOT / 'src' / 'wirefish_view' / 'layouts' / 'wirefish.json'
TF_NODE = Path(get_package_prefix('wirefish_tf'), 'lib', 'wirefish_tf', 'tf_node')
# robot_state_publisher's profile for robot_description: a late subscriber gets the last one.
DESCRIPTION_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
# The TF tree's parent of each frame (wirefish_tf.frames' docstring; tf_node publishes it).
TF_PARENTS = {'imu_link': 'base_link', 'tail_base': 'base_link', 'tail_plate_ii': 'tail_base',
              'tail_plate_iii': 'tail_base', 'caudal_fin': 'tail_base'}


def _parents(robot: URDF) -> dict[str, str]:
    return {joint.child: joint.parent for joint in robot.joints}


def test_the_shipped_urdf_is_the_default_fish():
    values = yaml.safe_load(default_params_file().read_text())['/**']['ros__parameters']
    geometry = FishGeometry(**{n: float(values[n]) for n in
                               ('l1', 'l2', 'l3', 'body_length', 'fin_span')})
    assert SHIPPED.read_text() == fish_urdf(geometry)


def test_the_urdf_links_are_the_tf_trees_frames():
    robot = URDF.from_xml_string(SHIPPED.read_text())
    assert {link.name for link in robot.links} == {f.value for f in Frame} - {'odom'}
    assert _parents(robot) == TF_PARENTS
    assert robot.get_root() == 'base_link'
    head = robot.link_map['base_link'].visuals[0]
    assert head.geometry.size == [0.29, 0.106, 0.15]  # 530 x 106 x 150 mm less the tail
    fin = robot.link_map['caudal_fin'].visuals[-1]
    assert fin.geometry.size[0] == 0.06 and fin.origin.xyz[0] == 0.03  # l3 from plate V


def test_tf_node_latches_the_model_and_its_links_are_the_frames_it_publishes(spawn,
                                                                             ros_context):
    tf_node = spawn([str(TF_NODE), '--ros-args', '-r', '__ns:=/model'])
    node = rclpy.create_node('model_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        frames: dict[str, str] = {}

        def heard(message: TFMessage) -> None:
            frames.update({t.child_frame_id: t.header.frame_id for t in message.transforms})

        node.create_subscription(TFMessage, '/tf', heard, 100)
        node.create_subscription(TFMessage, '/tf_static', heard, TF_STATIC_LISTENER)
        wave = node.create_publisher(BodyWave, '/model/body_wave', SENSOR_DATA)
        assert spin_until(executor, lambda: wave.get_subscription_count() > 0, 30.0), (
            tf_node.poll())
        assert spin_until(executor, lambda: wave.publish(BodyWave(beta1=0.2, beta2=0.1))
                          or len(frames) == len(TF_PARENTS), 20.0), frames
        # A subscriber that comes after the publication still gets it (latched).
        time.sleep(0.5)
        descriptions: list[String] = []
        node.create_subscription(String, '/model/robot_description', descriptions.append,
                                 DESCRIPTION_QOS)
        assert spin_until(executor, lambda: bool(descriptions), 20.0)
    finally:
        executor.shutdown()
        node.destroy_node()
    robot = URDF.from_xml_string(descriptions[-1].data)
    assert _parents(robot) == frames == TF_PARENTS


def test_the_foxglove_layout_and_the_rviz_config_show_the_model():
    layers = [layer for panel in json.loads(LAYOUT.read_text())['configById'].values()
              for layer in panel.get('layers', {}).values()]
    urdf = [layer for layer in layers if layer.get('layerId') == 'foxglove.Urdf']
    assert [(u['sourceType'], u['topic']) for u in urdf] == [
        ('topic', '/wirefish/robot_description')]
    rviz = yaml.safe_load(RVIZ.read_text())
    displays = rviz['Visualization Manager']['Displays']
    model = [d for d in displays if d['Class'] == 'rviz_default_plugins/RobotModel']
    assert len(model) == 1
    assert model[0]['Description Source'] == 'Topic'
    assert model[0]['Description Topic']['Value'] == '/wirefish/robot_description'
    assert model[0]['Description Topic']['Durability Policy'] == 'Transient Local'
    assert rviz['Visualization Manager']['Global Options']['Fixed Frame'] == 'odom'
