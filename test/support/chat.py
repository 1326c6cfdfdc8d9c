# SPDX-License-Identifier: Apache-2.0
"""
A one-topic DDS probe for the pair tests: ``python chat.py talk|listen SECONDS``.

``talk`` publishes a String on ``chat`` at 20 Hz; ``listen`` prints ``heard N`` once, on the
first message, and exits 0 (1 if nothing came within SECONDS).
"""

import sys
import time

import rclpy
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import String


def main(role: str, seconds: float) -> int:
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(f'chat_{role}')
    heard = []
    if role == 'talk':
        publisher = node.create_publisher(String, 'chat', 10)
        node.create_timer(0.05, lambda: publisher.publish(String(data='fish')))
    else:
        node.create_subscription(String, 'chat', heard.append, 10)
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and not heard:
        rclpy.spin_once(node, timeout_sec=0.1)
    if heard:
        print(f'heard {len(heard)}', flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0 if heard or role == 'talk' else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv[1], float(sys.argv[2])))
