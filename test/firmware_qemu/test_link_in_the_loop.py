# SPDX-License-Identifier: Apache-2.0
"""
bridge_node and the firmware's ARM build on an emulated STM32F405 (QEMU), end to end.

QEMU's netduinoplus2 machine, over the board's USART1 pseudo-terminal: the link as
PROTOCOL.md defines it.

What the board did is read from the board itself: its telemetry, and its debug console
(qemu_loop.py), which reports every compare register write (read back from the timer) and the
board time of every delimiter it received. Times of the firmware's rules are measured on the
board's clock: from the board time a frame arrived to the board time of the first telemetry
that shows the rule acted. A timeout is "no frame for more than the timeout" (the virtual
fish's rule too): at the board's 1 ms resolution it fires 1 ms after the timeout.
"""

import os
import signal
import time

from cobs import cobs
import pytest
from qemu_loop import board_time_of, Console, Tap
from wirefish_bridge.codec import encode_body, FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (ErrorCode, ErrorReport, Heartbeat, PROTOCOL_VERSION, Role,
                                      ServoCommand, Status, Telemetry)
from wirefish_bringup.graph import entry

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

# A host of a version the board does not speak.
OTHER_VERSION = PROTOCOL_VERSION + 1
# The graph's servo_cmd rate (the CPG's stream, as the registry lists it).
GRAPH_RATE_HZ = entry('cpg_node').rates_hz['servo_cmd']
# PROTOCOL.md's firmware defaults.
COMMAND_TIMEOUT_MS = 500
HEARTBEAT_TIMEOUT_MS = 1500
TELEMETRY_PERIOD_MS = 10
CLOCK_RESOLUTION_MS = 1
# The kinds of the debug console's "T" lines: the polls that took a frame of that kind.
TAKEN_HEARTBEAT, TAKEN_SERVO_CMD = 0, 1
# The graph's stream into the board: 3,000 commands, every one of them must be applied.
STREAM_S = 30.0
# The stream failsafe's way to neutral (PROTOCOL.md's failsafe_slew_rad_s default).
FAILSAFE_SLEW_RAD_S = 2.0
# The firmware answers each kind of damage with at most one ERROR per this interval.
ERROR_INTERVAL_MS = 20


def command_at(i: int) -> tuple[float, float]:
    """
    Return the i-th test command: two permutations of 97 angles in [-1.2, 1.2] rad.

    Any 97 commands in a row differ pairwise by at least 0.025 rad (16 timer ticks), so the
    bridge's rate limit, which forwards a subsequence, never sends the same value twice in a
    row: every command it sends must show as a change of both compare registers.
    """
    return (1.2 * ((i * 37) % 97 - 48) / 48.0, -1.2 * ((i * 53 + 11) % 97 - 48) / 48.0)


def _connected(probe) -> bool:
    values = probe.last_diagnostics()
    return (values.get('link_state') == 'connected'
            and values.get('fish_protocol_version') == str(PROTOCOL_VERSION))


def _telemetry(tap: Tap) -> list[Telemetry]:
    return [c.frame.message for c in tap.record.to_host if isinstance(c.frame.message, Telemetry)]


def _errors(tap: Tap) -> list[ErrorReport]:
    return [c.frame.message for c in tap.record.to_host
            if isinstance(c.frame.message, ErrorReport)]


def _servo_commands(tap: Tap, start: int = 0) -> list:
    return [c for c in tap.record.to_board[start:] if isinstance(c.frame.message, ServoCommand)
            and not c.dropped]


def _toward_neutral(value: float, before: float | None, tolerance: float) -> bool:
    """Return True when ``value`` lies between ``before`` and 0: a step of the failsafe slew."""
    if before is None:
        return abs(value) <= tolerance
    return abs(value) <= abs(before) + tolerance and (value * before >= 0 or
                                                      abs(value) <= tolerance)


