#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""
Does a SIGKILLed subscriber stall its publisher? A 100 Hz publisher, a victim killed N times.

    tools/wfenv python tools/probes/kill_stall_probe.py --kills 12
    # with shared memory:
    FASTDDS_BUILTIN_TRANSPORTS=DEFAULT tools/wfenv python tools/probes/kill_stall_probe.py

The publisher (a process of its own, RELIABLE, depth 10, like servo_cmd) times every
``publish()``; a victim subscriber is started, left ALIVE_S, SIGKILLed and started again. The
last line is the publisher's account: messages sent, its longest publish in ms, and every
publish over STALL_S. The transports are the environment's (FASTDDS_BUILTIN_TRANSPORTS).
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import time

PERIOD_S = 0.01
ALIVE_S = 2.5
DEAD_S = 0.5
STALL_S = 0.05
TOPIC = 'kill_stall_probe'


def _qos():
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    return QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)


def publish_for(duration_s: float) -> dict:
    """Publish an Int64 count at 100 Hz for ``duration_s``; return the publisher's account."""
    import rclpy
    from std_msgs.msg import Int64
    rclpy.init()
    node = rclpy.create_node('kill_stall_publisher')
    publisher = node.create_publisher(Int64, TOPIC, _qos())
    message, longest, stalls = Int64(), 0.0, []
    start = next_at = time.monotonic()
    while time.monotonic() < start + duration_s:
        before = time.monotonic()
        message.data += 1
        publisher.publish(message)
        took = time.monotonic() - before
        longest = max(longest, took)
        if took > STALL_S:
            stalls.append([round(before - start, 2), round(took, 3)])
        next_at += PERIOD_S
        time.sleep(max(0.0, next_at - time.monotonic()))
    node.destroy_node()
    rclpy.shutdown()
    return {'sent': message.data, 'longest_publish_ms': round(longest * 1e3, 1),
            'stalls': stalls}


def subscribe_forever() -> None:
    """Subscribe to the count and spin until killed."""
    import rclpy
    from std_msgs.msg import Int64
    rclpy.init()
    node = rclpy.create_node(f'kill_stall_victim_{os.getpid()}')
    node.create_subscription(Int64, TOPIC, lambda _msg: None, _qos())
    rclpy.spin(node)


def run(kills: int) -> dict:
    """Run the publisher while a victim is killed ``kills`` times; return its account."""
    me = [sys.executable, os.path.abspath(__file__)]
    duration_s = 3.0 + kills * (ALIVE_S + DEAD_S) + 2.0
    publisher = subprocess.Popen([*me, '--role', 'publisher', '--duration', str(duration_s)],
                                 stdout=subprocess.PIPE, text=True)
    try:
        time.sleep(3.0)
        for _ in range(kills):
            victim = subprocess.Popen([*me, '--role', 'victim'])
            time.sleep(ALIVE_S)
            victim.send_signal(signal.SIGKILL)
            victim.wait()
            time.sleep(DEAD_S)
        out, _ = publisher.communicate(timeout=duration_s + 30.0)
    finally:
        if publisher.poll() is None:
            publisher.kill()
            publisher.wait()
    if publisher.returncode != 0:
        raise RuntimeError(f'the publisher exited with {publisher.returncode}')
    return json.loads(out.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0].strip())
    parser.add_argument('--kills', type=int, default=12, help='victim kills (default 12)')
    parser.add_argument('--role', choices=['run', 'publisher', 'victim'], default='run',
                        help=argparse.SUPPRESS)
    parser.add_argument('--duration', type=float, default=0.0, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.kills < 1:
        parser.error('--kills must be at least 1')
    if args.role == 'publisher':
        print(json.dumps(publish_for(args.duration)), flush=True)
    elif args.role == 'victim':
        subscribe_forever()
    else:
        transports = os.environ.get('FASTDDS_BUILTIN_TRANSPORTS', 'DEFAULT (SHM and UDPv4)')
        print(f'transports {transports}, {args.kills} kills', flush=True)
        print(json.dumps(run(args.kills)), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
