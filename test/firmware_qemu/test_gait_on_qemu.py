# SPDX-License-Identifier: Apache-2.0
"""
Gait mode on the emulated STM32F405 (QEMU): the telemetry angles are wirefish_cpg's oscillator.

A host written here with the codec (no ROS) talks to the board over its USART1 pty: it waits
for the fish's HEARTBEAT, sends a host HEARTBEAT of protocol 2 (and one every 0.2 s after), a
LINK_CONFIG (telemetry every 10 ms FULL, no periodic HEALTH, link timeout 10 s: a loaded machine
never makes the board coast), then a GAIT and ten GAIT changes, one every 2.5 s of board time
(frequencies up to 10 Hz, amplitudes and offsets up to the servo limit, one that clamps,
couplings up to 40 /s, every phase bias and alpha in range). Every telemetry frame is kept.

When each GAIT took effect is read from the board: its debug console writes a "G" line with
the time of the poll that accepted it (firmware/port/stm32f4/debug_console.h); the CPG had
been stepped up to that millisecond with the old targets, and the steps after it run the new
ones. The telemetry's gait_id is held to those lines (the last frame before each and the first
after bound it to one telemetry period). The console's "J" lines give every pair of polls in
gait mode more than 1 ms apart: QEMU descheduled by the host moves the board clock on by the
time it lost. The board's backlog rule (a poll steps the CPG at most WF_CPG_MAX_LAG_MS = 5 ms,
the rest of a longer gap is a pause of the gait) is mirrored in the reference: a gap of
g > 5 ms between polls moves the reference's clock on by 5 ms, not g. The test stops QEMU
itself (SIGSTOP) twice for 0.3 s so that the rule is exercised on any machine.

The reference is CpgIntegrator (float64, RK4 at 1 ms) from rest, with the same (binary32)
parameters swapped in at the same CPG steps, its angles clipped as the board clips
(clamp_to_limit at the binary32 limit 1.57079625). Every telemetry angle in gait mode must be
within one timer tick of it: 1 / (ticks_per_us * us_per_rad) = 1 / (1 * 636.62) = 1.571 mrad
with the board's calibration (the compare resolution; the board's binary32 CPG alone stays
within 1e-4 rad of the reference, test/firmware/test_fw_cpg_parity.py). The largest error is
printed in rad and in ticks (``pytest -s``).
"""

from __future__ import annotations

from collections.abc import Iterator
import math
import os
import select
import signal
import time
import tty

import numpy as np
import pytest
from qemu_loop import Console
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Ack, Gait, Heartbeat, LinkConfig, MsgType,
                                      PROTOCOL_VERSION, Role, Status, Telemetry, TelemetryForm)
from wirefish_cpg.oscillator import CpgIntegrator, CpgParameters
from wirefish_cpg.servo_limit import clamp_to_limit
from wirefish_launcher.qemu_board import QemuBoard

# Not a module that loads the machine (machine_share.py): QEMU takes ~20 % of a core, and the
# claims hold on a board the host deschedules (the backlog rule above, a link timeout of 10 s).
# It passed twice sharing one core with a busy loop (`taskset -c 1` both).

LIMIT = float(np.float32(1.57079625))   # the board's servo limit (binary32 below pi/2)
CPG_MAX_LAG_MS = 5                      # WF_CPG_MAX_LAG_MS: a poll's steps at most
CHANGES = 10
CHANGE_EVERY_MS = 2500                  # board time between two GAITs
HOST_HEARTBEAT_S = 0.2
STALL_S = 0.3                           # QEMU stopped this long, twice
LINK = LinkConfig(telemetry_period_ms=10, telemetry_form=TelemetryForm.FULL,
                  health_period_ms=0, link_timeout_ms=10000, coast_ms=3000)


def f32(value: float) -> float:
    """Return ``value`` rounded to binary32: what a GAIT frame carries."""
    return float(np.float32(value))


