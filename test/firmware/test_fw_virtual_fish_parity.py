# SPDX-License-Identifier: Apache-2.0
"""
One set of firmware rules: the virtual fish (wirefish_sim) and the C core must not drift.

Both get the same host byte streams, chunk by chunk, on the same millisecond clock: the
virtual fish receives a chunk at time k and steps 1 ms; the board is polled at k + 1 with the
same chunk (the virtual fish emits at the end of its step, the board at its poll). The virtual
fish is given only the chunks that hold bytes, as fish_sim gives it what its pty read: its
schedules, CPG, gap and ERROR replies run on its own clock. Required
every millisecond, for protocol version 2:

- the same output frames in the same order: every frame's type and seq; HEARTBEAT, ERROR, ACK
  and HEALTH whole; TELEMETRY's board time, status and gait id exactly and its servo angles
  within ``TOLERANCE_RAD`` of the virtual fish's targets (its own telemetry reports its
  physical servo model, so the rules' angles are its targets of the same step);
  TELEMETRY_COMPACT's the same, its servo counts within one count of those targets';
- the same status bits, gait mode, gait id and gap (coasting, resting) exactly, and the servo
  targets within ``TOLERANCE_RAD``.

The board's CPG and failsafe slew are binary32 and the virtual fish's float64
(wirefish_cpg's CpgIntegrator), so the servo angles cannot be bit-identical: 1e-4 rad is the
tolerance the CPG parity (test_fw_cpg_parity.py) holds over 60 s; everything else is exact.
The streams cover stream mode (hello, commands beyond the limit, both timeouts and the slew to
neutral, a version mismatch, low battery, damaged, split and invalid frames) and gait mode
(GAITs accepted, refused and in a burst past the ACK queue, a gait beyond the servo limit,
LINK_CONFIG with compact telemetry and its HEALTH period, a gap long enough to coast and rest,
the link back, a SERVO_CMD back to stream mode, a version mismatch in gait mode) and the
switch from stream to gait mode while stream mode holds a command, while it slews to neutral
and right after a SERVO_CMD of the same chunk: both start the oscillator with its offsets at
the angles held, so the switch's millisecond moves no servo at all; and GAITs just within and
just beyond the coupling and phase-bias bounds, accepted and refused alike; and stalls of the
firmware's poll loop (``VirtualFish.stall``; the board not polled): in gait mode the first poll
after a stall steps the CPG ``CPG_MAX_LAG_MS`` and drops the rest of the backlog on both, in
stream mode the slew takes the whole gap, and the schedules catch up alike. And the servo
calibration (SERVO_TRIM): a storage that already holds records (a tie of generations, a damaged
slot, a stored servo that does not fit), a READ before the first poll whose report puts the
two boot reports off, SET, SAVE, FACTORY and READ accepted, each refusal (6 on every field and
on the fit, 7 in gait mode, 8 with the storage failing, 5 from a host of another version), a
non-finite one dropped and a burst past the ACK queue: every millisecond both run the same
calibration from the same source, and at the end their storage holds the same bytes.
"""

from collections.abc import Iterator
from dataclasses import dataclass, field, replace
import zlib

from firmware_host import FirmwareHost
from mpu6050_model import Mpu6050Model, sensor_from_flu, specific_force_at_rest
import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Ack, ANGLE_LSB_RAD, CalibrationSource, ErrorCode, Gait,
                                      Heartbeat, LinkConfig, MsgType, PROTOCOL_VERSION,
                                      ProtocolMessage, quantize, Role, ServoCommand, ServoTrim,
                                      ServoTrimReport, Status, Telemetry, TelemetryCompact,
                                      TelemetryForm, TrimOp)
from wirefish_sim.servo_model import ServoParameters
from wirefish_sim.servo_trim_store import (RamStorage, Record, RECORD_SIZE, StoredServo,
                                           winning_record)
from wirefish_sim.virtual_fish import CPG_MAX_LAG_MS, ImuNoise, SimConfig, VirtualFish

TOLERANCE_RAD = 1e-4
ADC_8_2_V = 3392
ADC_6_0_V = 2482
TABLE_1 = Gait(1, 1.0, 0.38, 0.47, 0.0, 0.0, -0.41, 0.64, 1.76, 1.06, 20.0)
GAP_FLAGS = Status.COASTING | Status.RESTING
STORAGE_FAIL_PROGRAM = 2   # wf_host_storage_fault_t: programming returns false, nothing written


