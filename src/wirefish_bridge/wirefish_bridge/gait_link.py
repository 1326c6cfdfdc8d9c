# SPDX-License-Identifier: Apache-2.0
"""
The bridge's gait mode, pure: GAIT and LINK_CONFIG until acknowledged, the oscillator watch.

No rclpy, no I/O; times are seconds of a monotonic clock.

In gait mode the board integrates eq 1 itself; the host sends it the CPG node's parameters as
GAIT messages, each with a gait id (1..65535, 0 names none). ``GaitLink`` keeps what the board
should run:

- ``set_gait`` takes the CPG node's latest parameters (its latched ``cpg_params``); a change
  gets the next gait id and is due at once.
- A gait is acknowledged by an ACK of its GAIT frame (result 0) or by telemetry reporting its
  gait id. Until then it is due again every ``resend_s`` (a lost GAIT or a lost ACK both end
  in a resend; the fish takes a repeated GAIT as the same targets: no step). With
  ``repeat_s`` > 0 a new gait's first copy is followed by a second ``repeat_s`` later, before
  its acknowledgement could be back: on a lossy radio one lost copy (or one lost ACK) then
  costs nothing, where it would cost the wait for a resend. An ACK with a refusal stops the
  resends (the board said why: ``refusal``) until the next change.
- Telemetry that reports another gait id after the acknowledgement (the board reset, or a
  SERVO_CMD put it back to stream mode) makes the gait due again.
- The time from a change to its acknowledgement is kept (``ack_latencies_s``).

``ConfigLink`` does the same for LINK_CONFIG: due when the fish identifies itself (link up) and
after a fish restart, until an ACK accepts it.

``OscillatorWatch`` compares the host CPG's servo_cmd with the board's servo_state. The two
integrate the same equations from the same parameters but not from the same start (the host's
oscillator runs since the node started, the board's since it entered gait mode), so their
phases differ; what must agree is each servo's offset (the mean) and amplitude (the RMS about
the mean, R / sqrt(2) for a sine) over the last ``window_s``. The divergence is the largest of
|mean_host - mean_board| + |rms_host - rms_board| over both servos (rad).
"""

from __future__ import annotations

from collections import deque, OrderedDict
from dataclasses import dataclass
import math

from wirefish_bridge.protocol import Ack, Gait, LinkConfig, MsgType

GAIT_ID_MODULO = 0x10000


@dataclass(frozen=True)
class GaitParameters:
    """The CPG node's parameters as GAIT carries them (wirefish_msgs/CpgParams' fields)."""

    frequency_hz: float
    amplitude: tuple[float, float]
    offset: tuple[float, float]
    w12: float
    w21: float
    phi12: float
    phi21: float
    alpha: float

    def message(self, gait_id: int) -> Gait:
        """Return the GAIT of these parameters with ``gait_id``."""
        return Gait(gait_id, self.frequency_hz, self.amplitude[0], self.amplitude[1],
                    self.offset[0], self.offset[1], self.w12, self.w21, self.phi12,
                    self.phi21, self.alpha)


def next_gait_id(gait_id: int) -> int:
    """Return the id after ``gait_id`` (1..65535; 0 names no gait and is skipped)."""
    following = (gait_id + 1) % GAIT_ID_MODULO
    return following or 1


class _Acknowledged:
    """One message sent until its ACK: the seqs it went out with, when, and its answer."""

    def __init__(self, kind: MsgType, resend_s: float) -> None:
        self.kind = kind
        self.resend_s = resend_s
        self.seqs: set[int] = set()
        self.changed_s: float | None = None   # when the current content was taken
        self.last_sent_s: float | None = None
        self.acknowledged = False
        self.refusal: int | None = None       # ErrorCode of a refusal
        self.sends = 0

    def renew(self, now: float) -> None:
        """Take new content: nothing of the old counts, due at once."""
        self.seqs.clear()
        self.changed_s = now
        self.last_sent_s = None
        self.acknowledged = False
        self.refusal = None

    def again(self) -> None:
        """Make the same content due once more: the board forgot it."""
        self.acknowledged = False
        self.refusal = None
        self.last_sent_s = None

    def due(self, now: float) -> bool:
        if self.changed_s is None or self.acknowledged or self.refusal is not None:
            return False
        return self.last_sent_s is None or now - self.last_sent_s >= self.resend_s

    def sent(self, seq: int, now: float) -> None:
        self.seqs.add(seq)
        self.last_sent_s = now
        self.sends += 1

    def on_ack(self, ack: Ack) -> bool:
        """Take an ACK; return True when it newly acknowledges the current content."""
        if ack.acked_type != self.kind or ack.acked_seq not in self.seqs:
            return False
        if not ack.accepted:
            self.refusal = ack.result
            return False
        if self.acknowledged:
            return False
        self.acknowledged = True
        return True


