# SPDX-License-Identifier: Apache-2.0
"""A fleet of virtual fish on one clock: each fish swims as it would alone (no ROS, no pty)."""

import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Telemetry
from wirefish_kinematics.geometry import FishGeometry
from wirefish_sim.servo_model import Servo, ServoParameters
from wirefish_sim.virtual_fish import SimConfig, VirtualFish
from wirefish_sim.virtual_fleet import VirtualFleet

FISH = 3
SECONDS = 4.0
# Each fish's own gait (amplitude rad, frequency Hz, offset rad) and when its host goes quiet
# (s; the firmware's failsafe then takes it to neutral): the fish must not mix.
GAITS = ((0.5, 1.0, 0.0, None), (0.3, 2.5, 0.15, 2.0), (0.6, 0.7, -0.2, 3.0))


def _frames(t, gait):
    amplitude, frequency, offset, quiet_after = gait
    if quiet_after is not None and t >= quiet_after:
        return b''
    angle = offset + amplitude * np.sin(2.0 * np.pi * frequency * t)
    encoder = FrameEncoder()
    return encoder.encode(Heartbeat()) + encoder.encode(ServoCommand(angle, 0.7 * angle))


def _record(fishes, gaits, step, seed):
    """Drive ``fishes`` with ``gaits`` over wall-clock-like steps; return states, frames."""
    steps = np.random.default_rng(seed).uniform(0.0007, 0.011, int(SECONDS / 0.005))
    states, output = [], [b''] * len(fishes)
    t = 0.0
    for dt in steps.tolist():
        for k, fish in enumerate(fishes):
            fish.receive(_frames(t, gaits[k]))
        step(dt)
        t += dt
        states.append([[f.state.time_s, f.state.speed, f.state.yaw_rate, f.state.yaw,
                        f.state.x, f.state.y, f.state.tail_tip_offset] for f in fishes])
        output = [o + b''.join(f.take_output()) for o, f in zip(output, fishes)]
    return np.array(states), output


def _telemetry(data):
    return [f.message for f in StreamDecoder().feed(data) if isinstance(f.message, Telemetry)]


@pytest.fixture(scope='module')
def fleet_and_alone():
    config, geometry = SimConfig(), FishGeometry()
    fleet = VirtualFleet([np.random.default_rng(10 + k) for k in range(FISH)], config, geometry)
    together = _record(fleet.fish, GAITS, fleet.step, 0)
    alone = []
    for k in range(FISH):
        fish = VirtualFish(config, geometry, np.random.default_rng(10 + k))
        states, output = _record([fish], GAITS[k:k + 1], fish.step, 0)
        alone.append((states[:, 0], output[0]))
    return together, alone


@pytest.mark.parametrize('k', range(FISH))
def test_each_fish_of_a_fleet_follows_the_trajectory_it_follows_alone(fleet_and_alone, k):
    (states, _), alone = fleet_and_alone
    assert np.ptp(states[:, k, 4]) > 0.05  # it swam (x moved 5 cm or more)
    np.testing.assert_allclose(states[:, k], alone[k][0], rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize('k', range(FISH))
def test_each_fish_of_a_fleet_sends_the_telemetry_it_sends_alone(fleet_and_alone, k):
    (_, output), alone = fleet_and_alone
    together, by_itself = _telemetry(output[k]), _telemetry(alone[k][1])
    assert len(together) == len(by_itself) >= 0.99 * SECONDS * 100
    for a, b in zip(together, by_itself):  # its own IMU noise, servos and failsafe status
        assert a.status == b.status and a.board_time_ms == b.board_time_ms
        assert (a.servo_1, a.yaw, *a.gyro, *a.accel) == pytest.approx(
            (b.servo_1, b.yaw, *b.gyro, *b.accel), rel=1e-9, abs=1e-12)


def test_the_fish_of_a_fleet_swim_apart(fleet_and_alone):
    (states, _), _ = fleet_and_alone
    assert np.all(states[:, 0, 0] == states[:, 1, 0])  # one clock
    assert not np.allclose(states[-1, 0, 1:], states[-1, 1, 1:])


def test_stacked_servos_step_as_each_servo_alone():
    params = ServoParameters(rate_limit_rad_s=5.0)
    single = [Servo(params, (2,)) for _ in range(3)]
    targets = np.array([[0.5, -0.5], [1.0, 0.2], [-2.0, 0.0]])
    bank = Servo.stacked(single)
    for _ in range(30):
        bank.step(targets, 0.001)
        for servo, target in zip(single, targets):
            servo.step(target, 0.001)
    for i, servo in enumerate(single):
        np.testing.assert_array_equal(bank.angle[i], servo.angle)
        np.testing.assert_array_equal(bank.rate[i], servo.rate)


def test_a_fleet_needs_a_fish():
    with pytest.raises(ValueError):
        VirtualFleet([])