@dataclass(frozen=True)
class Scenario:
    """A host's behaviour over a run (times in ms)."""

    name: str
    duration_ms: int = 2600
    version: int = PROTOCOL_VERSION
    version_until_ms: int = 0         # announce ``version`` before this, ours after
    commands_until_ms: int = 600
    heartbeats_until_ms: int = 800
    resume_at_ms: int = 2400          # both start again here
    damage: float = 0.0               # share of chunks damaged
    low_battery: bool = False
    near_timeouts: bool = False       # gaps of 498..502 ms (commands), 1499..1502 (heartbeats)
    # Frames sent at given times (gait scenarios), and a window without any host frame.
    events: dict[int, tuple[ProtocolMessage, ...]] = field(default_factory=dict)
    silent: tuple[int, int] = (0, 0)
    command: tuple[float, float] | None = None  # every SERVO_CMD's angles (else random)
    # Stalls of the firmware's poll loop: start -> length (ms); the host is silent meanwhile.
    stalls: dict[int, int] = field(default_factory=dict)
    stored: bytes = b''               # the calibration storage's first bytes at boot
    storage_fails: tuple[int, int] = (0, 0)  # a window in which every storage write fails


GAIT_EVENTS = {
    20: (LinkConfig(20, TelemetryForm.COMPACT, 500, 300, 500),),
    25: (LinkConfig(5, TelemetryForm.COMPACT, 500, 300, 500),),       # out of range: ACK 6
    100: (TABLE_1,),
    600: (Gait(2, 2.5, 0.3, 0.5, 0.1, -0.1, -0.41, 0.64, 1.76, 1.06, 30.0),),
    800: (replace(TABLE_1, gait_id=3, amplitude_1=2.0), replace(TABLE_1, gait_id=0)),
    900: tuple(replace(TABLE_1, gait_id=i, frequency_hz=1.0 + 0.1 * i) for i in range(4, 10)),
    1000: (Gait(10, 1.5, 1.2, 1.0, 0.6, -0.6, -0.41, 0.64, 1.76, 1.06, 30.0),),  # clamps
    1150: (LinkConfig(10, TelemetryForm.FULL, 500, 300, 500),),
    2700: (LinkConfig(10, TelemetryForm.COMPACT, 0, 1500, 3000),),
    2900: (replace(TABLE_1, gait_id=11),),
    3300: (ServoCommand(0.5, -0.4),),
}
# Into gait mode from stream mode: holding (0.3, -0.3) rad (commands every 10 ms up to 290);
# part way through the failsafe's slew (commands stop at 1000, the slew starts at 1501); and
# with a SERVO_CMD just before the GAIT in one chunk (the board sets its outputs at the
# command, so gait mode starts from that command's angles). Then GAITs at the coupling and
# bias bounds (binary32 on the wire): the next binary32 beyond 100/s and 2 pi refused (ACK
# 6), 100/s and the binary32 below 2 pi accepted, by both alike.
ABOVE_2PI = float(np.float32(2 * np.pi))
BELOW_2PI = float(np.nextafter(np.float32(2 * np.pi), np.float32(0)))
HELD_EVENTS = {
    300: (TABLE_1,),
    1000: (ServoCommand(0.3, -0.2),),
    1580: (replace(TABLE_1, gait_id=2),),
    2200: (ServoCommand(0.5, -0.4), replace(TABLE_1, gait_id=3, offset_1=-0.2)),
    2600: (replace(TABLE_1, gait_id=4, w12=float(np.nextafter(np.float32(100), np.inf))),
           replace(TABLE_1, gait_id=5, phi21=-ABOVE_2PI),
           replace(TABLE_1, gait_id=6, w21=-100.0, phi12=BELOW_2PI)),
}
# The storage at boot: generation 1, then two records of generation 2 (a tie, which no writer
# makes: the later wins, servo 1 at 1530 us), then a record of generation 3 with a wrong CRC
# (skipped, but its slot is used: the next record goes after it). The winner's servo 2 has a
# negative gain (its pulses 1500 -+ 15.7 us lie within the range, yet the board refuses it):
# it boots on the defaults and stays in the record until a SAVE or FACTORY of servo 2.
_DAMAGED = bytearray(Record(3, (StoredServo(1400.0, 600.0, 1, True), StoredServo())).encode())
_DAMAGED[12] ^= 0x01
STORED_RECORDS = b''.join((
    Record(1, (StoredServo(1510.0, 600.0, 1, True), StoredServo())).encode(),
    Record(2, (StoredServo(1520.0, 600.0, -1, True),
               StoredServo(2400.0, 600.0, 1, True))).encode(),
    Record(2, (StoredServo(1530.0, 600.0, -1, True),
               StoredServo(1500.0, -10.0, 1, True))).encode(),
    bytes(_DAMAGED)))