class GaitLink:
    """What the board should run in gait mode, and whether it does (see the module doc)."""

    def __init__(self, resend_s: float, min_interval_s: float = 0.0,
                 repeat_s: float = 0.0) -> None:
        """
        Nothing to send yet.

        An unacknowledged GAIT goes again every ``resend_s``; a new gait goes out no sooner
        than ``min_interval_s`` after the last GAIT (changes in between are coalesced: the
        newest goes); with ``repeat_s`` > 0 its second copy goes ``repeat_s`` after the first
        unless it was acknowledged by then.
        """
        self.resend_s = resend_s
        self.min_interval_s = min_interval_s
        self.repeat_s = repeat_s
        self.parameters: GaitParameters | None = None
        self.gait_id = 0
        self.board_gait_id = 0   # as the newest telemetry says
        self.ack_latencies_s: deque[float] = deque(maxlen=2000)
        self.changes = 0
        self.sends = 0
        self.refusal: int | None = None   # ErrorCode with which the current gait was refused
        # Gaits taken and not yet acknowledged, in the order taken: id -> when taken. A gait
        # the board runs (or a newer one) acknowledges every older one with it.
        self._pending: OrderedDict[int, float] = OrderedDict()
        self._seq_gait: dict[int, int] = {}   # seq of a GAIT frame -> its gait id
        self._last_sent_s: float | None = None    # the current gait's last send
        self._copies_sent = 0                     # of the current gait
        self._last_any_s = -math.inf              # any GAIT's last send

    @property
    def acknowledged(self) -> bool:
        """Return True when the board runs the current gait."""
        return self.parameters is not None and self.gait_id not in self._pending

    def waiting_s(self, now: float) -> float:
        """Return how long the oldest gait not yet acknowledged has waited (0: none waits)."""
        times = [t for t in self._pending.values() if not math.isnan(t)]
        if self.parameters is not None and self.gait_id in self._pending and not times:
            times = [self._last_sent_s if self._last_sent_s is not None else now]
        return now - min(times) if times else 0.0

    def set_gait(self, parameters: GaitParameters, now: float) -> bool:
        """Take the CPG node's parameters; return True when they are a new gait."""
        if parameters == self.parameters:
            return False
        self.parameters = parameters
        self.gait_id = next_gait_id(self.gait_id)
        self._pending.pop(self.gait_id, None)   # an id taken 65535 gaits ago
        self._pending[self.gait_id] = now
        self.changes += 1
        self.refusal = None
        self._last_sent_s = None
        self._copies_sent = 0
        return True

    def due(self, now: float) -> Gait | None:
        """Return the GAIT to send now (new, or its resend), or None."""
        if self.parameters is None or self.acknowledged or self.refusal is not None:
            return None
        if self._last_sent_s is None:
            if now - self._last_any_s < self.min_interval_s:
                return None
        elif now - self._last_sent_s < self._next_copy_after_s():
            return None
        return self.parameters.message(self.gait_id)

    def _next_copy_after_s(self) -> float:
        """Return how long after the current gait's last copy the next one is due."""
        if self._copies_sent == 1 and 0.0 < self.repeat_s < self.resend_s:
            return self.repeat_s
        return self.resend_s

    def sent(self, seq: int, now: float) -> None:
        """Note that the due GAIT went out with sequence number ``seq``."""
        if len(self._seq_gait) > 4096:   # frames long answered or lost
            self._seq_gait.clear()
        self._seq_gait[seq] = self.gait_id
        self._last_sent_s = self._last_any_s = now
        self._copies_sent += 1
        self.sends += 1

    def on_ack(self, ack: Ack, now: float) -> None:
        """Take an ACK from the fish."""
        if ack.acked_type != MsgType.GAIT or ack.acked_seq not in self._seq_gait:
            return
        gait_id = self._seq_gait.pop(ack.acked_seq)
        if not ack.accepted:
            if gait_id == self.gait_id:
                self.refusal = ack.result
            return
        self._acknowledge_through(gait_id, now)

    def on_telemetry(self, gait_id: int, now: float) -> None:
        """Take the gait id the board reports."""
        self.board_gait_id = gait_id
        if self.parameters is None:
            return
        if gait_id in self._pending and gait_id in self._seq_gait.values():
            self._acknowledge_through(gait_id, now)
        elif self.acknowledged and gait_id != self.gait_id and self.refusal is None:
            self.on_fish_restart()   # the board no longer runs it (reset, stream mode)

    def _acknowledge_through(self, gait_id: int, now: float) -> None:
        """Acknowledge ``gait_id`` and every gait taken before it."""
        if gait_id not in self._pending:
            return
        while self._pending:
            taken_id, taken_s = self._pending.popitem(last=False)
            self.ack_latencies_s.append(now - taken_s)
            if taken_id == gait_id:
                break

    def waits_from(self, now: float) -> None:
        """
        Count the waits of the gaits not yet acknowledged from ``now`` at the earliest.

        The bridge holds GAIT until the fish runs the link it configured (a board at its boot
        defaults floods a narrow radio, and an ACK has no room): a gait taken before then
        could not have been acknowledged sooner, and its latency is the link's from then.
        """
        for gait_id, taken_s in self._pending.items():
            if not math.isnan(taken_s):
                self._pending[gait_id] = max(taken_s, now)

    def resting_gait(self) -> Gait | None:
        """
        Return a GAIT that brings the tail to rest through the oscillator, or None.

        The current gait with amplitudes and offsets 0 and the next id: the board converges to
        rest at alpha, as after its coast (what the bridge sends when it stops in gait mode).
        """
        if self.parameters is None:
            return None
        p = self.parameters
        rest = GaitParameters(p.frequency_hz, (0.0, 0.0), (0.0, 0.0), p.w12, p.w21, p.phi12,
                              p.phi21, p.alpha)
        return rest.message(next_gait_id(self.gait_id))

    def on_fish_restart(self) -> None:
        """Take a board restart: it runs no gait until the current one reaches it again."""
        if self.parameters is None:
            return
        if self.gait_id not in self._pending:
            # Due again, but not a change: its acknowledgement adds no gait change's latency.
            self._pending[self.gait_id] = math.nan
        self._last_sent_s = None   # due at once
        self._copies_sent = 0

    def values(self) -> dict[str, object]:
        """Return the /diagnostics values of the gait link."""
        latencies = sorted(v for v in self.ack_latencies_s if not math.isnan(v))
        return {
            'gait_id': self.gait_id, 'board_gait_id': self.board_gait_id,
            'gait_acknowledged': self.acknowledged, 'gait_changes': self.changes,
            'gait_frames_sent': self.sends,
            'gait_refused': 'no' if self.refusal is None else f'error {self.refusal}',
            'gait_acks': len(latencies),
            'gait_ack_median_s': percentile(latencies, 0.5),
            'gait_ack_p99_s': percentile(latencies, 0.99),
            'gait_ack_last_s': self.ack_latencies_s[-1] if self.ack_latencies_s else math.nan,
        }


