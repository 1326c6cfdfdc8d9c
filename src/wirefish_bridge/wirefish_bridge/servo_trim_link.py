# SPDX-License-Identifier: Apache-2.0
"""
The bridge's servo calibration, pure: SERVO_TRIM until answered, the reports, the wiring sweep.

No rclpy, no I/O; times are seconds of a monotonic clock.

``TrimExchange`` is one servo_trim service call on the wire: its SERVO_TRIM goes out at once
and again every ``resend_s`` (a lost request or a lost answer both end in a resend; SET, SAVE
and FACTORY of the same values twice leave the fish as once) until the fish answers: an ACK of
one of its copies with a refusal, or an accepting ACK followed by the report of its servo. It
gives up after ``timeout_s``.

``CalibrationState`` keeps each servo's last SERVO_TRIM_REPORT (the latched servo_calibration
topic).

``ServoSweep`` is the wiring check: one servo from 0 to +a, to -a and back to 0 in straight
ramps over the period, the other at 0. The bridge sends it as its own SERVO_CMD (stream mode
only) instead of servo_cmd while it runs, so it never fights the CPG: the CPG's commands are
not forwarded meanwhile, and forwarding resumes at the end.
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
import math

from wirefish_bridge.protocol import (Ack, ErrorCode, MsgType, SERVOS, ServoTrim,
                                      ServoTrimReport, TrimOp)

# The fish's refusals of a SERVO_TRIM in words (ErrorCode -> reason); ``reason`` adds the rest.
GAIT_MODE_HINT = ('switch the bridge to stream mode first: ros2 param set {bridge} drive_mode '
                  'stream')
REFUSALS = {
    ErrorCode.COMMAND_OUT_OF_RANGE: 'out of range: the fish refused the values (direction +-1, '
                                    'us_per_rad > 0, and neutral_us +- us_per_rad x the servo '
                                    'limit within the pulse range min_us..max_us)',
    ErrorCode.NOT_NOW: 'not now: the fish runs a gait (gait mode) and changes a calibration '
                       'only in stream mode; ' + GAIT_MODE_HINT,
    ErrorCode.STORAGE_FAILED: 'storage failed: the fish could not write its calibration; '
                              'nothing changed',
}
SWEEP_PERIOD_RANGE_S = (1.0, 120.0)


def gait_mode_hint(bridge: str) -> str:
    """Return how to put the bridge ``bridge`` (its full node name) in stream mode."""
    return GAIT_MODE_HINT.format(bridge=bridge)


def reason(code: int, bridge: str = '/wirefish/bridge_node') -> str:
    """Return the words of the fish's refusal ``code`` (an ErrorCode) to bridge ``bridge``."""
    if code == ErrorCode.NOT_NOW:
        return REFUSALS[ErrorCode.NOT_NOW].format(bridge=bridge)
    if code in REFUSALS:
        return REFUSALS[ErrorCode(code)]
    name = ErrorCode(code).name if code in set(ErrorCode) else 'unknown'
    return f'refused by the fish with error {code} ({name})'


def trim_request(servo: int, op: int, direction: int, neutral_us: float,
                 us_per_rad: float) -> tuple[ServoTrim | None, str]:
    """
    Return the SERVO_TRIM of a service request, or (None, why it is refused) before it goes out.

    READ and FACTORY carry no values (direction 0, floats 0, as the spec sends them).
    """
    try:
        op = TrimOp(op)
    except ValueError:
        return None, f'op {op} is not one of READ 0, SET 1, SAVE 2, FACTORY 3'
    if servo not in SERVOS:
        return None, f'servo {servo} is neither 1 nor 2'
    if op in (TrimOp.READ, TrimOp.FACTORY):
        return ServoTrim(servo, op), ''
    for name, value in (('neutral_us', neutral_us), ('us_per_rad', us_per_rad)):
        if not math.isfinite(value):
            return None, f'{name} {value} is not finite'
    request = ServoTrim(servo, op, direction, neutral_us, us_per_rad)
    problem = request.problem()
    return (None, problem) if problem is not None else (request, '')


class Outcome(enum.Enum):
    """How a servo_trim call ended."""

    PENDING = 'pending'
    ACCEPTED = 'accepted'     # ACK 0, then the servo's report
    REFUSED = 'refused'       # an ACK with an ErrorCode
    NO_ANSWER = 'no answer'   # nothing within the timeout


