# SPDX-License-Identifier: Apache-2.0
"""The virtual fish's firmware rules of protocol version 2 (no ROS, no pty, simulated time)."""

import dataclasses
import math

import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Ack, CalibrationSource, ClockSource, ErrorCode,
                                      ErrorReport, Gait, Health, Heartbeat, LinkConfig, MsgType,
                                      ResetCause, Role, ServoCommand, ServoTrim, ServoTrimReport,
                                      Status, Telemetry, TelemetryCompact, TelemetryForm, TrimOp)
from wirefish_bridge.telemetry_limits import telemetry_problem
from wirefish_cpg.oscillator import CpgIntegrator, CpgParameters, OFFSET
from wirefish_sim.servo_trim_store import FileStorage, RamStorage
from wirefish_sim.virtual_fish import Gap, ImuNoise, SimConfig, VirtualFish

TABLE_1 = Gait(1, 1.0, 0.38, 0.47, 0.0, 0.0, -0.41, 0.64, 1.76, 1.06, 20.0)
FAST = Gait(2, 2.5, 0.3, 0.5, 0.1, -0.1, -0.41, 0.64, 1.76, 1.06, 30.0)


class Host:
    """A host talking to one virtual fish, 1 ms at a time; keeps every frame the fish sent."""

    def __init__(self, **config) -> None:
        self.fish = VirtualFish(SimConfig(imu_noise=ImuNoise().scaled(0.0), **config))
        self.encoder, self.decoder = FrameEncoder(), StreamDecoder()
        self.frames: list[tuple[int, object]] = []   # (ms of emission, message)
        self.targets: list[tuple[float, float]] = []
        self.statuses: list[int] = []

    def run(self, ms: int, *messages, every_ms: dict | None = None) -> list:
        """Send ``messages`` now, then run ``ms`` milliseconds; return the frames emitted."""
        seqs = []
        data = b''
        for message in messages:
            seqs.append(self.encoder.next_seq)
            data += self.encoder.encode(message)
        start = len(self.frames)
        for k in range(ms):
            chunk = data if k == 0 else b''
            for period, message in (every_ms or {}).items():
                if k and k % period == 0:
                    chunk += self.encoder.encode(message)
            self.fish.receive(chunk)
            self.fish.step(0.001)
            now = round(self.fish.state.time_s * 1000)
            self.frames += [(now, f.message) for f in self.decoder.feed(
                b''.join(self.fish.take_output()))]
            self.targets.append(self.fish.target)
            self.statuses.append(self.fish.status)
        self.last_seqs = seqs
        return [m for _, m in self.frames[start:]]


def of(frames, kind):
    return [m for m in frames if isinstance(m, kind)]


def test_a_gait_is_acked_and_run_as_wirefish_cpg_integrates_it():
    host = Host()
    host.run(5, Heartbeat())
    out = host.run(2000, TABLE_1, every_ms={200: Heartbeat()})
    assert of(out, Ack)[0] == Ack(MsgType.GAIT, host.last_seqs[0], 0)
    telemetry = of(out, Telemetry)
    assert all(t.gait_id == 1 and t.status & Status.GAIT_MODE for t in telemetry)
    assert all(telemetry_problem(t) is None or 'servo' in telemetry_problem(t)
               for t in telemetry)
    # The same equations from rest, one RK4 step per ms from the GAIT's millisecond.
    f32 = [float(np.float32(v)) for v in TABLE_1.to_wire()[1:]]  # as the GAIT carried them
    cpg = CpgIntegrator(CpgParameters(f32[0], tuple(f32[1:3]), tuple(f32[3:5]), *f32[5:]))
    expected = []
    for k in range(2000):
        cpg.advance(k * 1e-3)
        expected.append(cpg.output(cpg.time_s)[0])
    np.testing.assert_allclose(host.targets[5:], expected, atol=1e-12)
    assert max(abs(a) for a, _ in host.targets[-1000:]) == pytest.approx(0.38, abs=0.02)


def test_a_new_gait_changes_the_tail_without_a_step():
    host = Host()
    host.run(5, Heartbeat())
    host.run(1500, TABLE_1, every_ms={200: Heartbeat()})
    host.run(1500, FAST, every_ms={200: Heartbeat()})
    steps = np.abs(np.diff(np.array(host.targets), axis=0))
    # The output's rate is at most ~ 2 pi f (R + r_overshoot): 2 pi x 2.5 x 0.6 rad/s.
    assert steps.max() < 2 * np.pi * 2.5 * 0.6 * 1e-3
    assert host.fish.gait_id == 2 and host.fish.cpg.parameters.frequency_hz == 2.5


