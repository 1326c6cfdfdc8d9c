# SPDX-License-Identifier: Apache-2.0
"""
Small ROS peers that the cross-process tests start as separate processes.

Usage: ``python ros_peers.py PEER`` with PEER one of body_wave_talker, imu_talker or
retune_server.
"""

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Imu
from wirefish_msgs.msg import BodyWave
from wirefish_msgs.srv import RetuneGait


class BodyWaveTalker(Node):
    """Publishes a recognisable BodyWave at 20 Hz."""

    def __init__(self) -> None:
        super().__init__('body_wave_talker')
        self._pub = self.create_publisher(BodyWave, 'body_wave', 10)
        self._count = 0
        self.create_timer(0.05, self._tick)

    def _tick(self) -> None:
        msg = BodyWave()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = 'tail_base'
        msg.q = [0.0, 0.1, 0.2]
        msg.x = [0.0, 0.1, 0.2]
        msg.y = [0.0, 0.01, float(self._count)]
        msg.beta1 = 0.25
        self._count += 1
        self._pub.publish(msg)


class ImuTalker(Node):
    """Publishes Imu at IMU_RATE_HZ as sensor streams go: best effort, so a loss is a loss."""

    IMU_RATE_HZ = 200.0

    def __init__(self) -> None:
        super().__init__('imu_talker')
        self._pub = self.create_publisher(Imu, 'imu/data', qos_profile_sensor_data)
        self.create_timer(1.0 / self.IMU_RATE_HZ, self._tick)

    def _tick(self) -> None:
        msg = Imu()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = 'imu_link'
        msg.orientation.w = 1.0
        self._pub.publish(msg)


class RetuneServer(Node):
    """Answers RetuneGait with parameters derived from the request (a trivial server)."""

    def __init__(self) -> None:
        super().__init__('retune_server')
        self.create_service(RetuneGait, 'retune_gait', self._on_request)

    def _on_request(self, request: RetuneGait.Request,
                    response: RetuneGait.Response) -> RetuneGait.Response:
        response.success = request.wave.frequency_hz > 0.0
        response.message = 'echo'
        response.params.frequency_hz = request.wave.frequency_hz
        response.params.amplitude = [request.wave.c1, request.wave.c2]
        response.iterations = request.max_iterations
        return response


def main() -> None:
    peer = {'body_wave_talker': BodyWaveTalker, 'imu_talker': ImuTalker,
            'retune_server': RetuneServer}[sys.argv[1]]
    rclpy.init()
    node = peer()
    print('ready', flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
