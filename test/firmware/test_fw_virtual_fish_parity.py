"""
One set of firmware rules: the virtual fish (wirefish_sim) and the C core must not drift.

Both get the same host byte streams, chunk by chunk, on the same millisecond clock: the
virtual fish receives a chunk at time k and steps 1 ms; the board is polled at k + 1 with the
same chunk (the virtual fish emits at the end of its step, the board at its poll). Required
identical, every millisecond: every output frame's type and seq, every HEARTBEAT and ERROR
frame whole, every TELEMETRY's board time, status and servo angles (the virtual fish's
commanded targets after the clamp; its own telemetry reports its physical servo model), and
the status and servo targets of both. The streams cover hello, commands beyond the limit,
both timeouts, a version mismatch, low battery, and damaged, split and invalid frames.
"""

from collections.abc import Iterator
from dataclasses import dataclass
import zlib

from firmware_host import FirmwareHost
from mpu6050_model import Mpu6050Model, sensor_from_flu, specific_force_at_rest
import numpy as np
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Heartbeat, ProtocolMessage, Role, ServoCommand, Status,
                                      Telemetry)
from wirefish_sim.virtual_fish import ImuNoise, SimConfig, VirtualFish

LIMIT = np.float32(1.57079625)  # the board's limit: the binary32 just below the fish's pi/2
ADC_8_2_V = 3392
ADC_6_0_V = 2482


@dataclass(frozen=True)
class Scenario:
    """A host's behaviour over a run (times in ms)."""

    name: str
    duration_ms: int = 2600
    version: int = 1
    version_until_ms: int = 0         # announce ``version`` before this, 1 after
    commands_until_ms: int = 600
    heartbeats_until_ms: int = 800
    resume_at_ms: int = 2400          # both start again here
    damage: float = 0.0               # share of chunks damaged
    low_battery: bool = False
    near_timeouts: bool = False       # gaps of 498..502 ms (commands), 1499..1502 (heartbeats)


SCENARIOS = [
    Scenario('nominal'),
    Scenario('version_mismatch', version=2, version_until_ms=400),
    Scenario('damaged_stream', damage=0.25),
    Scenario('low_battery', low_battery=True, duration_ms=800),
    Scenario('gaps_at_the_timeouts', near_timeouts=True, duration_ms=6000,
             commands_until_ms=6000, heartbeats_until_ms=6000),
]


def host_stream(scenario: Scenario, rng: np.random.Generator) -> Iterator[bytes]:
    """Yield the host's bytes of each millisecond (frames split across chunks when damaged)."""
    encoder = FrameEncoder()
    carry = b''
    next_command, next_heartbeat = 50, 0
    commands = heartbeats = 0
    for t in range(scenario.duration_ms):
        active = t >= scenario.resume_at_ms
        chunk = bytearray(carry)
        carry = b''
        if t == next_heartbeat:
            heartbeats += 1
            next_heartbeat += 1499 + heartbeats % 4 if scenario.near_timeouts else 200
            if t < scenario.heartbeats_until_ms or active:
                version = scenario.version if t < scenario.version_until_ms else 1
                chunk += encoder.encode(Heartbeat(version, Role.HOST, t))
        if t == next_command:
            commands += 1
            next_command += 498 + commands % 5 if scenario.near_timeouts else 10
            if t < scenario.commands_until_ms or active:
                angles = rng.uniform(-2.0, 2.0, 2).astype(np.float32).tolist()
                chunk += encoder.encode(ServoCommand(*angles))
        if scenario.damage and rng.random() < scenario.damage:
            chunk, carry = damage(bytes(chunk), rng)
        yield bytes(chunk)


def damage(chunk: bytes, rng: np.random.Generator) -> tuple[bytes, bytes]:
    """Return a damaged chunk and the bytes held for the next millisecond."""
    kind = int(rng.integers(6))
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
    return chunk + bytes.fromhex('00 03 10 07 01 01 03 80 3e 01 00'), b''  # cut short


def firmware_view(message: ProtocolMessage) -> tuple:
    """Return what the firmware rules decide in an output message."""
    if isinstance(message, Telemetry):
        return ('telemetry', message.board_time_ms, message.status,
                np.float32(message.servo_1), np.float32(message.servo_2))
    return (type(message).__name__, message)


def clamped(target: tuple[float, float]) -> tuple[np.float32, np.float32]:
    """Return the virtual fish's targets as the board's binary32 after the clamp."""
    a, b = (np.clip(np.float32(v), -LIMIT, LIMIT) for v in target)
    return np.float32(a), np.float32(b)


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
    for k, chunk in enumerate(host_stream(scenario, rng)):
        fish.receive(chunk)
        fish.step(0.001)
        fish_out = fish_frames.feed(b''.join(fish.take_output()))
        board_out = board_frames.feed(board.step(k + 1, chunk))
        state = board.snapshot()
        target = clamped(fish.target)
        fish_view = []
        for f in fish_out:
            view = firmware_view(f.message)
            if view[0] == 'telemetry':
                # The virtual fish's telemetry reports its servo model; the rules' angles are
                # its targets of the same step.
                view = view[:3] + target
            fish_view.append((f.kind, f.seq, view))
            seen.add(type(f.message).__name__)
        assert [(f.kind, f.seq, firmware_view(f.message)) for f in board_out] == fish_view, \
            f'at {k + 1} ms'
        assert (state.status, tuple(state.target)) == (fish.status, target), f'at {k + 1} ms'
        statuses.add(state.status)
    assert fish_frames.stats.resyncs == board_frames.stats.resyncs == 0
    assert {'Telemetry', 'Heartbeat'} <= seen
    if scenario.version != 1 or scenario.damage:
        assert 'ErrorReport' in seen
    # The run went through what it is for: swimming, each timeout, the mismatch, low battery.
    neutral = Status.FAILSAFE_COMMAND | Status.FAILSAFE_HEARTBEAT
    assert any(not s & neutral for s in statuses)
    if scenario.duration_ms > 2000:
        assert any(s & neutral == Status.FAILSAFE_COMMAND for s in statuses)
        assert any(s & Status.FAILSAFE_HEARTBEAT for s in statuses)
    if scenario.version != 1:
        assert any(s & Status.VERSION_MISMATCH for s in statuses)
    assert all(bool(s & Status.LOW_BATTERY) == scenario.low_battery for s in statuses)
