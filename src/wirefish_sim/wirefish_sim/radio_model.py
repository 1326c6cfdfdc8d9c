# SPDX-License-Identifier: Apache-2.0
"""
A serial radio between the bridge and the fish's board: the pure, clock-agnostic link model.

The two ends write bytes into their radio module (``send``) and take what reached them
(``poll``); the caller passes the time (seconds of any monotonic clock) into every call, so the
model runs on the wall clock in ``radio_relay`` and on made-up times in its tests. Randomness
comes from one seeded ``random.Random``: the same seed and the same calls give the same link.

What a transparent serial radio does to the bytes, and how the model says it:

- The UART to the module. Each end writes into its UART's transmit queue
  (``uart_buffer_bytes``), which takes or refuses whole frames of the wire format (a write is
  cut at each frame boundary, ``0x00 0x00``): a frame that does not fit is lost whole
  (``frames_refused``), as a firmware's transmit ring or a non-blocking tty write refuses it.
  The queue feeds the module at ``uart_baud`` (10 bits a byte); ``uart_baud`` 0: the bytes reach
  the module at once (the UART is the channel itself, as ``wired``).
- Packets. A module gathers the bytes its serial input receives until the input has been idle
  for ``gather_s`` or ``max_packet_bytes`` are waiting, then sends them as one packet with
  ``packet_overhead_bytes`` of preamble, sync word, header and CRC. Its buffer holds
  ``buffer_bytes`` per direction; what arrives beyond it is lost (``bytes_overflowed``).
- Air time. A packet of n bytes occupies the channel for
  ``t_air = (packet_overhead_bytes + n) * bits_per_byte / bit_rate_bps`` (eq. R1);
  ``bits_per_byte`` is 10 where a UART's start and stop bits are the bottleneck, 8 on a
  packet radio's air.
- Duplex. A full-duplex link has a channel per direction. A half-duplex link has one: when it
  changes direction the next packet waits ``turnaround_s`` (eq. R2:
  ``t_start = max(t_free, t_ready) + turnaround_s`` on a change). When both ends have a packet
  ready they take turns (the modules are assumed to wait for a free channel; collisions are not
  modelled).
- Latency. A packet is delivered whole at ``t_start + t_air + latency_s + U(0, jitter_s)``
  (eq. R3), never before the packet sent before it in that direction (a serial radio keeps
  the order).
- Burst loss (Gilbert-Elliott, in continuous time). The medium is GOOD or BAD; each stay is
  exponential with mean ``good_mean_s`` or ``bad_mean_s`` (``bad_mean_s`` 0: never BAD). A
  packet is lost with probability ``loss_good`` or ``loss_bad``, by the state at its start;
  both directions see the same medium (the fish's antenna under water cuts both).
  Long-run share of BAD: ``bad_mean_s / (good_mean_s + bad_mean_s)`` (eq. R4).
- Corruption. Each byte of a delivered packet is replaced with probability
  ``byte_error_good`` or ``byte_error_bad`` (what the module's own CRC let through).
- Cuts. ``cut(start_s, end_s)`` loses every packet whose air time overlaps the window: a
  scripted outage (the fish dived, the operator walked behind a wall).

Link use per direction is the air time spent on that direction's packets over the elapsed
time (``RadioStats.use``), the figure a preset's rate limits.
"""

from __future__ import annotations

import bisect
from collections import deque
from dataclasses import dataclass, field, fields
import enum
import math
import random


class Direction(enum.IntEnum):
    """Which way bytes cross the radio."""

    TO_FISH = 0   # host (bridge) -> fish (board)
    TO_HOST = 1   # fish (board) -> host (bridge)


class Medium(enum.IntEnum):
    """State of the Gilbert-Elliott medium."""

    GOOD = 0
    BAD = 1