# The widest gain that fits 1500 us within 500..2500 over +-the limit (binary32, one step
# above the build's 636.619772), and the next binary32 beyond it, which does not.
WIDEST_GAIN = np.nextafter(np.float32(636.619772), np.float32(1e4))
BEYOND_GAIN = float(np.nextafter(WIDEST_GAIN, np.float32(1e4)))
TRIM_EVENTS: dict[int, tuple] = {
    0: (ServoTrim(2, TrimOp.READ),),   # before the first poll: its report goes first
    100: (ServoTrim(1, TrimOp.SET, 1, 1550.0, 600.0),),
    120: (ServoTrim(2, TrimOp.SAVE, -1, 1480.0, 620.0),),
    # ACK 6: servo, op, reserved, direction, gain <= 0, and just beyond the fit.
    140: (ServoTrim(3, TrimOp.READ), ServoTrim(1, 4), ServoTrim(1, TrimOp.READ, reserved=1),
          ServoTrim(1, TrimOp.SET, 0, 1500.0, 600.0)),
    160: (ServoTrim(1, TrimOp.SET, 1, 1500.0, -600.0),
          ServoTrim(1, TrimOp.SAVE, 1, 1500.0, BEYOND_GAIN),
          ServoTrim(2, TrimOp.SET, -1, 1000.0, 600.0)),
    180: (ServoTrim(1, TrimOp.SET, -1, 1500.0, float(WIDEST_GAIN)),),   # just within
    # Six in one chunk against a queue of four: all applied, two ACKs (and reports) dropped.
    200: tuple(ServoTrim(2, TrimOp.SET, 1, 1490.0 + i, 600.0) for i in range(6)),
    260: (ServoTrim(2, TrimOp.READ),),
    300: (ServoTrim(2, TrimOp.FACTORY),),
    320: (ServoTrim(1, TrimOp.SAVE, -1, 1520.0, 600.0),),
    340: (ServoTrim(1, TrimOp.SET, 1, float('nan'), 600.0),),   # dropped: ERROR 6 ref 0
    362: (ServoTrim(2, TrimOp.SAVE, 1, 1505.0, 610.0), ServoTrim(1, TrimOp.FACTORY)),  # 8, 8
    400: (TABLE_1,),
    420: (ServoTrim(1, TrimOp.SET, 1, 1550.0, 600.0), ServoTrim(2, TrimOp.READ),
          ServoTrim(2, TrimOp.FACTORY), ServoTrim(1, TrimOp.SAVE, 1, 1550.0, -1.0)),  # 7 0 7 6
    500: (Heartbeat(1, Role.HOST, 500),),   # another version: ERROR 5, out of gait mode
    510: (ServoTrim(1, TrimOp.READ), ServoTrim(1, TrimOp.SET, 0, 0.0, 0.0)),   # 5 before 6
    610: (ServoTrim(1, TrimOp.READ), ServoTrim(2, TrimOp.SAVE, 1, 1505.0, 610.0)),
}
SCENARIOS = [
    Scenario('nominal'),
    Scenario('version_mismatch', version=1, version_until_ms=400),
    Scenario('damaged_stream', damage=0.25),
    Scenario('low_battery', low_battery=True, duration_ms=800),
    Scenario('gaps_at_the_timeouts', near_timeouts=True, duration_ms=6000,
             commands_until_ms=6000, heartbeats_until_ms=6000),
    # Gait mode: commands stop at 50 ms; heartbeats every 200 ms but in the silent window
    # (300 ms link timeout, 500 ms coast: it coasts from ~1600, rests from ~2100).
    Scenario('gait_mode', duration_ms=4200, commands_until_ms=50, heartbeats_until_ms=4200,
             resume_at_ms=4200, events=GAIT_EVENTS, silent=(1300, 2600)),
    Scenario('gait_mode_damaged', duration_ms=4200, commands_until_ms=50,
             heartbeats_until_ms=4200, resume_at_ms=4200, events=GAIT_EVENTS,
             silent=(1300, 2600), damage=0.1),
    Scenario('gait_version_mismatch', duration_ms=1600, commands_until_ms=50,
             heartbeats_until_ms=1600, resume_at_ms=1600, version=1,
             events={100: (TABLE_1,), 500: (Heartbeat(1, Role.HOST, 500),),
                     600: (replace(TABLE_1, gait_id=2), LinkConfig(50)), 800: (Heartbeat(),),
                     900: (replace(TABLE_1, gait_id=3),)}),
    Scenario('gait_from_held_angles', duration_ms=3000, commands_until_ms=300,
             heartbeats_until_ms=3000, resume_at_ms=3000, events=HELD_EVENTS,
             command=(0.3, -0.3)),
    # Stalls: in stream mode holding a command, then slewing to neutral; in gait mode one
    # within the CPG's bound (caught up whole), one just beyond it, the 157 ms of a QEMU
    # descheduled on a loaded host (telemetry, heartbeat and HEALTH all due at once), and one
    # past the link timeout (coasting at the first poll after it).
    Scenario('stalls', duration_ms=4400, commands_until_ms=400, heartbeats_until_ms=4400,
             resume_at_ms=4400, command=(0.3, -0.3),
             events={1000: (TABLE_1,), 1800: (replace(TABLE_1, gait_id=2, frequency_hz=2.0),)},
             stalls={300: 40, 920: 50, 1400: CPG_MAX_LAG_MS - 1, 1500: CPG_MAX_LAG_MS,
                     1601: 157, 2000: 200, 2400: 1600}),
    Scenario('servo_trim', duration_ms=700, commands_until_ms=390, heartbeats_until_ms=700,
             resume_at_ms=700, events=TRIM_EVENTS, command=(0.2, -0.1),
             stored=STORED_RECORDS, storage_fails=(360, 370)),
]