def _align(wanted: list[float], seen: list[float], tolerance: float
           ) -> tuple[int, list[tuple[int, float]], int, int]:
    """
    Return how many of ``wanted`` were applied, those that were not, failsafe episodes, writes.

    The last figure is how many of ``seen`` were accounted for (commands and failsafe steps).

    Writes between two commands that are none of them and move towards neutral are the board's
    command-timeout failsafe (the emulator or the host stalled past the timeout), which slews
    to neutral at a bounded rate (PROTOCOL.md): skipped, each run of them counted once as an
    episode, and the caller holds the count against the gaps over the timeout between the
    commands' arrivals on the board. A neutral command that the slew already reached writes
    nothing: it counts as applied when the last write was neutral.
    """
    matched, missed, episodes, j = 0, [], 0, 0
    for i, angle in enumerate(wanted):
        slewing = False
        while (j < len(seen) and abs(seen[j] - angle) > tolerance
               and _toward_neutral(seen[j], seen[j - 1] if j else None, tolerance)):
            episodes += 0 if slewing else 1
            slewing = True
            j += 1
        if j < len(seen) and abs(seen[j] - angle) <= tolerance:
            matched += 1
            j += 1
        elif abs(angle) <= tolerance and j > 0 and abs(seen[j - 1]) <= tolerance:
            matched += 1   # the failsafe's slew was at neutral already
        else:
            missed.append((i, angle))
    return matched, missed, episodes, j


def _wait_board_time(tap: Tap, board_ms: int, timeout_s: float = 90.0) -> None:
    """
    Wait until the board's telemetry says its clock passed ``board_ms``.

    The emulated board's clock runs slower than the wall's on a loaded machine (QEMU misses
    SysTick periods it had no CPU for): waits are in board time.
    """
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        telemetry = _telemetry(tap)
        if telemetry and telemetry[-1].board_time_ms > board_ms:
            return
        time.sleep(0.05)
    raise AssertionError(f'the board clock did not pass {board_ms} ms within {timeout_s:g} s')


def _first_after_deadline(telemetry: list[Telemetry], arrival: int, taken: int,
                          timeout_ms: int, flag: Status) -> tuple[Telemetry, int]:
    """
    Check a timeout rule on the board's clock; return the first flagged frame and its lateness.

    The frame's delimiter arrived at board time ``arrival``; the core took it in the poll at
    ``taken`` (its "T" line: behind a backlog of received bytes that can be polls later). No
    frame before ``arrival + timeout + 1 ms`` carries ``flag``; every frame from ``taken +
    timeout + 1 ms`` on does, with both servos neutral. The lateness (ms) is how long after
    that bound the first flagged frame came, minus the gap to the frame before it beyond one
    telemetry period (a host that stopped the emulator for a while: the board's clock follows
    the wall's).
    """
    assert taken >= arrival
    after = [t for t in telemetry if t.board_time_ms > arrival]
    early = [t for t in after if t.board_time_ms < arrival + timeout_ms + CLOCK_RESOLUTION_MS]
    assert early and all(not t.status & flag for t in early)
    due = [t for t in after if t.board_time_ms >= taken + timeout_ms + CLOCK_RESOLUTION_MS]
    assert due and all(t.status & flag for t in due[:5]), due[:2]
    first = next(t for t in after if t.status & flag)
    _slews_to_neutral([t for t in after if t.board_time_ms >= first.board_time_ms])
    previous = after[after.index(first) - 1]
    stall = max(0, first.board_time_ms - previous.board_time_ms - TELEMETRY_PERIOD_MS)
    return first, first.board_time_ms - (taken + timeout_ms + CLOCK_RESOLUTION_MS) - stall


def _last_taken(console: Console, kind: int, arrival: int, timeout_s: float = 30.0) -> int:
    """Return the board time of the poll that took the last frame of ``kind`` ("T" line)."""
    deadline = time.monotonic() + timeout_s
    while not (console.taken[kind] and console.taken[kind][-1] >= arrival):
        assert time.monotonic() < deadline, (kind, arrival, console.taken[kind][-3:])
        time.sleep(0.05)
    return console.taken[kind][-1]


