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
stream mode the slew takes the whole gap, and the schedules catch up alike.
"""

from collections.abc import Iterator
from dataclasses import dataclass, field, replace
import zlib

from firmware_host import FirmwareHost
from mpu6050_model import Mpu6050Model, sensor_from_flu, specific_force_at_rest
import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (ANGLE_LSB_RAD, Gait, Heartbeat, LinkConfig,
                                      PROTOCOL_VERSION, ProtocolMessage, quantize, Role,
                                      ServoCommand, Status, Telemetry, TelemetryCompact,
                                      TelemetryForm)
from wirefish_sim.virtual_fish import CPG_MAX_LAG_MS, ImuNoise, SimConfig, VirtualFish

TOLERANCE_RAD = 1e-4
ADC_8_2_V = 3392
ADC_6_0_V = 2482
TABLE_1 = Gait(1, 1.0, 0.38, 0.47, 0.0, 0.0, -0.41, 0.64, 1.76, 1.06, 20.0)
GAP_FLAGS = Status.COASTING | Status.RESTING


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
    fish = VirtualFish(config, rng=np.random.default_rng(1))
    mpu = Mpu6050Model()
    mpu.accel_m_s2 = sensor_from_flu(specific_force_at_rest(0.0, 0.0), (2, -1, 3))
    board.reset(i2c=mpu.transfer, adc_raw=ADC_6_0_V if scenario.low_battery else ADC_8_2_V)
    fish_frames, board_frames = StreamDecoder(), StreamDecoder()
    seen: set[str] = set()
    statuses: set[int] = set()
    worst = Deviation()
    entries: list[tuple[int, tuple[float, float]]] = []   # (ms, angles held) into gait mode
    board_held = (0.0, 0.0)
    stall_end = 0
    moves: list[tuple[int, float]] = []   # (stall, how far the targets moved over it)
    for k, chunk in enumerate(host_stream(scenario, rng)):
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
    if scenario.silent[1]:
        assert any(s & Status.SERVO_CLAMPED and s & Status.GAIT_MODE for s in statuses)
        assert {Status.COASTING, Status.RESTING} <= {s & GAP_FLAGS for s in statuses}
        assert 'TelemetryCompact' in seen