def host_stream(scenario: Scenario, rng: np.random.Generator) -> Iterator[bytes]:
    """Yield the host's bytes of each millisecond (frames split across chunks when damaged)."""
    encoder = FrameEncoder()
    carry = b''
    next_command, next_heartbeat = 50, 0
    commands = heartbeats = 0
    stalled = {t for start, length in scenario.stalls.items()
               for t in range(start, start + length)}
    for t in range(scenario.duration_ms):
        active = t >= scenario.resume_at_ms
        silent = scenario.silent[0] <= t < scenario.silent[1] or t in stalled
        chunk = bytearray(carry)
        carry = b''
        if t == next_heartbeat:
            heartbeats += 1
            next_heartbeat += 1499 + heartbeats % 4 if scenario.near_timeouts else 200
            if (t < scenario.heartbeats_until_ms or active) and not silent:
                version = scenario.version if t < scenario.version_until_ms else PROTOCOL_VERSION
                chunk += encoder.encode(Heartbeat(version, Role.HOST, t))
        if t == next_command:
            commands += 1
            next_command += 498 + commands % 5 if scenario.near_timeouts else 10
            if (t < scenario.commands_until_ms or active) and t not in stalled:
                angles = (list(scenario.command) if scenario.command is not None
                          else rng.uniform(-2.0, 2.0, 2).astype(np.float32).tolist())
                chunk += encoder.encode(ServoCommand(*angles))
        for message in scenario.events.get(t, ()):
            chunk += encoder.encode(message)
        if scenario.damage and rng.random() < scenario.damage:
            chunk, carry = damage(bytes(chunk), rng)
        yield bytes(chunk)


