# SPDX-License-Identifier: Apache-2.0
"""
What one ROS message, timer tick or publish costs a Python process here (not a test).

docs/PROFILING.md builds its cost model of a fish's graph from these figures: each probe is a
process of its own on the events executor (the graph's default), measured with psutil over a
window after a warm-up. ``python -m wirefish_bench.message_cost`` prints the JSON: CPU in %
of one core per process of each probe, and the same per event in microseconds.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import psutil

RATE_HZ = 200.0  # servo_cmd's rate before its default became 100 Hz
TICK_HZ = 50.0  # kinematics_node's body_wave tick
WARM_UP_S = 4.0
MODULE = 'wirefish_bench.message_cost'  # each probe runs as its own process
# The probes' own topic: not one of the graph's (CONTRACTS.md lists those).
PROBE_TOPIC = 'cost_probe'


def _spin(node) -> None:
    from rclpy.experimental import EventsExecutor

    executor = EventsExecutor()
    executor.add_node(node)
    while True:
        executor.spin_once(timeout_sec=0.1)


def _publisher(rate_hz: float) -> None:
    """Publish a servo JointState at ``rate_hz`` from a thread loop, as cpg_node does."""
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState

    rclpy.init()
    node = rclpy.create_node('cost_publisher')
    publisher = node.create_publisher(JointState, PROBE_TOPIC, qos_profile_sensor_data)
    msg = JointState(name=['servo_1', 'servo_2'], position=[0.1, 0.2], velocity=[0.0, 0.0])
    deadline = time.monotonic()
    while True:
        deadline += 1.0 / rate_hz
        delay = deadline - time.monotonic()
        if delay > 0.0:
            time.sleep(delay)
        publisher.publish(msg)


def _subscriber(kind: str) -> None:
    """
    Take the probe's messages on the events executor: ``msg``, ``raw`` bytes, or ``none``.

    ``msg+tick``: a callback per message beside a 50 Hz timer (kinematics_node before);
    ``batch+tick``: the 50 Hz timer takes what arrived from a ``BatchIntake`` and reads each
    sample (kinematics_node now); ``raw+read``: a raw callback that reads the servo pair from
    the bytes, ``msg+read`` the same from the message (the bridge's intake, now and before).
    """
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from wirefish_common.batch_intake import BatchIntake
    from wirefish_common.cdr_views import read_joint_state
    from wirefish_common.servo_joints import servo_sample

    def read_message(msg) -> None:
        servo_sample(msg)

    def read_bytes(data) -> None:
        servo_sample(read_joint_state(data))

    rclpy.init()
    node = rclpy.create_node('cost_subscriber')
    if kind in ('msg', 'raw'):
        node.create_subscription(JointState, PROBE_TOPIC, lambda _m: None,
                                 qos_profile_sensor_data, raw=kind == 'raw')
    elif kind == 'msg+read':
        node.create_subscription(JointState, PROBE_TOPIC, read_message, qos_profile_sensor_data)
    elif kind == 'raw+read':
        node.create_subscription(JointState, PROBE_TOPIC, read_bytes, qos_profile_sensor_data,
                                 raw=True)
    elif kind == 'msg+tick':
        node.create_subscription(JointState, PROBE_TOPIC, read_message, qos_profile_sensor_data)
        node.create_timer(1.0 / TICK_HZ, lambda: None)
    elif kind == 'batch+tick':
        intake = BatchIntake(node, JointState, PROBE_TOPIC, _batch_qos())

        def take_batch() -> None:
            for data in intake.take():
                read_bytes(data)
        node.create_timer(1.0 / TICK_HZ, take_batch)
    _spin(node)


def _batch_qos():
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    # Four ticks' worth of samples at the probe's rate: a late tick loses none.
    return QoSProfile(depth=16, reliability=ReliabilityPolicy.BEST_EFFORT)


def _timer(rate_hz: float) -> None:
    """Run an empty timer callback at ``rate_hz`` on the events executor."""
    import rclpy

    rclpy.init()
    node = rclpy.create_node('cost_timer')
    node.create_timer(1.0 / rate_hz, lambda: None)
    _spin(node)


ROLES = {'publisher': lambda arg: _publisher(float(arg)), 'subscriber': _subscriber,
         'timer': lambda arg: _timer(float(arg))}


def _measure(roles: list[tuple[str, str]], window_s: float, domain_id: int) -> list[float]:
    """Run one process per role; return each one's CPU (% of a core) over ``window_s``."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    procs = [subprocess.Popen([sys.executable, '-m', MODULE, '--role', role, arg], env=env)
             for role, arg in roles]
    try:
        time.sleep(WARM_UP_S)
        handles = [psutil.Process(p.pid) for p in procs]
        start = [sum(h.cpu_times()[:2]) for h in handles]
        time.sleep(window_s)
        return [100.0 * (sum(h.cpu_times()[:2]) - s) / window_s for h, s in zip(handles, start)]
    finally:
        for p in procs:
            p.kill()
            p.wait()


def run(window_s: float = 8.0, domain_id: int = 93, only: str = '') -> dict:
    """Measure every probe (``only``: those whose name holds it); return CPU and us/event."""
    rate = str(RATE_HZ)
    probes = {
        'idle node': [('subscriber', 'none')],
        'timer at 200 Hz': [('timer', rate)],
        'publisher at 200 Hz, no reader': [('publisher', rate)],
        'publisher at 200 Hz, one reader': [('publisher', rate), ('subscriber', 'msg')],
        'publisher at 200 Hz, one raw reader': [('publisher', rate), ('subscriber', 'raw')],
        'publisher at 200 Hz, two readers': [('publisher', rate), ('subscriber', 'msg'),
                                             ('subscriber', 'msg')],
        'servo pair read from each message': [('publisher', rate), ('subscriber', 'msg+read')],
        'servo pair read from the raw bytes': [('publisher', rate), ('subscriber', 'raw+read')],
        'a callback per message and a 50 Hz tick': [('publisher', rate),
                                                    ('subscriber', 'msg+tick')],
        'a 50 Hz tick taking a batch': [('publisher', rate), ('subscriber', 'batch+tick')],
    }
    results = {}
    for name, roles in probes.items():
        if only not in name:
            continue
        cpu = _measure(roles, window_s, domain_id)
        results[name] = {'cpu_percent': [round(c, 2) for c in cpu],
                         'us_per_event': [round(c / 100.0 / RATE_HZ * 1e6) for c in cpu]}
    return {'window_s': window_s, 'rate_hz': RATE_HZ, 'probes': results}


def main(argv: list[str] | None = None) -> int:
    """Print the probes' JSON, or run one probe process (``--role``)."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--role', nargs=2, metavar=('ROLE', 'ARG'), help=argparse.SUPPRESS)
    parser.add_argument('--window', type=float, default=8.0, help='seconds measured per probe')
    parser.add_argument('--only', default='', help='run the probes whose name holds this text')
    args = parser.parse_args(argv)
    if args.role:
        ROLES[args.role[0]](args.role[1])
        return 0
    print(json.dumps(run(args.window, only=args.only), indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
