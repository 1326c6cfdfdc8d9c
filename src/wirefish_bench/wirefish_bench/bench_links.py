# SPDX-License-Identifier: Apache-2.0
"""
Latency of the bridge's two paths, over a real pty and real DDS (a benchmark, not a test).

(a) command: ``servo_cmd`` published here -> the SERVO_CMD frame's bytes readable on the fish's
    side of the pty (this process plays the fish: it holds the pty master);
(b) telemetry: TELEMETRY bytes written on the fish's side -> ``imu/data`` received here.
bridge_node runs as its own process (the installed executable). ``python -m
wirefish_bench.bench_links`` prints the JSON.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import select
import signal
import subprocess
import time
import tty

import numpy as np

from wirefish_bench.bench_graph import ros_session


def _percentiles(samples_s: list[float]) -> dict:
    if not samples_s:
        return {'count': 0}
    ms = np.asarray(samples_s) * 1000.0
    return {'count': int(ms.size), 'p50_ms': float(np.percentile(ms, 50)),
            'p99_ms': float(np.percentile(ms, 99)), 'max_ms': float(ms.max())}


def _measure(node, spinner, master: int, samples: int, period_s: float
             ) -> tuple[list[float], list[float]]:
    """Play the fish on ``master``: return the command and telemetry latencies (s)."""
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Imu, JointState
    from wirefish_bridge.codec import FrameEncoder, StreamDecoder
    from wirefish_bridge.protocol import Heartbeat, Role, ServoCommand, Telemetry

    received: list[float] = []
    node.create_subscription(Imu, 'imu/data', lambda _m: received.append(time.perf_counter()),
                             qos_profile_sensor_data)
    publisher = node.create_publisher(JointState, 'servo_cmd', qos_profile_sensor_data)
    encoder, decoder = FrameEncoder(), StreamDecoder()
    command_latency: list[float] = []
    telemetry_latency: list[float] = []
    deadline = time.monotonic() + 20.0   # discovery: until a telemetry comes back
    while time.monotonic() < deadline and not received:
        os.write(master, encoder.encode(Heartbeat(role=Role.FISH)))
        os.write(master, encoder.encode(Telemetry(0, 0.0, 0.0, 0.0, (0.0,) * 3,
                                                  (0.0, 0.0, 9.8), 0.0, 0.0, 8.0)))
        spinner.spin_once(timeout_sec=0.1)
    for i in range(samples):
        # (a) command path
        angle = 0.001 * (i % 100 + 1)
        sent = time.perf_counter()
        publisher.publish(JointState(name=['servo_1', 'servo_2'], position=[angle, 0.0]))
        stop = sent + 0.5
        while time.perf_counter() < stop:
            ready, _, _ = select.select([master], [], [], 0.0005)
            if not ready:
                continue
            frames = decoder.feed(os.read(master, 4096))
            if any(isinstance(f.message, ServoCommand)
                   and abs(f.message.servo_1 - angle) < 1e-6 for f in frames):
                command_latency.append(time.perf_counter() - sent)
                break
        # (b) telemetry path
        count = len(received)
        written = time.perf_counter()
        os.write(master, encoder.encode(Telemetry(i, 0.0, 0.0, 0.0, (0.0,) * 3,
                                                  (0.0, 0.0, 9.8), 0.0, 0.0, 8.0)))
        stop = written + 0.5
        while len(received) == count and time.perf_counter() < stop:
            spinner.spin_once(timeout_sec=0.0005)
        if len(received) > count:
            telemetry_latency.append(received[count] - written)
        time.sleep(period_s)
    return command_latency, telemetry_latency


def run(samples: int = 300, domain_id: int = 99, period_s: float = 0.02,
        executor: str | None = None) -> dict:
    """
    Measure both paths ``samples`` times each; return p50/p99 (ms) per path.

    ``executor`` ('events' or 'classic'; None: its default) is the bridge's WIREFISH_EXECUTOR.
    """
    from ament_index_python.packages import get_package_prefix

    master, slave = os.openpty()
    tty.setraw(slave)
    os.set_blocking(master, False)
    port = os.ttyname(slave)
    exe = Path(get_package_prefix('wirefish_bridge')) / 'lib' / 'wirefish_bridge' / 'bridge_node'
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    if executor is not None:
        env['WIREFISH_EXECUTOR'] = executor
    bridge = subprocess.Popen([str(exe), '--ros-args', '-p', f'port:={port}',
                               '-p', 'max_command_rate_hz:=1000.0'],
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              start_new_session=True)
    try:
        # The receiver spins on the bridge's executor kind (see bench_graph.ros_session).
        with ros_session(domain_id, executor) as (node, spinner):
            command_latency, telemetry_latency = _measure(node, spinner, master, samples,
                                                          period_s)
    finally:
        if bridge.poll() is None:
            os.killpg(bridge.pid, signal.SIGINT)
            try:
                bridge.wait(timeout=5.0)
            except subprocess.TimeoutExpired:
                os.killpg(bridge.pid, signal.SIGKILL)
                bridge.wait()
        os.close(master)
        os.close(slave)
    return {'executor': executor, 'command': _percentiles(command_latency),
            'telemetry': _percentiles(telemetry_latency),
            'how': f'{samples} samples each, {period_s * 1000:.0f} ms apart; bridge_node as a '
                   'separate process on a pty held by the benchmark (which plays the fish); '
                   'perf_counter from publish to bytes readable (command), and from write to '
                   "the imu/data callback (telemetry), received on the bridge's executor kind"}


if __name__ == '__main__':
    print(json.dumps(run(), indent=1))