def _slews_to_neutral(telemetry: list[Telemetry]) -> None:
    """
    Check the failsafe's way to neutral: never a step, and there in bounded time.

    Between two frames no servo moves by more than the slew rate times their board time
    apart (a float32's rounding allowed), no servo moves away from neutral, and both are at
    neutral from |angle| / rate plus one telemetry period after the first flagged frame on.
    """
    first = telemetry[0]
    for before, now in zip(telemetry, telemetry[1:]):
        dt = (now.board_time_ms - before.board_time_ms) * 1e-3
        for a, b in ((before.servo_1, now.servo_1), (before.servo_2, now.servo_2)):
            assert abs(b - a) <= FAILSAFE_SLEW_RAD_S * dt + 1e-5 and abs(b) <= abs(a) + 1e-6, (
                before, now)
    reach_ms = max(abs(first.servo_1), abs(first.servo_2)) / FAILSAFE_SLEW_RAD_S * 1e3
    settled = [t for t in telemetry
               if t.board_time_ms >= first.board_time_ms + reach_ms + TELEMETRY_PERIOD_MS]
    assert settled and all((t.servo_1, t.servo_2) == (0.0, 0.0) for t in settled), settled[:2]


def _wait_console_caught_up(console: Console, tap: Tap, timeout_s: float = 90.0) -> None:
    deadline = time.monotonic() + timeout_s
    while len(console.zeros) < tap.zeros_forwarded and time.monotonic() < deadline:
        time.sleep(0.05)
    # Every delimiter the tap forwarded reached USART1, none more: the board times of the
    # frames below are the board's own record of their arrival.
    assert len(console.zeros) == tap.zeros_forwarded, (len(console.zeros), tap.zeros_forwarded)
    assert console.lines_dropped == 0


def test_hello_then_thirty_seconds_of_servo_cmd_every_command_applied(
        board, console, tap, start_bridge, probe, tmp_path):
    start_bridge(tap.link)
    assert probe.spin_until(lambda: _connected(probe), 30.0), probe.last_diagnostics()
    # The board took the bridge's hello: neither heartbeat failsafe nor version mismatch.
    assert probe.spin_until(lambda: any(
        not t.status & (Status.FAILSAFE_HEARTBEAT | Status.VERSION_MISMATCH)
        for t in _telemetry(tap)[-5:]), 10.0)
    assert probe.spin_until(
        lambda: f'fish says hello (protocol {PROTOCOL_VERSION})'
        in (tmp_path / 'bridge.log').read_text(), 5.0)
    start = len(tap.record.to_board)
    telemetry_start = len(tap.record.to_host)

    probe.spin_for(STREAM_S, command_at, GRAPH_RATE_HZ)
    probe.spin_for(1.5)   # the bridge's command timeout passes: it commands neutral
    _wait_console_caught_up(console, tap)

    sent = _servo_commands(tap, start)
    first = next(i for i, c in enumerate(sent) if (c.frame.message.servo_1,
                                                   c.frame.message.servo_2) != (0.0, 0.0))
    sent = sent[first:]
    since = board_time_of(console, sent[0])
    applied = 0
    expected = 0
    failsafe_writes = 0
    for channel in (0, 1):
        wanted = [(c.frame.message.servo_1, c.frame.message.servo_2)[channel] for c in sent]
        changes = [wanted[0]] + [b for a, b in zip(wanted, wanted[1:]) if b != a]
        seen = [(t, console.angle(channel, ticks)) for t, ch, ticks in console.compares
                if ch == channel and t >= since]
        tick = console.tick_rad(channel)
        matched, missed, neutrals, accounted = _align(changes, [angle for _, angle in seen],
                                                      tick + 1e-9)
        # The failsafe may act only where no command arrived for longer than the timeout, on
        # the board's clock (a host or emulator stall): one episode per such gap at most. (The
        # telemetry can miss an episode the next command ends within a telemetry period.)
        arrivals = [board_time_of(console, c) for c in sent]
        stalls = sum(1 for a, b in zip(arrivals, arrivals[1:]) if b - a > COMMAND_TIMEOUT_MS)
        assert neutrals <= stalls, (
            f'channel {channel}: {neutrals} failsafe episodes between commands, '
            f'{stalls} gaps over {COMMAND_TIMEOUT_MS} ms between their arrivals')
        assert not missed and accounted == len(seen), (
            f'channel {channel}: {len(changes)} commands, {len(seen)} compare writes, '
            f'{matched} matching; not applied (index, angle): {missed[:10]}; console '
            f'dropped {console.lines_dropped} lines, lost {console.rx_lost} bytes; board '
            f'errors {_errors(tap)[:5]}')
        applied += matched
        expected += len(changes)
        failsafe_writes += neutrals
    # The servo angles the board reports are the commands it was sent (a PWM servo reports
    # what it is commanded), or the failsafe's way to neutral, never anything else.
    commanded = {(c.frame.message.servo_1, c.frame.message.servo_2) for c in sent}
    reported = [t for t in (c.frame.message for c in tap.record.to_host[telemetry_start:])
                if isinstance(t, Telemetry)]
    assert all((t.servo_1, t.servo_2) in commanded | {(0.0, 0.0)}
               or t.status & Status.FAILSAFE_COMMAND for t in reported)
    errors = _errors(tap)
    diagnostics = probe.last_diagnostics()
    neutral = sum(1 for c in sent if (c.frame.message.servo_1, c.frame.message.servo_2)
                  == (0.0, 0.0))
    print(f'\n{STREAM_S:g} s at {GRAPH_RATE_HZ:g} Hz: {probe.published} servo_cmd published, '
          f'{len(sent) - neutral} SERVO_CMD frames sent by the bridge (then {neutral} '
          f'neutral), {applied} compare writes, each the command it follows within one '
          f'timer tick (every command on both channels, then neutral once), '
          f'{failsafe_writes} failsafe episodes between commands; '
          f'{len(reported)} telemetry frames; bridge: crc_errors {diagnostics["crc_errors"]}, '
          f'seq gaps {diagnostics["drops"]}; board side: ERROR frames {len(errors)}, '
          f'host stream crc errors {tap.host_decoder.stats.crc_errors} gaps '
          f'{tap.host_decoder.stats.seq_gaps}, board stream crc errors '
          f'{tap.board_decoder.stats.crc_errors} gaps {tap.board_decoder.stats.seq_gaps}')
    assert applied == expected
    assert diagnostics['crc_errors'] == '0' and diagnostics['drops'] == '0', diagnostics
    assert not errors
    for stats in (tap.host_decoder.stats, tap.board_decoder.stats):
        assert stats.crc_errors == 0 and stats.seq_gaps == 0 and stats.resyncs == 0, stats


