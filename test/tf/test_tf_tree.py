# SPDX-License-Identifier: Apache-2.0
"""
The TF tree of `wirefish up --sim`, rebuilt by an independent subscriber from /tf and /tf_static.

One graph for the module. The claims: the published TFMessage is Jazzy's type (its type hash);
the frames make one tree with one parent each; odom -> base_link is the virtual fish's ground
truth; the fin frame sits on the kinematics' body wave; a fleet's frames are prefixed apart.
"""

from collections import defaultdict
import math
import os
from pathlib import Path
import time

from ament_index_python.packages import get_package_prefix
from e2e_utils import start_graph, stopped_on_exit
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from sensor_msgs.msg import Imu
from tf2_msgs.msg import TFMessage
from wirefish_common.qos import RELIABLE, reliable, SENSOR_DATA, TF_STATIC_LISTENER
from wirefish_kinematics.body_wave import body_positions
from wirefish_kinematics.geometry import FishGeometry
from wirefish_msgs.msg import BodyWave, SpeedEstimate

pytestmark = pytest.mark.ros

JAZZY_TF_MESSAGE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'
NAMESPACE = '/e2e_tf'
GEOMETRY = FishGeometry()  # the default parameter file's geometry
FRAMES = {'odom', 'base_link', 'imu_link', 'tail_base', 'tail_plate_ii', 'tail_plate_iii',
          'caudal_fin'}
TF_NODE = Path(get_package_prefix('wirefish_tf'), 'lib', 'wirefish_tf', 'tf_node')
MATCHED_AT_LEAST = 50  # truths a transform is checked against, for each of the two checks
# Of the truths in the span, the share that must have their transform heard. Every hop keeps
# the last samples only (the /tf writer 100, tf_node's ground-truth reader 50), so a listener
# starved for a second on a loaded machine loses some: the claim is the values, and that the
# transforms follow the truths, not that no sample is ever dropped.
MATCHED_SHARE = 0.75
SPANNED = 2 * MATCHED_AT_LEAST  # truths the transforms span before the checks start
SEND_PERIOD_S = 0.05  # how often the fleet test feeds its two tf_nodes


def _stamp_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


class TfRecord:
    """Everything an independent listener heard: /tf, /tf_static and the graph's own truths."""

    def __init__(self, node, namespace: str | None = None) -> None:
        self.transforms: list[TransformStamped] = []
        self.static: list[TransformStamped] = []
        self.ground_truth: list[Odometry] = []
        self.body_wave: list[BodyWave] = []
        self.tf_type_hash = ''
        # 10 s of /tf: this listener may be starved for a while on a loaded machine too
        node.create_subscription(TFMessage, '/tf', lambda m: self.transforms.extend(m.transforms),
                                 reliable(depth=1000))
        node.create_subscription(TFMessage, '/tf_static',
                                 lambda m: self.static.extend(m.transforms),
                                 TF_STATIC_LISTENER)
        if namespace is not None:
            node.create_subscription(Odometry, f'{namespace}/sim/ground_truth',
                                     self.ground_truth.append, RELIABLE)
            node.create_subscription(BodyWave, f'{namespace}/body_wave', self.body_wave.append,
                                     SENSOR_DATA)

    def parents(self) -> dict[str, set[str]]:
        found: dict[str, set[str]] = defaultdict(set)
        for t in [*self.static, *self.transforms]:
            found[t.child_frame_id].add(t.header.frame_id)
        return found

    def latest(self, child: str) -> dict[int, TransformStamped]:
        return {_stamp_ns(t.header.stamp): t for t in self.transforms
                if t.child_frame_id == child}


def _while_published(messages: list, published: dict[int, TransformStamped]) -> list:
    """Return the messages stamped from the first to the last transform published for them."""
    if not published:
        return []
    first, last = min(published), max(published)
    return [m for m in messages if first <= _stamp_ns(m.header.stamp) <= last]


def _spanned(record: TfRecord) -> int:
    """Return the fewest truths (ground truth, body wave) the transforms heard so far span."""
    return min(len(_while_published(record.ground_truth, record.latest('base_link'))),
               len(_while_published(record.body_wave, record.latest('caudal_fin'))))


def _roots(parents: dict[str, set[str]]) -> set[str]:
    frames = set(parents) | {p for ps in parents.values() for p in ps}
    return {f for f in frames if f not in parents}


