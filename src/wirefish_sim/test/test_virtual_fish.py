# SPDX-License-Identifier: Apache-2.0
"""The virtual fish's physics and firmware, faster than real time (no ROS, no pty)."""

import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Status, Telemetry
from wirefish_cpg.steady_state import steady_state_servo_angles
from wirefish_cpg.table1_gait import locked_speed_estimate, one_locked_period, table1_locked_at
from wirefish_kinematics.body_wave import lateral_slope
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import (lateral_added_mass_per_length, reactive_state,
                                           tail_tip_velocity_and_slope)
from wirefish_kinematics.wire_coupling import bend_angles
from wirefish_sim.fish_dynamics import surge_time_constant
from wirefish_sim.servo_model import Servo, ServoParameters
from wirefish_sim.virtual_fish import SimConfig, VirtualFish

# Servos that follow each 1 ms command within the step (no slew limit, no lag, 1 kHz PWM).
IDEAL_SERVO = ServoParameters(rate_limit_rad_s=1e6, time_constant_s=1e-6, update_hz=1000.0)
STEP_S = 1e-3


def _drive(fish, frequency_hz, seconds, start_s=0.0):
    """Command Table 1 locked at f every 1 ms for ``seconds``; return the speeds (T,)."""
    times = start_s + (np.arange(round(seconds / STEP_S)) + 1) * STEP_S
    commands, _ = steady_state_servo_angles(table1_locked_at(frequency_hz), times)
    speeds = []
    for servo_1, servo_2 in commands.tolist():
        fish.command(servo_1, servo_2)
        fish.step(STEP_S)
        speeds.append(fish.state.speed)
    return np.array(speeds)


def _ideal_fish():
    config = SimConfig(command_timeout_s=None, heartbeat_timeout_s=None, servo=IDEAL_SERVO)
    return VirtualFish(config, FishGeometry())


@pytest.mark.parametrize('frequency_hz', [1.0, 3.0])
def test_mean_speed_with_ideal_servos_is_within_1_percent_of_eq_18(frequency_hz):
    fish = _ideal_fish()
    settle = 1.5  # > 7 time constants at 1 Hz (0.2 s) and 3 Hz (0.07 s)
    _drive(fish, frequency_hz, settle)
    beat = _drive(fish, frequency_hz, 1.0 / frequency_hz, settle)  # one whole period
    eq18 = locked_speed_estimate(table1_locked_at(frequency_hz), FishGeometry()).speed
    print(f'{frequency_hz} Hz: mean {beat.mean():.4f} m/s, eq 18 {eq18:.4f} m/s, ripple '
          f'{np.ptp(beat):.4f} m/s peak to peak')
    assert beat.mean() == pytest.approx(eq18, rel=0.01)


def test_speed_ripple_is_at_twice_the_tail_beat_frequency():
    fish = _ideal_fish()
    _drive(fish, 2.0, 1.5)
    speeds = _drive(fish, 2.0, 2.0, 1.5)  # four whole beats
    spectrum = np.abs(np.fft.rfft(speeds - speeds.mean()))
    frequencies = np.fft.rfftfreq(speeds.size, STEP_S)
    assert frequencies[np.argmax(spectrum)] == pytest.approx(4.0)


def test_time_constant_follows_from_the_inertia_and_the_damping():
    # Two fish with the same tail motion, one pushed 2 % faster (small: linear regime): the
    # ripple is common to both, so their speed difference shows the surge time constant.
    reference, pushed = _ideal_fish(), _ideal_fish()
    _drive(reference, 3.0, 1.5)
    _drive(pushed, 3.0, 1.5)
    pushed.state.speed *= 1.02
    kick = pushed.state.speed - reference.state.speed
    difference = _drive(pushed, 3.0, 0.5, 1.5) - _drive(reference, 3.0, 0.5, 1.5)
    measured = STEP_S * (1 + int(np.argmax(difference <= kick / np.e)))
    g = FishGeometry()
    angles, rates, _ = one_locked_period(table1_locked_at(3.0))
    _, slope, _, k2 = reactive_state(angles, rates, g)
    mean_speed = locked_speed_estimate(table1_locked_at(3.0), g).speed
    expected = surge_time_constant(reference.total_mass, float(np.mean(k2)), mean_speed,
                                   float(np.mean(slope ** 2)), g.drag_coefficient,
                                   g.water_density, g.wetted_area, g.tip_cross_section_area)
    print(f'time constant: measured {measured:.4f} s, linearised {expected:.4f} s')
    assert measured == pytest.approx(expected, rel=0.2)


def test_reactive_state_tip_values_are_eqs_19_to_22():
    angles, rates, _ = one_locked_period(table1_locked_at(3.0), 64)
    velocity, slope, _, _ = reactive_state(angles, rates, FishGeometry())
    expected = tail_tip_velocity_and_slope(angles, rates, FishGeometry())
    np.testing.assert_allclose(velocity, expected[0], rtol=1e-12)
    np.testing.assert_allclose(slope, expected[1], rtol=1e-12)


def test_reactive_momentum_quadrature_matches_a_fine_trapezoid():
    g = FishGeometry()
    angles, rates, _ = one_locked_period(table1_locked_at(3.0), 16)
    _, _, _, k2 = reactive_state(angles, rates, g)
    q = np.linspace(0.0, g.tail_length, 20001)
    beta1, beta2 = bend_angles(angles[:, 0], angles[:, 1], g)
    fine = lateral_added_mass_per_length(g) * np.trapezoid(
        lateral_slope(q, beta1, beta2, g) ** 2, q, axis=-1)
    np.testing.assert_allclose(k2, fine, rtol=1e-5)


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