class ConfigLink:
    """LINK_CONFIG: due at link-up and after a fish restart, sent until an ACK accepts it."""

    def __init__(self, config: LinkConfig, resend_s: float) -> None:
        """Hold ``config``; nothing is due before the fish identifies itself."""
        self.config = config
        self._state = _Acknowledged(MsgType.LINK_CONFIG, resend_s)

    @property
    def resend_s(self) -> float:
        """Return the resend period (s)."""
        return self._state.resend_s

    @resend_s.setter
    def resend_s(self, value: float) -> None:
        self._state.resend_s = value

    @property
    def acknowledged(self) -> bool:
        """Return True when the fish accepted the configuration."""
        return self._state.acknowledged

    @property
    def refusal(self) -> int | None:
        """Return the ErrorCode of a refusal, or None."""
        return self._state.refusal

    def link_up(self, now: float) -> None:
        """Take a link-up (a new device, or the same one back): the config is due again."""
        self._state.renew(now)

    def set_config(self, config: LinkConfig, now: float) -> None:
        """Use ``config`` from now (sent again if the link is up)."""
        self.config = config
        if self._state.changed_s is not None:
            self._state.renew(now)

    def due(self, now: float) -> LinkConfig | None:
        """Return the LINK_CONFIG to send now, or None."""
        return self.config if self._state.due(now) else None

    def sent(self, seq: int, now: float) -> None:
        """Note that LINK_CONFIG went out with sequence number ``seq``."""
        self._state.sent(seq, now)

    def on_ack(self, ack: Ack) -> bool:
        """Take an ACK from the fish; return True when it newly acknowledges LINK_CONFIG."""
        return self._state.on_ack(ack)