def test_commands_stopped_on_the_wire_failsafe_command_and_neutral(
        board, console, tap, start_bridge, probe):
    start_bridge(tap.link)
    assert probe.spin_until(lambda: _connected(probe), 30.0), probe.last_diagnostics()
    probe.spin_for(1.0, lambda i: (0.4, -0.4), GRAPH_RATE_HZ)
    tap.drop_servo_cmd = True   # the radio loses every command; heartbeats still pass
    probe.spin_for(0.5, lambda i: (0.4, -0.4), GRAPH_RATE_HZ)
    _wait_console_caught_up(console, tap)
    last_arrival = board_time_of(console, _servo_commands(tap)[-1])
    slew_ms = 0.4 / FAILSAFE_SLEW_RAD_S * 1e3   # the failsafe's way from 0.4 rad to neutral
    while _telemetry(tap)[-1].board_time_ms <= last_arrival + COMMAND_TIMEOUT_MS + slew_ms + 100:
        probe.spin_for(0.2, lambda i: (0.4, -0.4), GRAPH_RATE_HZ)
    telemetry = _telemetry(tap)
    held = [t for t in telemetry if last_arrival < t.board_time_ms
            <= last_arrival + COMMAND_TIMEOUT_MS]
    assert held and all((t.servo_1, t.servo_2) == (pytest.approx(0.4), pytest.approx(-0.4))
                        for t in held)
    taken = _last_taken(console, TAKEN_SERVO_CMD, last_arrival)
    failsafe, late = _first_after_deadline(telemetry, last_arrival, taken, COMMAND_TIMEOUT_MS,
                                           Status.FAILSAFE_COMMAND)
    # The neutral compare itself (the slew's last steps come within a tick of it).
    neutral = [t for t, ch, ticks in console.compares if t > last_arrival
               and console.angle(ch, ticks) == pytest.approx(0.0, abs=console.tick_rad(ch) / 2)]
    latency = failsafe.board_time_ms - last_arrival
    print(f'\nlast command arrived at board time {last_arrival} ms; FAILSAFE_COMMAND in '
          f'telemetry after {latency} ms (bound: the core took the frame after '
          f'{taken - last_arrival} ms, + timeout + 1 ms + one {TELEMETRY_PERIOD_MS} ms period), '
          f'compare registers neutral after {[t - last_arrival for t in neutral]} ms')
    assert not failsafe.status & Status.FAILSAFE_HEARTBEAT
    assert len(neutral) == 2
    assert all(t - last_arrival > COMMAND_TIMEOUT_MS for t in neutral)
    assert late <= TELEMETRY_PERIOD_MS   # within the timeout and one telemetry period