@pytest.mark.parametrize('change', [{'gait_id': 0}, {'frequency_hz': 11.0},
                                    {'amplitude_1': 1.6}, {'offset_2': -1.6}, {'alpha': 0.0},
                                    {'w12': 100.5}, {'w21': -1e30}, {'phi12': 6.3},
                                    {'phi21': -1e30}])
def test_a_gait_out_of_range_gets_error_6_then_ack_6_and_changes_nothing(change):
    host = Host()
    host.run(5, Heartbeat())
    out = host.run(5, dataclasses.replace(TABLE_1, **change))
    seq = host.last_seqs[0]
    refusal = [m for m in out if isinstance(m, (Ack, ErrorReport))]
    assert refusal == [ErrorReport(ErrorCode.COMMAND_OUT_OF_RANGE, seq),
                       Ack(MsgType.GAIT, seq, ErrorCode.COMMAND_OUT_OF_RANGE)]
    assert host.fish.gait is None and not host.fish.status & Status.GAIT_MODE


def test_a_gait_with_couplings_beyond_the_bounds_leaves_the_running_gait_as_it_is():
    host = Host()
    host.run(5, Heartbeat())
    host.run(500, TABLE_1, every_ms={200: Heartbeat()})
    state = host.fish.cpg.state
    out = host.run(1, dataclasses.replace(FAST, w12=1e30, w21=-1e30))
    seq = host.last_seqs[0]
    assert Ack(MsgType.GAIT, seq, ErrorCode.COMMAND_OUT_OF_RANGE) in out
    assert host.fish.gait_id == 1 and host.fish.cpg.parameters.w12 == pytest.approx(-0.41)
    # One more step of the same gait: the phases went on, nothing restarted.
    assert np.abs(host.fish.cpg.state - state).max() < 2 * np.pi * 1.0 * 1e-3 * 1.1


def test_gait_mode_starts_from_the_angles_stream_mode_held():
    host = Host()
    host.run(5, Heartbeat())
    host.run(300, ServoCommand(0.3, -0.3), every_ms={100: ServoCommand(0.3, -0.3)})
    held = host.fish.target
    assert held == pytest.approx((0.3, -0.3), abs=1e-7)  # binary32 on the wire
    start = len(host.targets)
    host.run(3000, TABLE_1, every_ms={200: Heartbeat()})
    targets = np.array([held] + host.targets[start:])
    # The switch's millisecond moves nothing; then the output is the oscillator's from rest
    # but for its offsets at the angles held (phases, amplitudes and rates 0).
    assert tuple(targets[1]) == held
    f32 = [float(np.float32(v)) for v in TABLE_1.to_wire()[1:]]
    initial = np.zeros((5, 2))
    initial[OFFSET] = held
    cpg = CpgIntegrator(CpgParameters(f32[0], tuple(f32[1:3]), tuple(f32[3:5]), *f32[5:]),
                        state=initial)
    expected = []
    for k in range(3000):
        cpg.advance(k * 1e-3)
        expected.append(cpg.output(cpg.time_s)[0])
    np.testing.assert_allclose(targets[1:], expected, atol=1e-12)
    # Never more per ms than swimming itself (r 2 pi v h at 1 Hz, 3 mrad), and the offsets
    # converged to the gait's through alpha = 20 (0.3 (1 + 10 t) e^-10t: 4e-12 rad at 3 s).
    assert np.abs(np.diff(targets, axis=0)).max() < 0.47 * 2 * np.pi * 1.0 * 1e-3 * 1.3
    assert np.abs(host.fish.cpg.state[OFFSET]).max() < 1e-9
    assert max(abs(a) for a, _ in host.targets[-1000:]) == pytest.approx(0.38, abs=0.02)


def test_gait_mode_entered_during_the_failsafe_slew_goes_on_from_the_slew():
    host = Host(command_timeout_s=0.5)
    host.run(5, Heartbeat())
    host.run(700, ServoCommand(0.8, -0.8), every_ms={200: Heartbeat()})
    held = host.fish.target
    assert host.fish.status & Status.FAILSAFE_COMMAND and 0.3 < held[0] < 0.7
    start = len(host.targets)
    host.run(1000, TABLE_1, every_ms={200: Heartbeat()})
    targets = np.array([held] + host.targets[start:])
    assert tuple(targets[1]) == held
    assert np.abs(np.diff(targets, axis=0)).max() < 0.47 * 2 * np.pi * 1.0 * 1e-3 * 1.3