def damage(chunk: bytes, rng: np.random.Generator) -> tuple[bytes, bytes]:
    """Return a damaged chunk and the bytes held for the next millisecond."""
    kind = int(rng.integers(7))
    if kind == 0 and chunk:  # one bit flipped
        data = bytearray(chunk)
        data[int(rng.integers(len(data)))] ^= 1 << int(rng.integers(8))
        return bytes(data), b''
    if kind == 1:  # line noise between frames
        return chunk + rng.integers(0, 256, int(rng.integers(1, 80)), np.uint8).tobytes(), b''
    if kind == 2 and len(chunk) > 2:  # a frame split across two chunks
        cut = int(rng.integers(1, len(chunk)))
        return chunk[:cut], chunk[cut:]
    if kind == 3:  # a frame of an unknown type, with a right CRC
        return chunk + bytes.fromhex('00 02 42 03 01 01 40 1f 00'), b''
    if kind == 4:  # a SERVO_CMD with a NaN (non-finite: dropped, never applied)
        return chunk + bytes.fromhex('00 03 10 07 01 01 03 c0 7f 01 01 03 bd 6b 00'), b''
    if kind == 5:  # a GAIT with an infinite alpha, right CRC (dropped, ERROR 6 ref 0)
        return chunk + bytes.fromhex(
            '00 03 11 08 02 03 01 01 03 c0 3f 01 03 c0 3e 01 01 02 3f 01 03 80 3d 01 13 80 bd '
            '85 eb d1 be 0a d7 23 3f ae 47 e1 3f 14 ae 87 3f 01 05 80 7f 22 be 00'), b''
    return chunk + bytes.fromhex('00 03 10 07 01 01 03 80 3e 01 00'), b''  # cut short


def calibration_of(report) -> ServoTrimReport:
    """Return the board's calibration of one servo (wf_host_board_calibration) as a report."""
    return ServoTrimReport(report.servo, CalibrationSource(report.source), report.direction,
                           report.neutral_us, report.us_per_rad, report.min_us, report.max_us,
                           report.reserved)


@dataclass
class Deviation:
    """The largest servo-angle difference seen (rad), and where."""

    rad: float = 0.0
    at_ms: int = 0

    def see(self, a, b, at_ms: int) -> None:
        """Check |a - b| <= TOLERANCE_RAD element by element; keep the largest."""
        worst = float(np.max(np.abs(np.subtract(a, b, dtype=float))))
        assert worst <= TOLERANCE_RAD, f'servo angles {a} vs {b} at {at_ms} ms'
        if worst > self.rad:
            self.rad, self.at_ms = worst, at_ms


def same_frames(board: list, fish: list, target: tuple, at_ms: int, worst: Deviation) -> None:
    """Assert the board's frames of one millisecond are the virtual fish's (see module doc)."""
    assert [(f.kind, f.seq) for f in board] == [(f.kind, f.seq) for f in fish], \
        f'at {at_ms} ms: {[f.message for f in board]} vs {[f.message for f in fish]}'
    for b, f in zip(board, fish):
        bm, fm = b.message, f.message
        if isinstance(bm, Telemetry):
            assert (bm.board_time_ms, bm.status, bm.gait_id) == (
                fm.board_time_ms, fm.status, fm.gait_id), f'at {at_ms} ms'
            worst.see((bm.servo_1, bm.servo_2), target, at_ms)
        elif isinstance(bm, TelemetryCompact):
            assert (bm.board_time_ms, bm.status, bm.gait_id) == (
                fm.board_time_ms, fm.status, fm.gait_id), f'at {at_ms} ms'
            counts = [quantize(v, ANGLE_LSB_RAD) for v in target]
            assert np.max(np.abs(np.subtract((bm.servo_1, bm.servo_2), counts))) <= 1, \
                f'compact servo counts {bm.servo_1, bm.servo_2} vs {counts} at {at_ms} ms'
        else:
            assert bm == fm, f'at {at_ms} ms'


