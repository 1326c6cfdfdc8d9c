# SPDX-License-Identifier: Apache-2.0
"""
radio_relay: a serial radio (``radio_model``) between the bridge and a fish's pseudo-terminal.

``radio_relay --preset rf433 --device /tmp/wirefish-tty-fish --link /tmp/wirefish-tty`` opens a
pty pair for the bridge, prints its device path on stdout (one line, flushed; the symlink
``--link`` points at it, with an owner record, as the virtual fish's), opens ``--device``
(the virtual fish's link or the emulated board's USART1 pty: any serial device) and carries
the bytes of each side to the other through the link model, on the wall clock
(``time.monotonic``): a byte takes its air time, waits for a half-duplex channel, arrives
late with jitter, or never. A device that goes away (a virtual fish reopening its pty, a
restarted QEMU) is reopened every ``REOPEN_S`` while the relay runs on.

Cuts: ``--cut AT:FOR`` (s after start, repeatable), or a file written at ``--control``
PATH holding lines ``cut SECONDS`` (the relay reads it once its last line is complete,
removes it and cuts from now), lose everything on the air for that long. Each cut is printed
on stderr with its monotonic start and end (``radio_relay: cut 1234.500 .. 1244.500``), the
clock every process of the machine shares. ``--stats PATH`` writes the counters as JSON every
``--stats-every`` s and at the stop (``RadioStats``: link use per direction, losses,
turn-arounds).

Runs until SIGINT/SIGTERM (exit 0). The loop wakes when a side has bytes or the model has an
event due, and at least every ``MAX_WAIT_S``.
"""

from __future__ import annotations

import argparse
from dataclasses import asdict
import errno
import fcntl
import json
import math
import os
from pathlib import Path
import random
import select
import struct
import sys
import time
import tty
from typing import NoReturn

from wirefish_bridge.link_owner import open_refusal
from wirefish_common.shutdown import begin_teardown, exit_now, SignalShutdown
from wirefish_sim.pty_device import PtyDevice
from wirefish_sim.radio_model import Direction, preset, PRESETS, RadioLink, RadioStats

REOPEN_S = 0.2          # retry period of an absent device
MAX_WAIT_S = 0.02       # longest sleep of the loop (s): bounds the lateness of a stop
LATE_S = 0.0005         # an event due within this is handled now
# Bytes kept for a side that does not read (no bridge on the pty, a stalled board); beyond
# this the oldest go, as a module's buffer overflows.
MAX_PENDING = 65536
# One record of --tap: the monotonic time the bytes were read (s, float64), their count (u32),
# then the bytes (little-endian).
TAP_RECORD = struct.Struct('<dI')