def gaits() -> list[Gait]:
    """
    Return the GAIT and its ten changes (binary32 values, every one in the board's ranges).

    Seeded draws over 0.3..10 Hz, amplitudes 0..1.2 rad, offsets +-0.4 rad, couplings
    +-40 /s, phase biases +-2 pi, alpha 5..200; the fourth has offset + amplitude beyond the
    limit (1.3 + 0.5 rad): the board clips it.
    """
    rng = np.random.default_rng(33)
    plan = [Gait(1, 1.0, f32(0.38), f32(0.47), 0.0, 0.0, f32(-0.41), f32(0.64), f32(1.76),
                 f32(1.06), 20.0)]
    for gait_id in range(2, CHANGES + 2):
        plan.append(Gait(gait_id, f32(rng.uniform(0.3, 10.0)), f32(rng.uniform(0.0, 1.2)),
                         f32(rng.uniform(0.0, 1.2)), f32(rng.uniform(-0.4, 0.4)),
                         f32(rng.uniform(-0.4, 0.4)), f32(rng.uniform(-40.0, 40.0)),
                         f32(rng.uniform(-40.0, 40.0)), f32(rng.uniform(-6.28, 6.28)),
                         f32(rng.uniform(-6.28, 6.28)), f32(rng.uniform(5.0, 200.0))))
    plan[3] = Gait(4, f32(2.5), f32(0.5), f32(0.3), f32(1.3), f32(-1.0), f32(3.0), f32(-2.0),
                   f32(0.5), f32(-0.5), f32(60.0))
    assert all(g.problem(LIMIT) is None for g in plan)
    return plan


def parameters(gait: Gait) -> CpgParameters:
    """Return the oscillator's parameters of ``gait``."""
    return CpgParameters(frequency_hz=gait.frequency_hz,
                         amplitude=(gait.amplitude_1, gait.amplitude_2),
                         offset=(gait.offset_1, gait.offset_2), w12=gait.w12, w21=gait.w21,
                         phi12=gait.phi12, phi21=gait.phi21, alpha=gait.alpha)


class Host:
    """The host side of the link: frames written with the codec, everything received kept."""

    def __init__(self, path: str) -> None:
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.fd)
        self.encoder = FrameEncoder()
        self.decoder = StreamDecoder()
        self.received: list = []
        self.last_heartbeat = -math.inf

    def send(self, message) -> int:
        """Write ``message`` whole; return its seq."""
        seq = self.encoder.next_seq
        data = memoryview(self.encoder.encode(message))
        while data:
            try:
                data = data[os.write(self.fd, data):]
            except BlockingIOError:
                select.select([], [self.fd], [], 0.05)
        return seq

    def pump(self, timeout_s: float = 0.005) -> None:
        """Read what the board sent; send the host heartbeat when due."""
        if time.monotonic() - self.last_heartbeat >= HOST_HEARTBEAT_S:
            self.send(Heartbeat(PROTOCOL_VERSION, Role.HOST, 0))
            self.last_heartbeat = time.monotonic()
        if select.select([self.fd], [], [], timeout_s)[0]:
            try:
                chunk = os.read(self.fd, 65536)
            except (BlockingIOError, OSError):
                return
            self.received += [f.message for f in self.decoder.feed(chunk)]

    def telemetry(self) -> list[Telemetry]:
        return [m for m in self.received if isinstance(m, Telemetry)]

    def board_ms(self) -> int:
        """Return the newest telemetry's board time (-1 before the first)."""
        for message in reversed(self.received):
            if isinstance(message, Telemetry):
                return int(message.board_time_ms)
        return -1

    def until(self, predicate, timeout_s: float = 30.0) -> None:
        deadline = time.monotonic() + timeout_s
        while not predicate():
            assert time.monotonic() < deadline, f'not seen within {timeout_s:g} s'
            self.pump()

    def close(self) -> None:
        os.close(self.fd)