@pytest.fixture(scope='module')
def heard(tmp_path_factory):
    """Run `wirefish up --sim` and listen to its TF for a few seconds; yield the record."""
    domain = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19
    graph = start_graph(domain, tmp_path_factory.mktemp('tf_run'), namespace=NAMESPACE)
    with stopped_on_exit(graph):
        yield from _listened(domain)


def _listened(domain: int):
    """Listen to the graph's TF on ``domain`` until the transforms span enough; yield it."""
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('tf_listener', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        record = TfRecord(node, NAMESPACE)
        # /tf may be discovered after the truths: wait until the transforms span enough of
        # them for the checks below, not only for the truths.
        assert spin_until(executor, lambda: record.static and _spanned(record) >= SPANNED,
                          timeout_s=45.0), 'no TF spanning ground truths and body waves in 45 s'
        spin_until(executor, lambda: False, timeout_s=0.5)  # the last transforms' answers
        infos = node.get_publishers_info_by_topic('/tf')
        record.tf_type_hash = ' '.join(sorted({str(i.topic_type_hash) for i in infos}))
        yield record
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def test_the_published_tf_message_is_jazzys_type(heard):
    assert heard.tf_type_hash == JAZZY_TF_MESSAGE_HASH


def test_the_frames_form_one_tree_with_one_parent_each(heard):
    parents = heard.parents()
    assert FRAMES <= set(parents) | {'odom'}
    assert {child: ps for child, ps in parents.items() if len(ps) != 1} == {}
    assert _roots(parents) == {'odom'}


def test_odom_to_base_link_is_the_ground_truth_within_a_millimetre(heard):
    published = heard.latest('base_link')
    matched = 0
    truths = _while_published(heard.ground_truth, published)
    error = 0.0
    for truth in truths:
        t = published.get(_stamp_ns(truth.header.stamp))
        if t is None:
            continue
        matched += 1
        p, q = truth.pose.pose.position, t.transform.translation
        assert t.header.frame_id == 'odom'
        error = max(error, math.hypot(p.x - q.x, p.y - q.y))
    print(f'odom -> base_link: {matched} of {len(truths)} ground truths matched, '
          f'largest distance {error:.3g} m')
    assert error <= 1e-3
    assert matched >= max(MATCHED_AT_LEAST, MATCHED_SHARE * len(truths))


def test_the_fin_frame_is_on_the_body_wave(heard):
    fin = heard.latest('caudal_fin')
    matched, lateral, fin_error, tip_error = 0, [], 0.0, 0.0
    fin_root = np.array([GEOMETRY.l1 + GEOMETRY.l2])
    waves = _while_published(heard.body_wave, fin)
    for wave in waves:
        t = fin.get(_stamp_ns(wave.header.stamp))
        if t is None:
            continue
        matched += 1
        _, y = body_positions(fin_root, wave.beta1, wave.beta2, GEOMETRY)
        assert t.header.frame_id == 'tail_base'
        fin_error = max(fin_error, abs(t.transform.translation.y - float(y[0])))
        # The rigid fin reaches the body wave's last station, the tail tip, along its x.
        yaw = 2.0 * math.atan2(t.transform.rotation.z, t.transform.rotation.w)
        tip_y = t.transform.translation.y + GEOMETRY.l3 * math.sin(yaw)
        tip_error = max(tip_error, abs(tip_y - wave.y[-1]))
        lateral.append(t.transform.translation.y)
    print(f'caudal_fin: {matched} of {len(waves)} body waves matched, lateral error '
          f'{fin_error:.3g} m at plate V, {tip_error:.3g} m at the tip')
    assert fin_error <= 1e-6 and tip_error <= 1e-6
    assert matched >= max(MATCHED_AT_LEAST, MATCHED_SHARE * len(waves))
    assert np.ptp(lateral) > 0.01  # the tail beats: the frame moves


@pytest.fixture
def fleet(spawn, ros_context):
    """Start the tf_node processes of two fish, fish_1 and fish_2; yield a listener."""
    procs = {fish: spawn([str(TF_NODE), '--ros-args', '-r', f'__ns:=/fleet/{fish}',
                          '-p', f'frame_prefix:={fish}'])
             for fish in ('fish_1', 'fish_2')}
    node = rclpy.create_node('fleet_listener', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    yield node, executor, procs
    executor.shutdown()
    node.destroy_node()


def test_a_fleets_frames_are_prefixed_and_distinct(fleet):
    node, executor, procs = fleet
    record = TfRecord(node)
    waves = {fish: node.create_publisher(BodyWave, f'/fleet/{fish}/body_wave', SENSOR_DATA)
             for fish in ('fish_1', 'fish_2')}
    truths = {fish: node.create_publisher(Odometry, f'/fleet/{fish}/sim/ground_truth', RELIABLE)
              for fish in ('fish_1', 'fish_2')}

    sent = [-math.inf]

    def send_and_check() -> bool:
        if time.monotonic() - sent[0] < SEND_PERIOD_S:  # 20 Hz, not once per callback
            return False
        sent[0] = time.monotonic()
        for fish in waves:
            wave = BodyWave(beta1=0.3, beta2=-0.2)
            waves[fish].publish(wave)
            truth = Odometry()
            truth.pose.pose.orientation.w = 1.0
            truths[fish].publish(truth)
        children = set(record.parents())
        return len(children) >= 2 * (len(FRAMES) - 1)

    if not spin_until(executor, send_and_check, timeout_s=30.0):
        alive = {fish: proc.poll() is None for fish, proc in procs.items()}
        pytest.fail(f'frames heard: {sorted(record.parents())}; tf_node alive: {alive}')
    parents = record.parents()
    for fish in ('fish_1', 'fish_2'):
        mine = {c for c in parents if c.startswith(f'{fish}/')}
        assert mine == {f'{fish}/{f}' for f in FRAMES - {'odom'}}
        assert {p for c in mine for p in parents[c]} <= {f'{fish}/{f}' for f in FRAMES}
    assert {child: ps for child, ps in parents.items() if len(ps) != 1} == {}
    assert _roots(parents) == {'fish_1/odom', 'fish_2/odom'}


def test_the_real_fish_is_dead_reckoned_from_imu_yaw_and_the_speed_estimate(spawn, ros_context):
    spawn([str(TF_NODE), '--ros-args', '-r', '__ns:=/reckoned', '-p',
           'odom_source:=dead_reckoning'])
    node = rclpy.create_node('reckoning_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        record = TfRecord(node)
        imu = node.create_publisher(Imu, '/reckoned/imu/data', SENSOR_DATA)
        speed = node.create_publisher(SpeedEstimate, '/reckoned/speed_estimate', RELIABLE)
        assert spin_until(executor, lambda: imu.get_subscription_count() > 0
                          and speed.get_subscription_count() > 0, timeout_s=20.0)
        estimate = SpeedEstimate(speed=0.2)
        # Heading +y (yaw pi/2), 0.2 m/s: 100 IMU samples 10 ms apart are 0.198 m of travel.
        for i in range(101):
            speed.publish(estimate)
            sample = Imu()
            sample.header.stamp.sec, sample.header.stamp.nanosec = 100, 0
            sample.header.stamp.sec += (i * 10_000_000) // 1_000_000_000
            sample.header.stamp.nanosec = (i * 10_000_000) % 1_000_000_000
            sample.orientation.z = sample.orientation.w = math.sqrt(0.5)
            imu.publish(sample)
            spin_until(executor, lambda: False, timeout_s=0.02)
        # Best effort: a loaded tf_node may drop samples, which costs nothing (dt comes from
        # the stamps) unless they are the last ones; half of the run must be in.
        assert spin_until(executor, lambda: any(
            _stamp_ns(t.header.stamp) >= 100_500_000_000 for t in record.transforms),
            timeout_s=10.0)
        spin_until(executor, lambda: False, timeout_s=1.0)
    finally:
        executor.shutdown()
        node.destroy_node()
    last = max(record.transforms, key=lambda t: _stamp_ns(t.header.stamp))
    travelled = 0.2 * (_stamp_ns(last.header.stamp) - 100_000_000_000) * 1e-9
    p = last.transform.translation
    assert (last.header.frame_id, last.child_frame_id) == ('odom', 'base_link')
    # The first samples may precede the first speed estimate: at most that much short.
    assert abs(p.x) < 1e-9 and travelled - 0.05 <= p.y <= travelled + 1e-9