def read_tap(path: Path) -> list[tuple[float, bytes]]:
    """Return the (time, bytes) records of a ``--tap`` file."""
    data = path.read_bytes()
    records = []
    offset = 0
    while offset + TAP_RECORD.size <= len(data):
        t, size = TAP_RECORD.unpack_from(data, offset)
        offset += TAP_RECORD.size
        records.append((t, data[offset:offset + size]))
        offset += size
    return records


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of ``radio_relay``."""
    p = argparse.ArgumentParser(prog='radio_relay', description=__doc__.split('\n\n')[0])
    p.add_argument('--preset', choices=list(PRESETS), required=True,
                   help='the radio: ' + ', '.join(PRESETS) + ' (docs/REFERENCE.md)')
    p.add_argument('--device', type=Path, required=True,
                   help="the fish's serial device (the virtual fish's or the board's link)")
    p.add_argument('--link', type=Path, required=True,
                   help="symlink to point at the relay's pty: the bridge's port")
    p.add_argument('--seed', type=int, default=0, help='seed of the radio (loss, jitter)')
    p.add_argument('--cut', action='append', default=[], metavar='AT:FOR',
                   help='lose everything on the air from AT s after start for FOR s '
                   '(repeatable)')
    p.add_argument('--control', type=Path, default=None,
                   help='a file the relay watches: a line "cut SECONDS" written there '
                        'starts a cut now')
    p.add_argument('--stats', type=Path, default=None,
                   help='write the link counters here as JSON (every --stats-every s)')
    p.add_argument('--stats-every', type=float, default=1.0, help='(s)')
    p.add_argument('--tap', type=Path, default=None,
                   help='record what the fish sends, before the radio (TAP_RECORD records: '
                   'monotonic time, length, bytes)')
    return p


def parse_cut(text: str) -> tuple[float, float]:
    """Return (at, for) of a ``--cut AT:FOR``; a ValueError says what is wrong."""
    try:
        at_text, for_text = text.split(':')
        at, length = float(at_text), float(for_text)
    except ValueError:
        raise ValueError(f'--cut {text!r}: give AT:FOR in seconds, e.g. 20:10') from None
    if not (math.isfinite(at) and at >= 0.0 and math.isfinite(length) and length > 0.0):
        raise ValueError(f'--cut {text!r}: AT >= 0 and FOR > 0 (s)')
    return at, length


def stats_document(stats: RadioStats, preset_name: str, now: float,
                   cuts: list[tuple[float, float]]) -> dict[str, object]:
    """
    Return the JSON document of ``--stats``: counters, use per direction, the cuts.

    ``use_*``: the share of time each direction's packets held the air; ``load_*``: the bytes
    a second each direction carried over the preset's rate (``capacity_bytes_s``).
    """
    capacity_bytes_s = preset(preset_name).capacity_bytes_s
    return {
        'preset': preset_name, 'started': stats.started_s, 'now': now,
        'elapsed_s': now - stats.started_s, 'turnarounds': stats.turnarounds,
        'use_to_fish': stats.use(Direction.TO_FISH, now),
        'use_to_host': stats.use(Direction.TO_HOST, now),
        'capacity_bytes_s': capacity_bytes_s,
        'load_to_fish': stats.load(Direction.TO_FISH, now, capacity_bytes_s),
        'load_to_host': stats.load(Direction.TO_HOST, now, capacity_bytes_s),
        'to_fish': asdict(stats.to_fish), 'to_host': asdict(stats.to_host),
        'cuts': [list(cut) for cut in cuts],
    }


class _Device:
    """The fish's end: a serial device opened raw, non-blocking and locked; reopened."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.fd: int | None = None
        self._next_try = 0.0
        self.pending = bytearray()

    def ensure_open(self, now: float) -> None:
        if self.fd is not None or now < self._next_try:
            return
        self._next_try = now + REOPEN_S
        if open_refusal(str(self.path)) is not None:   # a stale virtual-fish link
            return
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        except OSError:
            return
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)   # as the bridge's own open
            tty.setraw(fd)
        except OSError:
            os.close(fd)
            return
        self.fd = fd
        print(f'radio_relay: {self.path} open ({os.path.realpath(self.path)})',
              file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
            self.pending.clear()

    def read(self) -> bytes:
        if self.fd is None:
            return b''
        try:
            return os.read(self.fd, 4096)
        except (BlockingIOError, InterruptedError):
            return b''
        except OSError as error:
            print(f'radio_relay: {self.path} lost ({error.strerror}); reopening',
                  file=sys.stderr, flush=True)
            self.close()
            return b''

    def write(self, data: bytes) -> None:
        """Queue ``data`` and write what the device takes now (what it refuses waits)."""
        if self.fd is None:
            return   # no device: the bytes reached no one, as over a radio without a peer
        self.pending.extend(data)
        del self.pending[:-MAX_PENDING]
        try:
            written = os.write(self.fd, self.pending)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as error:
            if error.errno in (errno.EIO, errno.EBADF):
                self.close()
                return
            raise
        del self.pending[:written]


def run(args: argparse.Namespace) -> int:
    """Relay until SIGINT/SIGTERM; return the exit code."""
    signals = SignalShutdown()
    params = preset(args.preset)
    start = time.monotonic()
    link = RadioLink(params, random.Random(args.seed), start)
    cuts: list[tuple[float, float]] = []

    def add_cut(begin: float, length: float) -> None:
        link.cut(begin, begin + length)
        cuts.append((begin, begin + length))
        print(f'radio_relay: cut {begin:.3f} .. {begin + length:.3f}', file=sys.stderr,
              flush=True)

    for at, length in (parse_cut(text) for text in args.cut):
        add_cut(start + at, length)
    host = PtyDevice(args.link)
    device = _Device(args.device)
    host_pending = bytearray()
    next_stats = start
    tap = open(args.tap, 'ab') if args.tap is not None else None
    try:
        print(host.open_pair(), flush=True)
        print(f'radio_relay: {params.name} between {args.link} and {args.device}',
              file=sys.stderr, flush=True)
        while not signals.requested:
            now = time.monotonic()
            if args.control is not None:
                for length in read_control_cuts(args.control):
                    add_cut(now, length)
            device.ensure_open(now)
            from_host = host.read()
            if from_host:
                link.send(Direction.TO_FISH, from_host, now)
            from_fish = device.read()
            if from_fish:
                link.send(Direction.TO_HOST, from_fish, now)
                if tap is not None:
                    tap.write(TAP_RECORD.pack(now, len(from_fish)) + from_fish)
                    tap.flush()
            for direction, data in link.poll(now + LATE_S):
                if direction is Direction.TO_FISH:
                    device.write(data)
                else:
                    host_pending.extend(data)
                    del host_pending[:-MAX_PENDING]
            if host_pending:
                del host_pending[:host.write(bytes(host_pending))]
            if device.pending:
                device.write(b'')
            if args.stats is not None and now >= next_stats:
                _write_stats(args.stats, stats_document(link.stats, params.name, now, cuts))
                next_stats = now + args.stats_every
            due = link.next_event_s()
            wait = MAX_WAIT_S if due is None else min(max(due - time.monotonic(), 0.0),
                                                      MAX_WAIT_S)
            readers = [host.fileno()] + ([device.fd] if device.fd is not None else [])
            if wait > 0.0:
                select.select(readers, [], [], wait)
    finally:
        begin_teardown()
        if args.stats is not None:
            now = time.monotonic()
            _write_stats(args.stats, stats_document(link.stats, params.name, now, cuts))
        if tap is not None:
            tap.close()
        device.close()
        host.close()
        host.remove_link()
    stats = link.stats
    now = time.monotonic()
    print(f'radio_relay: {params.name}, {now - start:.1f} s: use to fish '
          f'{stats.use(Direction.TO_FISH, now):.1%}, to host '
          f'{stats.use(Direction.TO_HOST, now):.1%}; packets lost '
          f'{stats.to_fish.packets_lost}/{stats.to_host.packets_lost}, '
          f'cut {stats.to_fish.packets_cut}/{stats.to_host.packets_cut}, bytes overflowed '
          f'{stats.to_fish.bytes_overflowed}/{stats.to_host.bytes_overflowed}',
          file=sys.stderr, flush=True)
    return 0


def read_control_cuts(path: Path) -> list[float]:
    """
    Return the cut lengths written at ``path`` and remove it ([] when there is none).

    A file whose last line is not complete is left for the next look: a writer creates the
    file before it writes (``echo cut 10 > PATH``, Python's ``write_text``), and a file read
    and removed in between took the cut with it (seen: a drive's cut never made).
    """
    try:
        text = path.read_text()
    except (FileNotFoundError, IsADirectoryError):
        return []
    if not text.endswith('\n'):
        return []
    path.unlink(missing_ok=True)
    lengths = []
    for line in text.splitlines():
        words = line.split()
        try:
            length = float(words[1]) if len(words) == 2 and words[0] == 'cut' else math.nan
        except ValueError:
            length = math.nan
        if math.isfinite(length) and length > 0.0:
            lengths.append(length)
        else:
            print(f'radio_relay: {path}: not "cut SECONDS": {line!r}', file=sys.stderr,
                  flush=True)
    return lengths


def _write_stats(path: Path, document: dict[str, object]) -> None:
    """Write ``document`` to ``path`` in one step (a reader never sees half of it)."""
    temporary = path.with_name(f'.{path.name}.{os.getpid()}')
    temporary.write_text(json.dumps(document))
    os.replace(temporary, path)


def flags_problem(args: argparse.Namespace) -> str | None:
    """Return why the flags cannot make a relay, or None."""
    for text in args.cut:
        try:
            parse_cut(text)
        except ValueError as error:
            return str(error)
    for name in ('stats_every',):
        value = getattr(args, name)
        if not (math.isfinite(value) and value > 0.0):
            return f'--{name.replace("_", "-")} must be finite and > 0, got {value}'
    if args.device == args.link:
        return '--device and --link must differ (the relay sits between them)'
    return None


def main(argv: list[str] | None = None) -> NoReturn:
    """Entry point: parse the flags, run; exit with its code."""
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    problem = flags_problem(args)
    if problem is not None:
        parser.error(problem)
    exit_now(run(args))


if __name__ == '__main__':
    raise SystemExit(main())