def percentile(sorted_values: list[float], share: float) -> float:
    """Return the ``share`` quantile of ``sorted_values`` (nearest rank), NaN when empty."""
    if not sorted_values:
        return math.nan
    rank = min(len(sorted_values) - 1, max(0, math.ceil(share * len(sorted_values)) - 1))
    return sorted_values[rank]


class OscillatorWatch:
    """The host CPG's servo_cmd against the board's servo_state (see the module doc)."""

    def __init__(self, window_s: float, bound_rad: float) -> None:
        """Compare over the last ``window_s``; a divergence above ``bound_rad`` is a problem."""
        self.window_s = window_s
        self.bound_rad = bound_rad
        self._host: deque[tuple[float, float, float]] = deque()
        self._board: deque[tuple[float, float, float]] = deque()

    def add_host(self, now: float, angles: tuple[float, float]) -> None:
        """Take a servo_cmd (rad) received at ``now``."""
        self._add(self._host, now, angles)

    def add_board(self, now: float, angles: tuple[float, float]) -> None:
        """Take the board's servo angles (rad) received at ``now``."""
        self._add(self._board, now, angles)

    def restart(self) -> None:
        """Forget both streams (a new gait converges: compare it once it ran a window)."""
        self._host.clear()
        self._board.clear()

    def _add(self, samples: deque[tuple[float, float, float]], now: float,
             angles: tuple[float, float]) -> None:
        samples.append((now, float(angles[0]), float(angles[1])))
        while samples and samples[0][0] < now - self.window_s:
            samples.popleft()

    def divergence(self, now: float) -> float | None:
        """Return the divergence in rad; None while a stream covers less than a window."""
        for samples in (self._host, self._board):
            if len(samples) < 4 or samples[-1][0] - samples[0][0] < 0.8 * self.window_s:
                return None
            if now - samples[-1][0] > 0.5 * self.window_s:
                return None   # a stream stopped: nothing current to compare
        worst = 0.0
        for servo in (1, 2):
            host = _mean_and_rms(self._host, servo)
            board = _mean_and_rms(self._board, servo)
            worst = max(worst, abs(host[0] - board[0]) + abs(host[1] - board[1]))
        return worst

    def problem(self, now: float) -> str | None:
        """Return a line for /diagnostics when the divergence is beyond the bound, else None."""
        value = self.divergence(now)
        if value is None or value <= self.bound_rad:
            return None
        return (f'board oscillator diverges from the host CPG by {value:.3f} rad '
                f'(offset + amplitude, bound {self.bound_rad:g} rad)')


def _mean_and_rms(samples: deque[tuple[float, float, float]], servo: int
                  ) -> tuple[float, float]:
    values = [sample[servo] for sample in samples]
    mean = sum(values) / len(values)
    rms = math.sqrt(sum((v - mean) ** 2 for v in values) / len(values))
    return mean, rms