def test_a_servo_command_in_gait_mode_goes_back_to_stream_mode():
    host = Host()
    host.run(5, Heartbeat())
    host.run(300, TABLE_1)
    out = host.run(20, ServoCommand(0.2, -0.3))
    telemetry = of(out, Telemetry)[-1]
    assert (telemetry.gait_id, telemetry.status & Status.GAIT_MODE) == (0, 0)
    assert host.fish.target == pytest.approx((0.2, -0.3), abs=1e-7)  # binary32 on the wire


def test_a_gap_in_gait_mode_coasts_then_rests_without_a_step_and_the_gait_resumes():
    host = Host(link_timeout_s=0.3, coast_s=0.5)
    host.run(5, Heartbeat())
    host.run(1000, TABLE_1, every_ms={100: Heartbeat()})
    before = len(host.statuses)
    host.run(2000)                         # the host falls silent
    statuses = host.statuses[before:]
    gap = [s & (Status.COASTING | Status.RESTING) for s in statuses]
    # The last host frame came at 1000 ms minus one heartbeat period's remainder (900 ms).
    first_coast = gap.index(Status.COASTING)
    first_rest = gap.index(Status.RESTING)
    assert first_rest - first_coast == 500
    assert all(s & Status.GAIT_MODE for s in statuses)
    targets = np.array(host.targets[before:])
    assert np.abs(np.diff(targets, axis=0)).max() < 2 * np.pi * 1.0 * 0.5 * 1e-3
    assert np.abs(targets[-200:]).max() < 0.01      # at rest: 1.5 s of alpha = 20 after coast
    assert host.fish.gap is Gap.RESTING
    out = host.run(1500, Heartbeat(), every_ms={100: Heartbeat()})
    assert not of(out, Telemetry)[-1].status & (Status.COASTING | Status.RESTING)
    assert max(abs(a) for a, _ in host.targets[-1000:]) == pytest.approx(0.38, abs=0.02)
    assert np.abs(np.diff(np.array(host.targets[-1500:]), axis=0)).max() < 0.003


def test_stream_failsafe_slews_to_neutral_at_the_bounded_rate():
    host = Host(command_timeout_s=0.5)
    host.run(5, Heartbeat())
    host.run(100, ServoCommand(1.2, -0.8), every_ms={200: Heartbeat()})
    start = len(host.targets)
    host.run(1500, every_ms={200: Heartbeat()})
    targets = np.array(host.targets[start:])
    steps = np.abs(np.diff(targets, axis=0))
    assert steps.max() <= 2.0e-3 + 1e-12          # 2 rad/s x 1 ms
    timeout = next(i for i, s in enumerate(host.statuses[start:])
                   if s & Status.FAILSAFE_COMMAND)
    assert targets[timeout + 299, 0] == pytest.approx(1.2 - 0.6, abs=1e-6)
    assert tuple(targets[-1]) == (0.0, 0.0)       # 1.2 rad at 2 rad/s: 0.6 s, then held


def test_link_config_sets_compact_telemetry_its_period_and_health():
    host = Host()
    host.run(5, Heartbeat())
    out = host.run(1000, LinkConfig(50, TelemetryForm.COMPACT, 200, 1500, 3000),
                   every_ms={200: Heartbeat()})
    assert of(out, Ack) == [Ack(MsgType.LINK_CONFIG, host.last_seqs[0], 0)]
    assert of(out, Telemetry) == []
    compact = [(t, m) for t, m in host.frames[-len(out):] if isinstance(m, TelemetryCompact)]
    times = [t for t, _ in compact]
    assert np.all(np.diff(times) == 50) and times[0] == 6 + 50 and len(compact) == 19
    assert all(telemetry_problem(m) is None for _, m in compact)
    assert compact[-1][1].expanded().battery_v == pytest.approx(8.2, abs=1e-3)
    assert len(of(out, Health)) == 4  # at 206, 406, 606 and 806 ms


def test_link_config_out_of_range_is_acked_6_and_changes_nothing():
    host = Host()
    host.run(5, Heartbeat())
    out = host.run(100, LinkConfig(5, TelemetryForm.COMPACT, 2000, 1500, 3000))
    assert of(out, Ack) == [Ack(MsgType.LINK_CONFIG, host.last_seqs[0], 6)]
    assert of(out, ErrorReport) == [] and len(of(out, Telemetry)) == 10


