"""The virtual fish's physics and firmware, faster than real time (no ROS, no pty)."""

import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Status, Telemetry
from wirefish_kinematics.geometry import FishGeometry
from wirefish_sim.fish_dynamics import force_scale_for_time_constant
from wirefish_sim.servo_model import Servo, ServoParameters
from wirefish_sim.virtual_fish import SimConfig, VirtualFish


def test_force_scale_gives_tau_from_the_linearised_drag():
    g = FishGeometry()
    s = force_scale_for_time_constant(3.57, 0.75, 0.39, 0.05, g.drag_coefficient,
                                      g.water_density, g.wetted_area)
    assert 3.57 / (s * g.drag_coefficient * g.water_density * g.wetted_area * 0.39) == \
        pytest.approx(0.75)


def test_servo_slews_at_its_rate_limit():
    servo = Servo(ServoParameters(rate_limit_rad_s=12.0))
    for _ in range(10):
        servo.step(1.0, 0.001)
    assert servo.motor == pytest.approx(12.0 * 0.010)


def test_servo_stops_at_the_mechanical_limit():
    servo = Servo(ServoParameters(limit_rad=0.5))
    for _ in range(1000):
        servo.step(2.0, 0.001)
    assert servo.angle == pytest.approx(0.5, abs=1e-6)


def _telemetry(fish):
    return [f.message for f in StreamDecoder().feed(b''.join(fish.take_output()))
            if isinstance(f.message, Telemetry)]


def test_telemetry_is_emitted_at_100_hz_of_simulated_time():
    fish = VirtualFish(SimConfig(), FishGeometry())
    for _ in range(100):
        fish.step(0.01)
    assert len(_telemetry(fish)) == 100


def test_firmware_follows_commands_then_goes_neutral_after_its_timeout():
    fish = VirtualFish(SimConfig(command_timeout_s=0.3, heartbeat_timeout_s=None),
                       FishGeometry())
    encoder = FrameEncoder()
    for _ in range(50):
        fish.receive(encoder.encode(ServoCommand(0.3, -0.2)))
        fish.step(0.01)
    last = _telemetry(fish)[-1]
    assert (last.servo_1, last.servo_2) == pytest.approx((0.3, -0.2), abs=1e-3)
    for _ in range(60):
        fish.step(0.01)
    last = _telemetry(fish)[-1]
    assert last.status & Status.FAILSAFE_COMMAND
    assert (last.servo_1, last.servo_2) == pytest.approx((0.0, 0.0), abs=1e-3)


def test_firmware_goes_neutral_without_host_heartbeats():
    fish = VirtualFish(SimConfig(command_timeout_s=None, heartbeat_timeout_s=0.5),
                       FishGeometry())
    fish.receive(FrameEncoder().encode(Heartbeat()))
    fish.command(0.3, 0.3)
    for _ in range(100):
        fish.step(0.01)
    last = _telemetry(fish)[-1]
    assert last.status & Status.FAILSAFE_HEARTBEAT and abs(last.servo_1) < 1e-3


def test_imu_noise_is_reproducible_with_a_seed():
    def first(seed):
        fish = VirtualFish(SimConfig(), FishGeometry(), np.random.default_rng(seed))
        fish.step(0.01)
        return _telemetry(fish)[0]
    assert first(3) == first(3) and first(3) != first(4)


@pytest.mark.parametrize('offset, sign', [(0.2, -1.0), (-0.2, 1.0)])
def test_tail_held_to_one_side_turns_the_fish_that_way(offset, sign):
    # A positive bend is to the right (+y of C0); turning right is a negative yaw about z up.
    fish = VirtualFish(SimConfig(command_timeout_s=None, heartbeat_timeout_s=None),
                       FishGeometry())
    fish.state.speed = 0.3
    dt, rates = 0.005, []
    for i in range(400):
        beat = 0.3 * np.sin(2 * np.pi * 2.0 * i * dt)
        fish.command(offset + beat, offset + beat)
        fish.step(dt)
        rates.append(fish.state.yaw_rate)
    assert sign * np.mean(rates[200:]) > 0.1   # mean over the last second (whole beats)