@dataclass(frozen=True)
class RadioParameters:
    """The numbers of one radio (see the module docstring for each one's role)."""

    name: str
    bit_rate_bps: float
    bits_per_byte: float = 8.0
    packet_overhead_bytes: int = 0
    max_packet_bytes: int = 64
    gather_s: float = 0.0
    buffer_bytes: int = 4096
    half_duplex: bool = False
    turnaround_s: float = 0.0
    latency_s: float = 0.0
    jitter_s: float = 0.0
    good_mean_s: float = 1.0
    bad_mean_s: float = 0.0
    loss_good: float = 0.0
    loss_bad: float = 0.0
    byte_error_good: float = 0.0
    byte_error_bad: float = 0.0
    uart_baud: float = 0.0
    uart_buffer_bytes: int = 4096

    def __post_init__(self) -> None:
        """Refuse numbers no radio has (a clear ValueError naming the field)."""
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == 'name' or isinstance(value, bool):
                continue
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f'radio {self.name}: {f.name} must be finite and >= 0, '
                                 f'got {value}')
        for name in ('bit_rate_bps', 'bits_per_byte', 'max_packet_bytes', 'good_mean_s'):
            if getattr(self, name) <= 0:
                raise ValueError(f'radio {self.name}: {name} must be > 0')
        for name in ('loss_good', 'loss_bad', 'byte_error_good', 'byte_error_bad'):
            if getattr(self, name) > 1.0:
                raise ValueError(f'radio {self.name}: {name} is a probability, got '
                                 f'{getattr(self, name)}')
        if self.buffer_bytes < self.max_packet_bytes:
            raise ValueError(f'radio {self.name}: buffer_bytes ({self.buffer_bytes}) must hold '
                             f'one packet ({self.max_packet_bytes})')

    @property
    def byte_time_s(self) -> float:
        """Return the air time of one byte (s)."""
        return self.bits_per_byte / self.bit_rate_bps

    def air_time_s(self, payload_bytes: int) -> float:
        """Return the air time of a packet carrying ``payload_bytes`` (eq. R1)."""
        return (self.packet_overhead_bytes + payload_bytes) * self.byte_time_s

    @property
    def capacity_bytes_s(self) -> float:
        """Return the bytes a second one way: full packets on the air, or the UART if slower."""
        air = self.max_packet_bytes / self.air_time_s(self.max_packet_bytes)
        return min(air, self.uart_baud / 10.0) if self.uart_baud > 0.0 else air


# The presets of `wirefish up --radio`. docs/REFERENCE.md gives each number's source; what a
# datasheet does not give is marked an assumption there.
PRESETS: dict[str, RadioParameters] = {
    # A UART cable at 115200 baud, 8N1: 11520 bytes/s each way at once, nothing lost.
    'wired': RadioParameters('wired', bit_rate_bps=115200.0, bits_per_byte=10.0,
                             max_packet_bytes=64, buffer_bytes=4096),
    # A Bluetooth Classic SPP module (HC-05 class) at its 115200 baud UART: the UART is the
    # bottleneck (BR/EDR's ACL carries ~700 kbit/s); its radio slots both ways. At the surface
    # the 2.4 GHz antenna dips under water in bursts (a tail beat, a wave): BAD ~0.3 s every
    # ~3 s, where nearly all is lost.
    'bluetooth': RadioParameters('bluetooth', bit_rate_bps=700000.0, bits_per_byte=8.0,
                                 packet_overhead_bytes=16, uart_baud=115200.0,
                                 uart_buffer_bytes=1024,
                                 max_packet_bytes=128, gather_s=0.002, buffer_bytes=1024,
                                 latency_s=0.015, jitter_s=0.010, good_mean_s=3.0,
                                 bad_mean_s=0.3, loss_good=0.002, loss_bad=0.9,
                                 byte_error_good=1e-6, byte_error_bad=1e-4),
    # A transparent sub-GHz module (433 MHz, HC-12 class) at its factory default: 9600 baud on
    # the UART (the bottleneck: 960 B/s), 15 kbit/s on the air (FU3 mode at 9600 baud), the
    # sender's transmit queue 512 bytes, half duplex: a few ms to turn around, ~12-30 ms of
    # module latency, packets gathered after 3 byte times of idle input, a 256-byte buffer.
    # 433 MHz reaches over the surface much better than 2.4 GHz: shorter, rarer bursts.
    'rf433': RadioParameters('rf433', bit_rate_bps=15000.0, bits_per_byte=8.0,
                             uart_baud=9600.0, uart_buffer_bytes=512,
                             packet_overhead_bytes=9, max_packet_bytes=60, gather_s=0.003,
                             buffer_bytes=256, half_duplex=True, turnaround_s=0.003,
                             latency_s=0.015, jitter_s=0.010, good_mean_s=8.0,
                             bad_mean_s=0.15, loss_good=0.005, loss_bad=0.5,
                             byte_error_good=1e-6, byte_error_bad=1e-4),
}


