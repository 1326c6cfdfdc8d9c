# SPDX-License-Identifier: Apache-2.0
"""
The QoS profiles of every wirefish topic and service client, defined once.

- ``SENSOR_DATA``: streams where only the latest sample matters (servo_cmd, imu/data, body_wave,
  servo_state...): best effort, shallow; rclpy's ``qos_profile_sensor_data``.
- ``RELIABLE``: commands, results and status a reader must not miss (/diagnostics,
  speed_estimate, retune results): reliable, volatile, depth 10. ``reliable(depth)`` for
  another depth.
- ``COMMAND``: a control signal sent at its controller's rate, where only the latest counts
  (cpg_command): reliable, volatile, keep last 1, so a late sample is superseded by the next.
- ``LATCHED``: state a node announces once and a late joiner still needs (cpg_params,
  cpg_status, target_wave): reliable, transient local, depth 1 (the last value).
  ``latched(depth)`` keeps the last ``depth`` for a late joiner (the tuner's feedback).
- ``TF``, ``TF_STATIC``, ``TF_STATIC_LISTENER``: tf2_ros's own profiles for /tf (broadcaster
  and listener alike), the /tf_static broadcaster and the /tf_static listener.
- ``CLOCK``: /clock, the simulated time fish_sim owns (reliable, keep last 1).
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, qos_profile_sensor_data, QoSProfile, ReliabilityPolicy

SENSOR_DATA: QoSProfile = qos_profile_sensor_data


def reliable(depth: int) -> QoSProfile:
    """Return a reliable, volatile profile keeping ``depth`` samples."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE)


def latched(depth: int) -> QoSProfile:
    """Return a reliable, transient-local profile keeping ``depth`` samples."""
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)


RELIABLE = reliable(10)
COMMAND = reliable(1)
LATCHED = latched(1)

TF = reliable(100)
TF_STATIC = latched(1)
# Deep enough to keep every latched /tf_static message when several broadcasters (a fleet's
# tf_nodes) answer one late subscriber at once; a depth of 1 would keep only the last writer's.
TF_STATIC_LISTENER = latched(100)
# /clock of the simulated-time road (fish_sim): rclpy's TimeSource takes it best effort, depth 1;
# a reliable writer serves it as well as a reader that wants every step (a test's probe).
CLOCK = reliable(1)
# The holding nodes' next ticks (clock_hold): several nodes answer on one fish's topic and its
# clock waits for each one's answer, so none may push another's out before fish_sim takes it
# (it takes them every millisecond while held; 100 is seconds of answers).
HOLD = reliable(100)