def test_health_once_after_boot_then_every_period_with_the_honest_values():
    host = Host()
    host.run(4500)
    health = [(t, m) for t, m in host.frames if isinstance(m, Health)]
    assert [t for t, _ in health] == [1, 2001, 4001]
    assert health[-1][1] == Health(ResetCause.POWER_ON, ClockSource.EMULATED, 0,
                                   uptime_ms=4001)


def test_health_counts_the_decoders_drops():
    fish = VirtualFish(SimConfig())
    fish.receive(b'\x00\x05\x01\x02\x00' + b'\x00\x03\x10\x07\x01\x01\x03\x80\x3e\x01\x00')
    health = fish.health()
    assert (health.rx_frame, health.rx_crc) == (1, 1)


def test_a_host_of_another_version_ends_gait_mode_and_its_gaits_are_refused_with_5():
    host = Host()
    host.run(5, Heartbeat())
    host.run(300, TABLE_1)
    out = host.run(400, Heartbeat(version=1, role=Role.HOST))
    assert ErrorReport(ErrorCode.VERSION_MISMATCH, host.last_seqs[0]) in out
    telemetry = of(out, Telemetry)
    assert telemetry[-1].gait_id == 0 and telemetry[-1].status & Status.VERSION_MISMATCH
    steps = np.abs(np.diff(np.array(host.targets[-400:]), axis=0))
    assert steps.max() <= 2.0e-3 + 1e-12 and host.targets[-1] == (0.0, 0.0)
    out = host.run(5, FAST)
    seq = host.last_seqs[0]
    assert [m for m in out if isinstance(m, (Ack, ErrorReport))] == [
        ErrorReport(ErrorCode.VERSION_MISMATCH, seq), Ack(MsgType.GAIT, seq, 5)]


def test_acks_leave_one_per_millisecond_from_a_queue_of_four():
    host = Host()
    host.run(5, Heartbeat())
    gaits = [dataclasses.replace(TABLE_1, gait_id=i) for i in range(1, 7)]
    host.run(10, *gaits)
    acks = [(t, m) for t, m in host.frames if isinstance(m, Ack)]
    assert [m.acked_seq for _, m in acks] == host.last_seqs[:4]
    assert [t for t, _ in acks] == [6, 7, 8, 9]
    assert host.fish.acks_dropped == 2 and host.fish.gait_id == 6


def test_each_millisecond_emits_at_most_one_of_each_kind():
    host = Host()
    host.run(5, Heartbeat())
    host.run(3000, LinkConfig(10, TelemetryForm.FULL, 200, 1500, 3000), TABLE_1,
             *[dataclasses.replace(TABLE_1, gait_id=i) for i in range(2, 9)],
             every_ms={1: Heartbeat()})
    by_ms: dict = {}
    for t, m in host.frames:
        by_ms.setdefault((t, type(m)), []).append(m)
    assert max(len(ms) for (_, kind), ms in by_ms.items() if kind is not ErrorReport) == 1


# --- SERVO_TRIM: the spec's judging order, ACK then report, the reel it moves -------------
HOST = Heartbeat(role=Role.HOST)
TRIM = ServoTrim(1, TrimOp.SET, 1, 1550.0, 600.0)


def _streaming_host(**config) -> Host:
    host = Host(**config)
    host.run(20, HOST, ServoCommand(0.0, 0.0))
    return host


def test_boot_sends_both_reports_right_after_the_boot_health():
    host = Host()
    host.run(5)
    health = [t for t, m in host.frames if isinstance(m, Health)][0]
    reports = [(t, m) for t, m in host.frames if isinstance(m, ServoTrimReport)]
    assert [t for t, _ in reports] == [health, health + 1]   # one of a kind per millisecond
    reports = [m for _, m in reports]
    assert [(r.servo, r.source) for r in reports] == [(1, CalibrationSource.DEFAULTS),
                                                      (2, CalibrationSource.DEFAULTS)]
    first = reports[0]
    assert (first.neutral_us, first.min_us, first.max_us) == (1500.0, 500.0, 2500.0)


def test_an_accepted_set_is_acked_then_reported_live():
    host = _streaming_host()
    frames = host.run(5, TRIM)
    seq = host.last_seqs[0]
    ack = [i for i, m in enumerate(frames) if isinstance(m, Ack)][0]
    assert frames[ack] == Ack(MsgType.SERVO_TRIM, seq, 0)
    report = frames[ack + 1]
    assert isinstance(report, ServoTrimReport)
    assert (report.servo, report.source, report.neutral_us, report.us_per_rad) == (
        1, CalibrationSource.LIVE, 1550.0, 600.0)