def frame_units(data: bytes) -> list[bytes]:
    """
    Return ``data`` cut at each frame boundary of the wire format (``0x00 0x00``).

    Frames are ``0x00 COBS(body) 0x00``, so two frames written together meet as ``00 00``;
    bytes without that pattern are one unit.
    """
    units = []
    start = 0
    index = data.find(b'\x00\x00')
    while index >= 0:
        units.append(data[start:index + 1])
        start = index + 1
        index = data.find(b'\x00\x00', start)
    if start < len(data):
        units.append(data[start:])
    return units


def preset(name: str) -> RadioParameters:
    """Return the preset ``name``; a ValueError names the presets for an unknown one."""
    try:
        return PRESETS[name]
    except KeyError:
        raise ValueError(f'no radio preset {name!r}: choose one of '
                         f'{", ".join(PRESETS)}') from None


@dataclass
class DirectionStats:
    """What crossed (or failed to cross) the radio one way."""

    bytes_offered: int = 0      # written into the sending end's UART
    frames_refused: int = 0     # lost whole: the UART's transmit queue had no room
    bytes_refused: int = 0      # their bytes
    bytes_overflowed: int = 0   # lost: the module's buffer was full
    packets_sent: int = 0
    packets_lost: int = 0       # burst loss
    packets_cut: int = 0        # in a scripted cut
    bytes_delivered: int = 0
    bytes_corrupted: int = 0
    air_time_s: float = 0.0


@dataclass
class RadioStats:
    """Counters of both directions, turn-arounds and the elapsed time they cover."""

    started_s: float
    to_fish: DirectionStats = field(default_factory=DirectionStats)
    to_host: DirectionStats = field(default_factory=DirectionStats)
    turnarounds: int = 0

    def of(self, direction: Direction) -> DirectionStats:
        """Return the counters of ``direction``."""
        return self.to_fish if direction is Direction.TO_FISH else self.to_host

    def use(self, direction: Direction, now: float) -> float:
        """Return the share of time ``direction``'s packets held the air since the start."""
        return self.of(direction).air_time_s / max(now - self.started_s, 1e-9)

    def load(self, direction: Direction, now: float, capacity_bytes_s: float) -> float:
        """Return the bytes a second ``direction`` carried (not refused) over ``capacity``."""
        stats = self.of(direction)
        carried = stats.bytes_offered - stats.bytes_refused - stats.bytes_overflowed
        return carried / max(now - self.started_s, 1e-9) / capacity_bytes_s


@dataclass
class _Packet:
    direction: Direction
    deliver_s: float
    data: bytes


class _Medium:
    """The Gilbert-Elliott state as a function of time; queries may go back a little."""

    def __init__(self, params: RadioParameters, rng: random.Random, start_s: float) -> None:
        self._params, self._rng = params, rng
        self._switches = [start_s]     # times the state changed; state k alternates from GOOD
        self._first = Medium.GOOD
        self._horizon = start_s + self._stay(Medium.GOOD)

    def _stay(self, state: Medium) -> float:
        if self._params.bad_mean_s <= 0.0:
            return math.inf   # a medium without BAD stays GOOD
        mean = self._params.good_mean_s if state is Medium.GOOD else self._params.bad_mean_s
        return self._rng.expovariate(1.0 / mean)

    def state(self, t: float) -> Medium:
        """Return the state at ``t`` (not before the last ``forget``)."""
        while t >= self._horizon:
            self._switches.append(self._horizon)
            self._horizon += self._stay(self._state_of(len(self._switches) - 1))
        k = max(bisect.bisect_right(self._switches, t) - 1, 0)
        return self._state_of(k)

    def _state_of(self, k: int) -> Medium:
        return Medium((int(self._first) + k) % 2)

    def forget(self, before_s: float) -> None:
        """Drop the history before ``before_s`` (queries stay at or after it)."""
        k = bisect.bisect_right(self._switches, before_s) - 1
        if k > 0:
            self._first = self._state_of(k)
            del self._switches[:k]