class TrimExchange:
    """One SERVO_TRIM on the wire until the fish answers (see the module doc)."""

    def __init__(self, request: ServoTrim, now: float, resend_s: float,
                 timeout_s: float) -> None:
        """Send ``request`` from ``now``: due at once, again every ``resend_s``."""
        self.request = request
        self.resend_s = resend_s
        self.deadline = now + timeout_s
        self.seqs: set[int] = set()
        self.sends = 0
        self.outcome = Outcome.PENDING
        self.result: int | None = None   # the ACK's result, once one came
        self.report: ServoTrimReport | None = None
        self._last_sent: float | None = None

    @property
    def done(self) -> bool:
        """Return True once the fish answered or the time ran out."""
        return self.outcome is not Outcome.PENDING

    def due(self, now: float) -> bool:
        """Return True when a copy should go out now (and mark the timeout)."""
        if self.done:
            return False
        if now >= self.deadline:
            self.outcome = Outcome.NO_ANSWER
            return False
        return self._last_sent is None or now - self._last_sent >= self.resend_s

    def sent(self, seq: int, now: float) -> None:
        """Note a copy that went out with sequence number ``seq``."""
        self.seqs.add(seq)
        self._last_sent = now
        self.sends += 1

    def on_ack(self, ack: Ack) -> bool:
        """Take an ACK; return True when it answers one of this request's copies."""
        if self.done or ack.acked_type != MsgType.SERVO_TRIM or ack.acked_seq not in self.seqs:
            return False
        self.result = ack.result
        if not ack.accepted:
            self.outcome = Outcome.REFUSED
        return True

    def on_report(self, report: ServoTrimReport) -> bool:
        """Take a report; return True when it is the answer (its servo, after an accepting ACK)."""
        if self.done or self.result != 0 or report.servo != self.request.servo:
            return False
        self.report = report
        self.outcome = Outcome.ACCEPTED
        return True

    def reason(self, bridge: str = '/wirefish/bridge_node') -> str:
        """Return why the call did not succeed, in words ('' when accepted)."""
        if self.outcome is Outcome.REFUSED and self.result is not None:
            return reason(self.result, bridge)
        if self.outcome is Outcome.NO_ANSWER:
            if self.result == 0:
                return 'the fish accepted it but its report did not arrive; read it again'
            if self.sends == 0:
                return ('nothing could be sent: the link to the fish is down or the fish has '
                        'not identified itself yet (see /diagnostics)')
            return (f'no answer from the fish ({self.sends} SERVO_TRIM sent): is the link up, '
                    'and does its firmware know SERVO_TRIM (protocol 2 with calibration)?')
        return ''


class CalibrationState:
    """Each servo's last report (None until one came)."""

    def __init__(self) -> None:
        """Know nothing yet."""
        self.reports: dict[int, ServoTrimReport | None] = {servo: None for servo in SERVOS}

    def on_report(self, report: ServoTrimReport) -> bool:
        """Take a report; return True when it is of servo 1 or 2 (kept)."""
        if report.servo not in SERVOS:
            return False
        self.reports[report.servo] = report
        return True


@dataclass(frozen=True)
class ServoSweep:
    """One sweep of ``servo`` (1 or 2): 0 -> +amplitude -> -amplitude -> 0 over ``period_s``."""

    servo: int
    amplitude_rad: float
    period_s: float
    start_s: float

    def angle(self, now: float) -> float:
        """Return the swept servo's angle at ``now`` (rad): three straight ramps, 0 outside."""
        t = (now - self.start_s) / self.period_s
        a = self.amplitude_rad
        if not 0.0 <= t < 1.0:
            return 0.0
        if t < 0.25:
            return a * 4.0 * t
        if t < 0.75:
            return a * (1.0 - 4.0 * (t - 0.25))
        return a * (-1.0 + 4.0 * (t - 0.75))

    def command(self, now: float) -> tuple[float, float]:
        """Return the SERVO_CMD angles of ``now``: the swept servo's, the other at 0."""
        angle = self.angle(now)
        return (angle, 0.0) if self.servo == 1 else (0.0, angle)

    def over(self, now: float) -> bool:
        """Return True once the period has passed."""
        return now - self.start_s >= self.period_s


def sweep_problem(servo: int, amplitude_rad: float, period_s: float,
                  limit_rad: float) -> str | None:
    """Return why a sweep request is refused (nothing sent), or None."""
    if servo not in SERVOS:
        return f'servo {servo} is neither 1 nor 2'
    if not math.isfinite(amplitude_rad) or not 0.0 < amplitude_rad <= limit_rad:
        return f'amplitude {amplitude_rad:g} rad outside (0, {limit_rad:g}] (servo_limit_rad)'
    low, high = SWEEP_PERIOD_RANGE_S
    if not math.isfinite(period_s) or not low <= period_s <= high:
        return f'period {period_s:g} s outside [{low:g}, {high:g}]'
    return None
