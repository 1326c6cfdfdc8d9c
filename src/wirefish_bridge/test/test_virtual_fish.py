"""The virtual fish's physics and firmware, faster than real time (no ROS, no pty)."""

import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.fig11 import peak_frequency, run_steady, speed_sweep
from wirefish_bridge.fish_dynamics import force_scale_for_time_constant
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Status, Telemetry
from wirefish_bridge.servo_model import Servo, ServoParameters
from wirefish_bridge.virtual_fish import SimConfig, VirtualFish
from wirefish_cpg.steady_state import steady_state_servo_angles
from wirefish_cpg.table1_gait import table1_locked_at
from wirefish_kinematics.geometry import FishGeometry


def test_table_1_gait_at_3_hz_swims_within_10_percent_of_eq_18():
    run = run_steady(table1_locked_at(3.0), 3.0, FishGeometry())
    print(f'3 Hz: virtual fish {run.speed:.4f} m/s, eq 18 {run.ideal_speed:.4f} m/s '
          f'({100 * (run.speed / run.ideal_speed - 1):+.1f} %)')
    assert run.speed == pytest.approx(run.ideal_speed, rel=0.10)


@pytest.mark.parametrize('tau', [0.5, 1.0])
def test_speed_time_constant_is_the_configured_one(tau):
    config = SimConfig(command_timeout_s=None, heartbeat_timeout_s=None,
                       speed_time_constant_s=tau)
    final = run_steady(table1_locked_at(3.0), 3.0, FishGeometry(), config).speed
    fish = VirtualFish(config, FishGeometry())
    dt, warm_up = 0.005, 200   # 1 s for the servos to reach their steady oscillation
    commands, _ = steady_state_servo_angles(table1_locked_at(3.0),
                                            np.arange(warm_up + int(3 * tau / dt)) * dt)
    speeds = []
    for i, (servo_1, servo_2) in enumerate(commands.tolist()):
        if i == warm_up:
            fish.state.speed = 0.8 * final   # a small step below the steady speed
        fish.command(servo_1, servo_2)
        fish.step(dt)
        if i >= warm_up:
            speeds.append(fish.state.speed)
    # The error to the steady speed falls to 1/e after about one time constant.
    t_e = dt * next(i for i, u in enumerate(speeds) if final - u <= 0.2 * final / np.e)
    print(f'tau {tau} s: error at 1/e after {t_e:.3f} s')
    assert 0.6 * tau < t_e < 1.4 * tau  # nonlinear drag: ~0.7-0.85 tau measured


def test_force_scale_gives_tau_from_the_linearised_drag():
    g = FishGeometry()
    s = force_scale_for_time_constant(3.57, 0.75, 0.39, 0.05, g.drag_coefficient,
                                      g.water_density, g.wetted_area)
    assert 3.57 / (s * g.drag_coefficient * g.water_density * g.wetted_area * 0.39) == \
        pytest.approx(0.75)


def test_speed_rises_then_falls_where_the_servo_cannot_follow(fig11_runs):
    speeds = [r.speed for r in fig11_runs]
    peak = int(np.argmax(speeds))
    assert fig11_runs[0].tail_tip_amplitude == pytest.approx(0.05, rel=0.02)
    assert all(b > a for a, b in zip(speeds[:peak], speeds[1:peak + 1]))
    assert all(b < a for a, b in zip(speeds[peak:], speeds[peak + 1:]))
    assert peak < len(speeds) - 2  # falls for at least two steps (1 Hz) before 8 Hz


def test_speed_peaks_between_5_and_7_5_hz_as_in_fig_11(fig11_runs):
    assert 5.0 <= peak_frequency(fig11_runs) <= 7.5


def test_tail_amplitude_falls_faster_above_5_hz(fig11_runs):
    amplitude = {r.frequency_hz: r.tail_tip_amplitude for r in fig11_runs}
    below = (amplitude[1.0] - amplitude[5.0]) / 4.0  # m per Hz
    above = (amplitude[5.0] - amplitude[8.0]) / 3.0
    print(f'tail amplitude loss: {100 * below:.2f} cm/Hz below 5 Hz, '
          f'{100 * above:.2f} cm/Hz above')
    assert above > 1.5 * below


def test_a_slower_servo_peaks_at_a_lower_frequency():
    frequencies = np.arange(4.0, 10.01, 1.0)

    def peak_hz(rate_limit: float) -> float:
        config = SimConfig(command_timeout_s=None, heartbeat_timeout_s=None,
                           servo=ServoParameters(rate_limit_rad_s=rate_limit))
        return peak_frequency(speed_sweep(frequencies, config=config))

    assert peak_hz(8.0) < peak_hz(12.0)


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