# How far back a query of the medium may reach (s): the full-duplex channels start packets a
# little out of order between them, never by more than one packet's wait.
_MEDIUM_MEMORY_S = 10.0


class RadioLink:
    """One radio link: two modules and the medium between them (see the module docstring)."""

    def __init__(self, params: RadioParameters, rng: random.Random, now: float) -> None:
        """Start idle at ``now``: empty buffers, GOOD medium, no cut."""
        self.params = params
        self.stats = RadioStats(started_s=now)
        self._rng = rng
        self._medium = _Medium(params, rng, now)
        self._time = now
        self._queues = (bytearray(), bytearray())
        self._last_input = [now, now]
        # The UART stage: chunks (arrival at the module, bytes) in order, per direction.
        self._uart: tuple[deque[tuple[float, bytes]], ...] = (deque(), deque())
        self._uart_free = [now, now]
        self._channel_free = [now, now]     # full duplex: per direction; half: [0] only
        self._last_direction: Direction | None = None
        self._last_delivery = [now, now]
        self._in_flight: deque[_Packet] = deque()
        self._cuts: list[tuple[float, float]] = []
        self._next_turn = Direction.TO_HOST

    # --- the ends -----------------------------------------------------------------------
    def send(self, direction: Direction, data: bytes, now: float) -> None:
        """Write ``data`` into the UART of the end that sends ``direction`` at ``now``."""
        self._advance(now)
        if not data:
            return
        stats = self.stats.of(direction)
        stats.bytes_offered += len(data)
        if self.params.uart_baud <= 0.0:
            self._into_module(direction, data, now)
            self._advance(now)
            return
        uart = self._uart[direction]
        byte_s = 10.0 / self.params.uart_baud
        for unit in frame_units(data):
            # The bytes the UART has not shifted out yet: it frees room byte by byte.
            queued = max(0.0, self._uart_free[direction] - now) / byte_s
            if queued + len(unit) > self.params.uart_buffer_bytes + 1e-9:
                stats.frames_refused += 1
                stats.bytes_refused += len(unit)
                continue
            self._uart_free[direction] = (max(now, self._uart_free[direction])
                                          + len(unit) * byte_s)
            uart.append((self._uart_free[direction], unit))
        self._advance(now)

    def _into_module(self, direction: Direction, data: bytes, now: float) -> None:
        """Put ``data`` into the module's buffer at ``now`` (what overflows is lost)."""
        stats = self.stats.of(direction)
        queue = self._queues[direction]
        room = max(self.params.buffer_bytes - len(queue), 0)
        if len(data) > room:
            stats.bytes_overflowed += len(data) - room
            data = data[:room]
        queue.extend(data)
        self._last_input[direction] = now

    def poll(self, now: float) -> list[tuple[Direction, bytes]]:
        """Return the packets delivered by ``now``, in delivery order, as (direction, bytes)."""
        self._advance(now)
        delivered = []
        while self._in_flight and self._in_flight[0].deliver_s <= now:
            packet = self._in_flight.popleft()
            delivered.append((packet.direction, packet.data))
        return delivered

    def cut(self, start_s: float, end_s: float) -> None:
        """Lose every packet on the air between ``start_s`` and ``end_s`` (a scripted cut)."""
        if not end_s > start_s:
            raise ValueError(f'a cut ends after it starts, got {start_s} .. {end_s}')
        self._cuts.append((start_s, end_s))

    def next_event_s(self) -> float | None:
        """Return when ``poll`` next has work (a delivery or a packet to start), or None."""
        times = [self._in_flight[0].deliver_s] if self._in_flight else []
        times += [uart[0][0] for uart in self._uart if uart]
        for direction in Direction:
            ready = self._ready_s(direction)
            if ready is not None:
                times.append(max(ready, self._free_s(direction)))
        return min(times) if times else None

    def waiting_bytes(self, direction: Direction) -> int:
        """Return the bytes in ``direction``'s module buffer, not yet on the air."""
        return len(self._queues[direction])

    # --- the model ----------------------------------------------------------------------
    def _free_s(self, direction: Direction) -> float:
        return self._channel_free[0 if self.params.half_duplex else direction]

    def _ready_s(self, direction: Direction) -> float | None:
        """Return when ``direction``'s module has a packet to send, or None (nothing waits)."""
        queue = self._queues[direction]
        if not queue:
            return None
        if len(queue) >= self.params.max_packet_bytes:
            return self._last_input[direction]
        return self._last_input[direction] + self.params.gather_s

    def _advance(self, now: float) -> None:
        """Move the UARTs' bytes and start every packet, in time order, up to ``now``."""
        while True:
            arrivals = [(uart[0][0], d) for d, uart in zip(Direction, self._uart) if uart]
            arrival = min(arrivals) if arrivals else None
            choice = self._next_start(now if arrival is None or arrival[0] > now
                                      else arrival[0])
            if choice is not None and (arrival is None or choice[1] <= arrival[0]):
                self._transmit(*choice)
            elif arrival is not None and arrival[0] <= now:
                t, direction = arrival
                self._into_module(direction, self._uart[direction].popleft()[1], t)
            else:
                break
        self._time = max(self._time, now)
        self._medium.forget(now - _MEDIUM_MEMORY_S)

    def _next_start(self, now: float) -> tuple[Direction, float] | None:
        """Return the next packet to start by ``now`` and its start (eq. R2), or None."""
        candidates = []
        for direction in Direction:
            ready = self._ready_s(direction)
            if ready is None:
                continue
            start = max(ready, self._free_s(direction))
            if (self.params.half_duplex and self._last_direction is not None
                    and direction is not self._last_direction):
                start += self.params.turnaround_s
            candidates.append((start, direction, ready))
        if not candidates:
            return None
        start, direction, _ = min(candidates)
        if self.params.half_duplex and len(candidates) == 2:
            free = self._channel_free[0]
            if all(ready <= free for _, _, ready in candidates):
                # Both ends waited for the channel: they take turns (neither starves).
                start, direction = next((s, d) for s, d, _ in candidates
                                        if d is self._next_turn)
        return (direction, start) if start <= now else None

    def _transmit(self, direction: Direction, start: float) -> None:
        params = self.params
        queue = self._queues[direction]
        size = min(len(queue), params.max_packet_bytes)
        data = bytes(queue[:size])
        del queue[:size]
        air = params.air_time_s(size)
        end = start + air
        if params.half_duplex:
            if self._last_direction is not None and direction is not self._last_direction:
                self.stats.turnarounds += 1
            self._channel_free[0] = end
            self._next_turn = Direction(1 - direction)
        else:
            self._channel_free[direction] = end
        self._last_direction = direction
        stats = self.stats.of(direction)
        stats.packets_sent += 1
        stats.air_time_s += air
        if any(a < end and start < b for a, b in self._cuts):
            stats.packets_cut += 1
            return
        state = self._medium.state(start)
        loss = params.loss_good if state is Medium.GOOD else params.loss_bad
        if loss > 0.0 and self._rng.random() < loss:
            stats.packets_lost += 1
            return
        error = params.byte_error_good if state is Medium.GOOD else params.byte_error_bad
        if error > 0.0:
            data = self._corrupt(data, error, stats)
        deliver = end + params.latency_s + self._rng.uniform(0.0, params.jitter_s)
        deliver = max(deliver, self._last_delivery[direction])
        self._last_delivery[direction] = deliver
        stats.bytes_delivered += len(data)
        packet = _Packet(direction, deliver, data)
        # Deliveries of the two directions interleave: keep the flight sorted by time.
        index = len(self._in_flight)
        while index > 0 and self._in_flight[index - 1].deliver_s > deliver:
            index -= 1
        self._in_flight.insert(index, packet)

    def _corrupt(self, data: bytes, probability: float, stats: DirectionStats) -> bytes:
        """Replace each byte with ``probability``: the gaps between errors are geometric."""
        out = bytearray(data)
        index = -1
        log_keep = math.log1p(-probability) if probability < 1.0 else -math.inf
        while True:
            # Bytes to the next error: floor(ln U / ln(1 - p)), U in (0, 1].
            draw = 1.0 - self._rng.random()
            index += 1 + (0 if log_keep == -math.inf else int(math.log(draw) / log_keep))
            if index >= len(out):
                return bytes(out)
            out[index] ^= self._rng.randrange(1, 256)   # never 0: the byte does change
            stats.bytes_corrupted += 1