@pytest.mark.parametrize('scenario', SCENARIOS, ids=lambda s: s.name)
def test_virtual_fish_and_c_core_emit_the_same_frames_and_states(board: FirmwareHost,
                                                                 scenario: Scenario):
    rng = np.random.default_rng(zlib.crc32(scenario.name.encode()))
    config = SimConfig(imu_noise=ImuNoise().scaled(0.0),
                       battery_full_v=6.0 if scenario.low_battery else 8.2)
    storage = RamStorage()
    storage.unit[:len(scenario.stored)] = scenario.stored
    fish = VirtualFish(config, rng=np.random.default_rng(1), storage=storage)
    mpu = Mpu6050Model()
    mpu.accel_m_s2 = sensor_from_flu(specific_force_at_rest(0.0, 0.0), (2, -1, 3))
    board.reset()   # an erased storage, then the scenario's records in it
    board.poke_storage(0, scenario.stored)
    board.reset(i2c=mpu.transfer, adc_raw=ADC_6_0_V if scenario.low_battery else ADC_8_2_V,
                keep_storage=True)
    fish_frames, board_frames = StreamDecoder(), StreamDecoder()
    seen: set[str] = set()
    statuses: set[int] = set()
    worst = Deviation()
    entries: list[tuple[int, tuple[float, float]]] = []   # (ms, angles held) into gait mode
    board_held = (0.0, 0.0)
    stall_end = 0
    moves: list[tuple[int, float]] = []   # (stall, how far the targets moved over it)
    trim_acks: set[int] = set()
    reports: list[tuple[int, int]] = []   # (ms, servo) of each SERVO_TRIM_REPORT
    for k, chunk in enumerate(host_stream(scenario, rng)):
        if k in scenario.storage_fails:   # its start and end: every write fails in between
            failing = k == scenario.storage_fails[0]
            storage.fail = failing
            board.set_storage_fault(STORAGE_FAIL_PROGRAM if failing else 0)
        if k in scenario.stalls:
            fish.stall(scenario.stalls[k] * 1e-3)
            stall_end, before_stall = k + scenario.stalls[k], fish.target
        if k < stall_end:   # the board is not polled; the virtual fish's physics goes on
            assert not chunk
            fish.step(0.001)
            assert not fish.take_output(), f'at {k + 1} ms'
            continue
        held, was_gait, commands = fish.target, fish.cpg is not None, fish.commands_received
        if chunk:  # as fish_sim does: the firmware's own clock runs the rest
            fish.receive(chunk)
        commanded = fish.commands_received != commands
        if commanded:
            # A SERVO_CMD of this chunk (back to stream mode) set the outputs before the GAIT
            # that follows it (binary32 on the wire).
            held = fish.target
            board_held = tuple(float(v) for v in np.float32(held))
        fish.step(0.001)
        fish_out = fish_frames.feed(b''.join(fish.take_output()))
        board_out = board_frames.feed(board.step(k + 1, chunk))
        same_frames(board_out, fish_out, fish.target, k + 1, worst)
        seen.update(type(f.message).__name__ for f in fish_out)
        trim_acks.update(f.message.result for f in fish_out if isinstance(f.message, Ack)
                         and f.message.acked_type == MsgType.SERVO_TRIM)
        reports += [(k + 1, f.message.servo) for f in fish_out
                    if isinstance(f.message, ServoTrimReport)]
        assert [calibration_of(r) for r in board.calibration()] == [
            fish.calibration.report(servo) for servo in (1, 2)], f'at {k + 1} ms'
        state, gait = board.snapshot(), board.gait()
        assert state.status == fish.status, f'at {k + 1} ms'
        assert (gait.gait_mode, gait.gait_id, gait.gap) == (
            fish.cpg is not None, fish.gait_id, int(fish.gap)), f'at {k + 1} ms'
        worst.see(tuple(state.target), fish.target, k + 1)
        statuses.add(state.status)
        if gait.gait_mode and (commanded or not was_gait):
            # No step: the oscillator starts at the angles held, both sides exactly.
            assert fish.target == held, f'at {k + 1} ms'
            assert tuple(state.target) == board_held, f'at {k + 1} ms'
            entries.append((k + 1, held))
        board_held = tuple(state.target)
        if k == stall_end and k in {s + n for s, n in scenario.stalls.items()}:
            moves.append((k, float(np.max(np.abs(np.subtract(fish.target, before_stall))))))
    print(f'{scenario.name}: servo angles within {worst.rad:.2e} rad (at {worst.at_ms} ms)')
    if scenario.stalls:
        print(f'{scenario.name}: the targets moved over each stall: '
              + ', '.join(f'{m:.4f} rad by {k + 1} ms' for k, m in moves))
        assert len(moves) == len(scenario.stalls)
    assert board.gait().acks_dropped == fish.acks_dropped
    assert board.storage() == storage.read()   # the same record log, byte for byte
    # The boot reports: servo 1 then 2, one a millisecond from the boot HEALTH's (at 1 ms).
    boot = [(t, servo) for t, servo in reports if t <= 3]
    assert boot == ([(1, 2), (2, 1), (3, 2)] if 0 in scenario.events else [(1, 1), (2, 2)])
    if len(scenario.events.get(900, ())) == 6 and not scenario.damage:
        assert fish.acks_dropped == 2   # a burst of six GAITs against a queue of four
    assert fish_frames.stats.resyncs == board_frames.stats.resyncs == 0
    assert {'Telemetry', 'Heartbeat', 'Health'} <= seen
    if scenario.version != PROTOCOL_VERSION or scenario.damage:
        assert 'ErrorReport' in seen
    # The run went through what it is for: swimming, each timeout, the mismatch, low battery,
    # gait mode with its coast and rest, compact telemetry, ACKs.
    neutral = Status.FAILSAFE_COMMAND | Status.FAILSAFE_HEARTBEAT
    assert any(not s & neutral for s in statuses)
    if scenario.duration_ms > 2000 and not scenario.events:
        assert any(s & neutral == Status.FAILSAFE_COMMAND for s in statuses)
        assert any(s & Status.FAILSAFE_HEARTBEAT for s in statuses)
    if scenario.version != PROTOCOL_VERSION:
        assert any(s & Status.VERSION_MISMATCH for s in statuses)
    assert all(bool(s & Status.LOW_BATTERY) == scenario.low_battery for s in statuses)
    if scenario.events:
        assert 'Ack' in seen and any(s & Status.GAIT_MODE for s in statuses)
    if scenario.events is HELD_EVENTS:
        print(f'{scenario.name}: into gait mode at {entries}')
        assert [held != (0.0, 0.0) for _, held in entries] == [True] * 3
        assert fish.gait_id == 6 and board.gait().gaits_refused == 2
    if scenario.events is TRIM_EVENTS:
        print(f'{scenario.name}: SERVO_TRIM ACK results {sorted(trim_acks)}, '
              f'{len(reports)} reports, calibration in force {fish.calibration.cals}')
        assert trim_acks == {0, ErrorCode.VERSION_MISMATCH, ErrorCode.COMMAND_OUT_OF_RANGE,
                             ErrorCode.NOT_NOW, ErrorCode.STORAGE_FAILED}
        assert fish.acks_dropped == 2 and 'ErrorReport' in seen
        assert fish.calibration.sources == [CalibrationSource.STORED] * 2
        # Appended after the damaged slot: SAVE, FACTORY, SAVE, SAVE (generations 3 to 6).
        unit = storage.read()
        record, end = winning_record(unit)
        assert unit[:len(scenario.stored)] == scenario.stored
        assert record is not None and (record.generation, end) == (6, 8 * RECORD_SIZE)
    if scenario.silent[1]:
        assert any(s & Status.SERVO_CLAMPED and s & Status.GAIT_MODE for s in statuses)
        assert {Status.COASTING, Status.RESTING} <= {s & GAP_FLAGS for s in statuses}
        assert 'TelemetryCompact' in seen


def test_the_fit_is_judged_against_the_boards_frame_whatever_the_servo_models_refresh(
        board: FirmwareHost):
    # A 500 Hz servo model (a 2000 us refresh) under the build's 2500 us longest pulse: the
    # firmware's rule is the board's 20 ms frame, so both accept the SET alike.
    fish = VirtualFish(SimConfig(servo=ServoParameters(update_hz=500.0)))
    trim = ServoTrim(1, TrimOp.SET, 1, 1550.0, 600.0)
    board_out = StreamDecoder().feed(board.step(1, FrameEncoder().encode(trim)))
    assert fish.trim(trim) == 0
    assert Ack(MsgType.SERVO_TRIM, 0, 0) in [f.message for f in board_out]
    assert [calibration_of(r) for r in board.calibration()] == [
        fish.calibration.report(servo) for servo in (1, 2)]