@pytest.fixture
def host(board: QemuBoard, console: Console) -> Iterator[Host]:
    """Yield the host end of the board's link, after the fish identified itself."""
    assert board.ports is not None
    link = Host(board.ports.link)
    link.until(lambda: any(isinstance(m, Heartbeat) and m.role == Role.FISH
                           and m.version == PROTOCOL_VERSION for m in link.received))
    yield link
    link.close()


def stall(board: QemuBoard, seconds: float) -> None:
    """Stop the emulator for ``seconds`` (its virtual clock runs on: the board's jumps)."""
    assert board.pid is not None
    os.kill(board.pid, signal.SIGSTOP)
    try:
        time.sleep(seconds)
    finally:
        os.kill(board.pid, signal.SIGCONT)


def reference(plan: list[Gait], applied: list[int], pauses: list[tuple[int, int]],
              times: list[int]) -> dict[int, tuple[float, float]]:
    """
    Return CpgIntegrator's clipped angles at each board ms of ``times``.

    ``applied``: the board ms each gait took effect (the first: the CPG's start, at rest);
    ``pauses``: (poll ms, lost ms) of each gap between polls beyond the backlog rule's 5 ms.
    A board ms t is the reference's CPG step n(t) = t - applied[0] - the ms lost up to t.
    """
    start = applied[0]

    def step_of(t: int) -> int:
        return t - start - sum(lost for at, lost in pauses if at <= t)

    changes = {step_of(t): parameters(g) for t, g in zip(applied[1:], plan[1:])}
    wanted = {step_of(t): t for t in times}
    integrator = CpgIntegrator(parameters(plan[0]), step_s=1e-3)
    angles: dict[int, tuple[float, float]] = {}
    for n in range(0, max(wanted) + 1):
        integrator.advance(n * 1e-3)
        output, rates = integrator.output(n * 1e-3)
        if n in wanted:
            angles[wanted[n]] = clamp_to_limit(output, rates, LIMIT)[0]
        if n in changes:
            integrator.set_parameters(changes[n])
    return angles


