# SPDX-License-Identifier: Apache-2.0
"""
A probe process for one side of the two-host tests: it runs inside that side's namespace.

``python link_probe.py NAMESPACE TOPIC:TYPE:QOS ...`` subscribes to each topic (QOS sensor,
reliable or latched) and prints one JSON line every REPORT_S seconds on stdout:
``{"t": monotonic s, "counts": {topic: messages so far}, "gap": {topic: the longest time
between two messages, or since the last one, within the period}}`` and, for cpg_params and
planner_state, an event line ``{"t": .., "event": topic, ...fields}`` per message (planner
state: on a mode change only). Lines on stdin steer the cmd_vel publisher: ``go SPEED YAW``
publishes cmd_vel at 20 Hz, ``halt`` stops it. CLOCK_MONOTONIC is one clock for the whole
machine (a network namespace does not change it), so the test compares both sides' times.
"""

import json
import sys
import threading
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions

REPORT_S = 0.5
CMD_RATE_HZ = 20.0


def _qos(kind: str):
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from wirefish_common.qos import LATCHED, RELIABLE

    # Best effort as the sensor streams are published, but a deep queue: a probe busy for a
    # moment counts what came instead of losing it (the rate is the publisher's, not ours).
    sensor = QoSProfile(depth=200, reliability=ReliabilityPolicy.BEST_EFFORT)
    return {'sensor': sensor, 'reliable': RELIABLE, 'latched': LATCHED}[kind]


def _print(line: dict) -> None:
    sys.stdout.write(json.dumps(line) + '\n')
    sys.stdout.flush()


def main(argv: list[str]) -> int:
    from geometry_msgs.msg import Twist
    from wirefish_common.topics import message_class

    namespace, specs = argv[0], [a.split(':') for a in argv[1:]]
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node('link_probe', namespace=namespace)
    lock = threading.Lock()
    counts = {topic: 0 for topic, _, _ in specs}
    last = {topic: time.monotonic() for topic, _, _ in specs}
    gap = {topic: 0.0 for topic, _, _ in specs}
    mode = ['']

    def on_message(topic: str, msg) -> None:
        now = time.monotonic()
        with lock:
            counts[topic] += 1
            gap[topic] = max(gap[topic], now - last[topic])
            last[topic] = now
        if topic.endswith('cpg_params'):
            _print({'t': now, 'event': 'cpg_params', 'frequency_hz': msg.frequency_hz,
                    'amplitude': list(msg.amplitude), 'w12': msg.w12})
        elif topic.endswith('planner_state') and msg.mode != mode[0]:
            mode[0] = msg.mode
            _print({'t': now, 'event': 'planner_state', 'mode': msg.mode})

    for topic, type_name, qos in specs:
        node.create_subscription(message_class(type_name), topic,
                                 lambda m, t=topic: on_message(t, m), _qos(qos))
    command: list = [None]
    publisher = node.create_publisher(Twist, 'cmd_vel', _qos('reliable'))

    def send() -> None:
        if command[0] is not None:
            msg = Twist()
            msg.linear.x, msg.angular.z = command[0]
            publisher.publish(msg)

    def report() -> None:
        now = time.monotonic()
        with lock:
            line = {'t': now, 'counts': dict(counts),
                    'gap': {t: max(gap[t], now - last[t]) for t in gap}}
            for topic in gap:
                gap[topic] = 0.0
        _print(line)

    node.create_timer(1.0 / CMD_RATE_HZ, send)
    node.create_timer(REPORT_S, report)

    def read_commands() -> None:
        for text in sys.stdin:
            words = text.split()
            if words[:1] == ['go']:
                command[0] = (float(words[1]), float(words[2]))
            elif words[:1] == ['halt']:
                command[0] = None
        command[0] = None

    threading.Thread(target=read_commands, daemon=True).start()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    import signal
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    try:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
