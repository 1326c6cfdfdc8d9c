# SPDX-License-Identifier: Apache-2.0
"""`wirefish play`: a bag written by rosbags plays into a subscriber, every message in order."""

import subprocess
import sys
import threading
import time

import pytest
from wirefish_bag.verb.play import remapped

# It mostly waits (0.11 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

CLI = [sys.executable, '-m', 'wirefish_cli.cli']
COUNT = 40


def write_bag(path):
    """Write a bag: COUNT std_msgs/String on /recorded/chatter 20 ms apart, one latched."""
    from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                    QosReliability, QosTime)
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import get_typestore, Stores

    store = get_typestore(Stores.ROS2_JAZZY)
    string = store.types['std_msgs/msg/String']
    forever = QosTime(2**31 - 1, 0)

    def qos(durability):
        return Qos(QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, durability, forever,
                   forever, QosLiveliness.AUTOMATIC, forever, False)

    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        chatter = writer.add_connection('/recorded/chatter', 'std_msgs/msg/String',
                                        typestore=store,
                                        offered_qos_profiles=[qos(QosDurability.VOLATILE)])
        state = writer.add_connection('/recorded/state', 'std_msgs/msg/String',
                                      typestore=store,
                                      offered_qos_profiles=[qos(QosDurability.TRANSIENT_LOCAL)])
        start = 1_000_000_000_000
        writer.write(state, start, store.serialize_cdr(string(data='latched'), string.__msgtype__))
        for i in range(COUNT):
            writer.write(chatter, start + i * 20_000_000,
                         store.serialize_cdr(string(data=f'message {i}'), string.__msgtype__))


@pytest.mark.parametrize('topic, remaps, expected', [
    ('/wirefish/imu/data', [('/wirefish', '/replay')], '/replay/imu/data'),
    ('/wirefishy/imu', [('/wirefish', '/replay')], '/wirefishy/imu'),  # whole tokens only
    ('/diagnostics', [('/wirefish', '/replay')], '/diagnostics'),
])
def test_a_remap_replaces_a_whole_prefix(topic, remaps, expected):
    assert remapped(topic, remaps) == expected


@pytest.mark.ros
def test_play_publishes_every_message_in_order_with_its_qos(ros_context, ros_env, tmp_path):
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    bag = tmp_path / 'bag'
    write_bag(bag)
    node = rclpy.create_node('listener', context=ros_context)
    heard: list[str] = []
    node.create_subscription(String, '/played/chatter', lambda m: heard.append(m.data),
                             QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    try:
        # Discovery on a loaded machine took over 3 s: the first messages went to no one.
        result = subprocess.run([*CLI, 'play', str(bag), '--remap', '/recorded:=/played',
                                 '--wait-for-subscribers', '60', '--delay', '0.5'],
                                env=ros_env, capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stderr
        assert f'played {COUNT + 1} messages of 2 topics' in result.stdout
        assert 'deprecated' not in result.stderr, result.stderr  # rcl read no --remap of ours
        assert 'no subscriber' not in result.stderr, result.stderr
        deadline = time.monotonic() + 10.0
        while len(heard) < COUNT and time.monotonic() < deadline:
            time.sleep(0.1)
        assert heard == [f'message {i}' for i in range(COUNT)]
        # The latched topic is offered latched again, as its recorded publisher offered it.
        late = subprocess.Popen([*CLI, 'play', str(bag), '--topics', '/recorded/state',
                                 '--remap', '/recorded:=/played', '--delay', '10'],
                                env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        deadline = time.monotonic() + 30.0
        while not node.get_publishers_info_by_topic('/played/state') and \
                time.monotonic() < deadline:
            time.sleep(0.1)
        offered = [i.qos_profile.durability for i in
                   node.get_publishers_info_by_topic('/played/state')]
        assert late.wait(timeout=60) == 0, late.stderr.read()
        late.stdout.close()
        late.stderr.close()
        assert offered == [DurabilityPolicy.TRANSIENT_LOCAL]
    finally:
        executor.shutdown()
        spinner.join(timeout=5.0)
        node.destroy_node()


@pytest.mark.ros
def test_a_topic_without_a_subscriber_is_said_and_played_anyway(ros_env, tmp_path):
    bag = tmp_path / 'bag'
    write_bag(bag)
    result = subprocess.run([*CLI, 'play', str(bag), '--remap', '/recorded:=/nobody',
                             '--wait-for-subscribers', '0.5', '--delay', '0'],
                            env=ros_env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    # The latched topic needs no subscriber before it plays: only the volatile one is named.
    assert 'no subscriber of /nobody/chatter within 0.5 s: playing anyway' in result.stderr
    assert '/nobody/state' not in result.stderr
    assert f'played {COUNT + 1} messages of 2 topics' in result.stdout


@pytest.mark.parametrize('option, value', [('--delay', 'nan'), ('--delay', '-1'),
                                           ('--wait-for-subscribers', 'inf')])
def test_a_wait_that_is_no_number_of_seconds_is_refused(tmp_path, option, value):
    bag = tmp_path / 'bag'
    write_bag(bag)
    result = subprocess.run([*CLI, 'play', str(bag), option, value],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert f'{option} must be a number of seconds from 0 to 3600' in result.stderr