def test_telemetry_angles_are_the_oscillator_within_one_timer_tick(board, console, host):
    plan = gaits()
    started = time.monotonic()
    config_seq = host.send(LINK)
    seqs = [host.send(plan[0])]
    host.until(lambda: console.gaits)
    first_ms = console.gaits[0][0]
    stalls_at = {first_ms + 4 * CHANGE_EVERY_MS + 700, first_ms + 8 * CHANGE_EVERY_MS + 1300}
    for k, gait in enumerate(plan[1:], start=1):
        due_ms = first_ms + k * CHANGE_EVERY_MS
        deadline = time.monotonic() + 30.0
        while host.board_ms() < due_ms:
            assert time.monotonic() < deadline, f'the board clock did not reach {due_ms} ms'
            host.pump()
            if stalls_at and host.board_ms() >= min(stalls_at):
                stalls_at.remove(min(stalls_at))
                stall(board, STALL_S)
        seqs.append(host.send(gait))
    end_ms = first_ms + (CHANGES + 1) * CHANGE_EVERY_MS
    host.until(lambda: host.board_ms() >= end_ms)
    wall_s = time.monotonic() - started
    # The console's lines of a poll are written after its telemetry: let them all arrive.
    host.until(lambda: len(console.gaits) == len(plan), 5.0)
    deadline = time.monotonic() + 0.5
    while time.monotonic() < deadline:
        host.pump()

    acks = [m for m in host.received if isinstance(m, Ack)]
    assert [(a.acked_type, a.acked_seq, a.result) for a in acks] == [
        (MsgType.LINK_CONFIG, config_seq, 0)] + [(MsgType.GAIT, s, 0) for s in seqs]
    assert [(gait_id, accepted) for _, gait_id, accepted in console.gaits] == [
        (g.gait_id, i) for i, g in enumerate(plan, start=1)]
    applied = [ms for ms, _, _ in console.gaits]
    telemetry = [t for t in host.telemetry() if t.board_time_ms <= end_ms]
    swimming = [t for t in telemetry if t.board_time_ms >= applied[0]]
    # Before the first GAIT: stream mode; after: gait mode on the gait the console named, no
    # coasting (the host's heartbeats), every frame in gait mode.
    assert all(t.gait_id == 0 and not t.status & Status.GAIT_MODE
               for t in telemetry if t.board_time_ms < applied[0])
    # Several polls may share a millisecond (a received byte wakes the loop too): a frame of
    # the very ms a gait took effect may have left in an earlier poll, with the old gait_id.
    for t in swimming:
        current = max(i for i, ms in enumerate(applied) if ms <= t.board_time_ms)
        named = {plan[current].gait_id} | (
            {plan[current - 1].gait_id} if current and applied[current] == t.board_time_ms
            else set())
        assert t.gait_id in named, (t.board_time_ms, t.gait_id, applied)
        assert t.status & Status.GAIT_MODE
        assert not t.status & (Status.COASTING | Status.RESTING), t
    # The telemetry's own bound on each change: the last frame of the old gait_id and the
    # first of the new, at most a telemetry period apart but for a stall between them.
    windows = []
    for ms, gait in zip(applied[1:], plan[1:]):
        before = max(t.board_time_ms for t in swimming if t.gait_id != gait.gait_id
                     and t.board_time_ms <= ms)
        after = min(t.board_time_ms for t in swimming if t.gait_id == gait.gait_id)
        assert before <= ms <= after
        windows.append(after - before)

    gaps = [(a, b) for a, b in console.jumps if a >= applied[0]]
    pauses = [(b, b - a - CPG_MAX_LAG_MS) for a, b in gaps if b - a > CPG_MAX_LAG_MS]
    times = [t.board_time_ms for t in swimming]
    expected = reference(plan, applied, pauses, times)
    errors = np.array([[abs(t.servo_1 - expected[t.board_time_ms][0]),
                        abs(t.servo_2 - expected[t.board_time_ms][1])] for t in swimming])
    ticks = np.array([console.tick_rad(0), console.tick_rad(1)])
    worst = errors.max(axis=0)
    clipped = sum(1 for t in swimming if t.status & Status.SERVO_CLAMPED)
    # Without the backlog rule (the board clock's jumps integrated in full) the reference
    # parts from the board after the first pause: the rule is what the telemetry shows.
    unpaused = reference(plan, applied, [], times)
    unpaused_worst = max(max(abs(t.servo_1 - unpaused[t.board_time_ms][0]),
                             abs(t.servo_2 - unpaused[t.board_time_ms][1])) for t in swimming)
    print(f'\n{len(plan)} GAITs over {(end_ms - applied[0]) / 1e3:.1f} s of board time '
          f'({wall_s:.1f} s wall), {len(swimming)} telemetry frames in gait mode '
          f'({clipped} clipped at the limit); each change within a '
          f'{max(windows)} ms telemetry window of its "G" line; polls > 1 ms apart: '
          f'{len(gaps)} (largest {max((b - a for a, b in gaps), default=0)} ms), pauses of '
          f'the backlog rule: {len(pauses)}, {sum(lost for _, lost in pauses)} ms in all; '
          f'max |telemetry - CpgIntegrator| servo_1 {worst[0]:.3g} rad '
          f'({worst[0] / ticks[0]:.3f} tick), servo_2 {worst[1]:.3g} rad '
          f'({worst[1] / ticks[1]:.3f} tick), one tick {ticks[0]:.4g} rad; without the '
          f'pauses in the reference: {unpaused_worst:.3g} rad')
    assert len(pauses) >= 2   # at least the two stalls made here
    assert np.all(worst <= ticks), (worst, ticks)
    assert unpaused_worst > ticks.max()