def test_a_live_trim_moves_the_reel_by_the_pulse_it_gets():
    host = _streaming_host()
    host.run(300, TRIM, every_ms={20: ServoCommand(0.0, 0.0), 400: HOST})
    # 50 us of neutral on a 636.62 us/rad servo: the reel sits 0.0785 rad off; servo 2 at 0.
    assert host.fish.servos.angle[0] == pytest.approx(50.0 / 636.619772, abs=1e-5)
    assert abs(host.fish.servos.angle[1]) < 1e-9


def test_a_reversed_direction_turns_the_reel_the_other_way():
    host = _streaming_host()
    host.run(400, ServoTrim(2, TrimOp.SET, -1, 1500.0, 600.0),
             every_ms={20: ServoCommand(0.0, 0.3), 400: HOST})
    assert host.fish.servos.angle[1] == pytest.approx(-0.3 * 600.0 / 636.619772, abs=1e-5)


def test_refusals_get_ack_6_no_report_and_change_nothing():
    host = _streaming_host()
    bad = [ServoTrim(3, TrimOp.SET, 1, 1550.0, 600.0), ServoTrim(1, TrimOp.SET, 0, 1550.0, 600.0),
           ServoTrim(1, TrimOp.SET, 1, 1550.0, 636.62), ServoTrim(1, 4),
           ServoTrim(1, TrimOp.READ, reserved=1), ServoTrim(1, TrimOp.SET, 1, 1500.0, -1.0)]
    frames = []
    for trim in bad:
        frames += host.run(3, trim)
    assert [a.result for a in of(frames, Ack)] == [ErrorCode.COMMAND_OUT_OF_RANGE] * len(bad)
    assert not of(frames, ServoTrimReport)
    assert host.fish.calibration.sources == [CalibrationSource.DEFAULTS] * 2


def test_a_non_finite_trim_is_dropped_with_error_6_ref_0_and_no_ack():
    host = _streaming_host()
    frames = host.run(30, ServoTrim(1, TrimOp.SET, 1, math.nan, 600.0))
    assert ErrorReport(ErrorCode.COMMAND_OUT_OF_RANGE, 0) in frames
    assert not of(frames, Ack) and not of(frames, ServoTrimReport)


def test_in_gait_mode_a_change_is_not_now_and_a_read_is_answered():
    host = _streaming_host()
    host.run(5, TABLE_1)
    frames = host.run(5, TRIM, ServoTrim(2, TrimOp.FACTORY), ServoTrim(2, TrimOp.READ))
    assert [a.result for a in of(frames, Ack) if a.acked_type == MsgType.SERVO_TRIM] == [
        ErrorCode.NOT_NOW, ErrorCode.NOT_NOW, 0]
    assert [(r.servo, r.source) for r in of(frames, ServoTrimReport)] == [
        (2, CalibrationSource.DEFAULTS)]


def test_a_failed_storage_write_is_storage_failed_and_nothing_changes():
    storage = RamStorage()
    storage.fail = True
    fish = VirtualFish(SimConfig(imu_noise=ImuNoise().scaled(0.0)), storage=storage)
    assert fish.trim(ServoTrim(1, TrimOp.SAVE, 1, 1550.0, 600.0)) == ErrorCode.STORAGE_FAILED
    assert fish.calibration.sources[0] is CalibrationSource.DEFAULTS
    assert fish.reel_setpoint() == (0.0, 0.0)


def test_a_saved_trim_is_stored_after_a_restart_and_factory_undoes_it(tmp_path):
    path = tmp_path / 'calibration.bin'
    fish = VirtualFish(storage=FileStorage(path))
    assert fish.trim(ServoTrim(1, TrimOp.SAVE, -1, 1550.0, 600.0)) == 0
    restarted = VirtualFish(storage=FileStorage(path))
    assert restarted.calibration.report(1) == ServoTrimReport(
        1, CalibrationSource.STORED, -1, 1550.0, 600.0, 500.0, 2500.0)
    assert restarted.trim(ServoTrim(1, TrimOp.FACTORY)) == 0
    again = VirtualFish(storage=FileStorage(path))
    assert again.calibration.report(1).source is CalibrationSource.DEFAULTS


def test_a_full_ack_queue_drops_the_ack_and_its_report():
    fish = VirtualFish(SimConfig(imu_noise=ImuNoise().scaled(0.0)))
    encoder = FrameEncoder()
    fish.receive(b''.join(encoder.encode(ServoTrim(1, TrimOp.READ)) for _ in range(6)))
    assert fish.acks_dropped == 2