def test_bridge_killed_failsafe_heartbeat_and_neutral(board, console, tap, start_bridge, probe):
    bridge = start_bridge(tap.link)
    assert probe.spin_until(lambda: _connected(probe), 30.0), probe.last_diagnostics()
    probe.spin_for(1.0, lambda i: (0.4, -0.4), GRAPH_RATE_HZ)
    os.killpg(bridge.pid, signal.SIGKILL)
    bridge.wait()
    _wait_console_caught_up(console, tap)   # the tap still reads the board
    heartbeats = [c for c in tap.record.to_board if isinstance(c.frame.message, Heartbeat)]
    last_arrival = board_time_of(console, heartbeats[-1])
    _wait_board_time(tap, last_arrival + HEARTBEAT_TIMEOUT_MS + 100)
    taken = _last_taken(console, TAKEN_HEARTBEAT, last_arrival)
    failsafe, late = _first_after_deadline(_telemetry(tap), last_arrival, taken,
                                           HEARTBEAT_TIMEOUT_MS, Status.FAILSAFE_HEARTBEAT)
    latency = failsafe.board_time_ms - last_arrival
    print(f'\nbridge killed; its last heartbeat arrived at board time {last_arrival} ms; '
          f'FAILSAFE_HEARTBEAT in telemetry after {latency} ms (bound: the core took the frame '
          f'after {taken - last_arrival} ms, + timeout + 1 ms + one {TELEMETRY_PERIOD_MS} ms '
          f'period), servos {failsafe.servo_1, failsafe.servo_2}')
    assert late <= TELEMETRY_PERIOD_MS   # within the timeout and one telemetry period


def test_a_host_of_another_version_gets_error_5_and_the_servos_stay_neutral(board, console):
    fd = os.open(board.ports.link, os.O_RDWR | os.O_NOCTTY)
    import tty
    tty.setraw(fd)
    decoder, encoder = StreamDecoder(), FrameEncoder()
    frames: list = []
    heartbeat_seqs: list[int] = []
    try:
        deadline = time.monotonic() + 5.0
        while not any(isinstance(f.message, Heartbeat) for f in frames):
            assert time.monotonic() < deadline, 'no fish heartbeat'
            frames += decoder.feed(os.read(fd, 4096))
        last_heartbeat = 0.0
        end = time.monotonic() + 1.5
        while time.monotonic() < end:
            if time.monotonic() - last_heartbeat >= 0.2:
                heartbeat_seqs.append(encoder.next_seq)
                os.write(fd, encoder.encode(Heartbeat(version=OTHER_VERSION, role=Role.HOST)))
                last_heartbeat = time.monotonic()
            os.write(fd, encoder.encode(ServoCommand(0.5, -0.5)))
            time.sleep(0.02)
            os.set_blocking(fd, False)
            try:
                frames += decoder.feed(os.read(fd, 65536))
            except BlockingIOError:
                pass
            os.set_blocking(fd, True)
        # The emulated board may run behind the wall clock: read until it answered them all.
        os.set_blocking(fd, False)
        deadline = time.monotonic() + 20.0
        while (sum(isinstance(f.message, ErrorReport) for f in frames) < len(heartbeat_seqs)
               and time.monotonic() < deadline):
            time.sleep(0.05)
            try:
                frames += decoder.feed(os.read(fd, 65536))
            except BlockingIOError:
                pass
    finally:
        os.close(fd)
    errors = [f.message for f in frames if isinstance(f.message, ErrorReport)]
    telemetry = [f.message for f in frames if isinstance(f.message, Telemetry)]
    mismatched = [t for t in telemetry if t.status & Status.VERSION_MISMATCH]
    print(f'\nversion {OTHER_VERSION} host: {len(heartbeat_seqs)} heartbeats, ERROR frames '
          f'{[(e.code, e.ref_seq) for e in errors]}, {len(mismatched)} telemetry frames with '
          f'VERSION_MISMATCH, compare writes seen {console.compares}')
    assert [e.code for e in errors] == [ErrorCode.VERSION_MISMATCH] * len(heartbeat_seqs)
    assert [e.ref_seq for e in errors] == heartbeat_seqs
    assert mismatched and all((t.servo_1, t.servo_2) == (0.0, 0.0) for t in mismatched)
    # No command moved a servo: every compare write is a neutral one. The console was read
    # before the first HEARTBEAT went out, so a write a command caused is seen; the two of
    # power-up are seen only if it attached before the board set them (its "C" and "K" lines
    # repeat every second, a "P" line is said once: beside two CPU hogs it attached later).
    neutral = {ch: round(console.calibration[ch].neutral_us * console.ticks_per_us)
               for ch in (0, 1)}
    assert all(ticks == neutral[ch] for _, ch, ticks in console.compares), console.compares


def _damaged_frames() -> list[tuple[bytes, int]]:
    """Return damaged runs, each with the ERROR code the board must answer it with."""
    body = bytearray(encode_body(ServoCommand(1.2, -1.2), 0x4242))
    body[-1] ^= 0x01   # one bit of the CRC: a frame that decodes but fails its check
    bad_crc = b'\x00' + cobs.encode(bytes(body)) + b'\x00'
    bad_cobs = b'\x00\x09\x10\x01\x00'                      # a code byte pointing past the end
    short = b'\x00' + cobs.encode(b'\x10\x01') + b'\x00'    # 2 bytes: no header and CRC
    return [(bad_crc, ErrorCode.BAD_CRC), (bad_cobs, ErrorCode.BAD_FRAME),
            (short, ErrorCode.BAD_FRAME)]


def test_corrupted_bytes_are_reported_and_no_damaged_command_is_applied(
        board, console, tap, start_bridge, probe):
    start_bridge(tap.link)
    assert probe.spin_until(lambda: _connected(probe), 30.0), probe.last_diagnostics()
    probe.spin_for(0.5, lambda i: (0.3, -0.3), GRAPH_RATE_HZ)
    damage = _damaged_frames() * 4
    ends = []
    for run, _ in damage:
        ends.append(tap.inject(run))
        probe.spin_for(0.06, lambda i: (0.3, -0.3), GRAPH_RATE_HZ)
    probe.spin_for(0.5, lambda i: (0.3, -0.3), GRAPH_RATE_HZ)
    _wait_console_caught_up(console, tap)
    arrivals = [console.zeros[end] for end in ends]
    _wait_board_time(tap, arrivals[-1] + 100)   # the last answers are out
    assert probe.spin_until(lambda: probe.last_diagnostics().get('fish_errors')
                            == str(len(_errors(tap))) and _errors(tap), 20.0), (
        probe.last_diagnostics().get('fish_errors'), _errors(tap), arrivals)
    errors = _errors(tap)
    # One ERROR per damaged frame, of its kind; the board answers each kind at most once per
    # ERROR_INTERVAL_MS, so damage of one kind that arrived closer than that may share one.
    for code in {code for _, code in damage}:
        times = [t for t, (_, c) in zip(arrivals, damage) if c == code]
        apart = 1 + sum(b - a > 2 * ERROR_INTERVAL_MS for a, b in zip(times, times[1:]))
        answered = sum(e.code == code for e in errors)
        assert apart <= answered <= len(times), (code, times, answered)
    assert {e.code for e in errors} <= {code for _, code in damage}
    angles = {round(console.angle(ch, ticks), 2) for _, ch, ticks in console.compares}
    print(f'\n{len(damage)} damaged frames injected (board arrivals {arrivals} ms); ERROR '
          f'frames {[e.code for e in errors]}; bridge fish_errors '
          f'{probe.last_diagnostics()["fish_errors"]}; compare values seen (rad) {sorted(angles)}')
    assert angles <= {0.0, 0.3, -0.3}   # never the damaged frame's +-1.2 rad
    # The bridge's commands went on being applied after the damage.
    assert any(t.board_time_ms > arrivals[-1] and (t.servo_1, t.servo_2)
               == (pytest.approx(0.3), pytest.approx(-0.3)) for t in _telemetry(tap))
