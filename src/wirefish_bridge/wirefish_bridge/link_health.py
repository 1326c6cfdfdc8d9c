# SPDX-License-Identifier: Apache-2.0
"""
Health of the bridge's link to the fish (pure: no rclpy, no I/O).

What the fish said, the rules of the diagnostic level and the /diagnostics values; times are
seconds of a monotonic clock.

The bridge node feeds ``LinkHealth`` with what it decodes and sends and asks it for the report;
the counters of the decoder and of the serial link are listed from their dataclasses, so a new
counter there shows up in /diagnostics without being named here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
import enum
import math

from wirefish_bridge.codec import DecoderStats
from wirefish_bridge.protocol import (ClockSource, ErrorCode, ErrorReport, Health, HealthFlags,
                                      Heartbeat, PROTOCOL_VERSION, ProtocolMessage, ResetCause,
                                      Role, Status, Telemetry,
                                      TelemetryCompact)
from wirefish_bridge.telemetry_limits import telemetry_problem
from wirefish_bridge.transport import LinkState, LinkStats

# Public /diagnostics names of counters whose dataclass field says it differently.
DECODER_KEYS: dict[str, str | None] = {'frames_ok': 'frames_in', 'seq_gaps': 'drops'}
LINK_KEYS: dict[str, str | None] = {
    'last_error': 'last_link_error', 'callback_errors': 'reader_errors',
    'writes_withheld': 'frames_withheld', 'bytes_in': None}   # None: the decoder's is listed


class Level(enum.IntEnum):
    """Diagnostic level, numbered as diagnostic_msgs/DiagnosticStatus."""

    OK = 0
    WARN = 1
    ERROR = 2


def identifies_fish(message: ProtocolMessage) -> bool:
    """Return True if ``message`` shows that a wirefish fish is on the line (a FISH heartbeat)."""
    return isinstance(message, Heartbeat) and message.role is Role.FISH


def error_name(code: int) -> str:
    """Return the name of an ERROR code, or 'code N' for one this bridge does not know."""
    try:
        return ErrorCode(code).name
    except ValueError:
        return f'code {code}'


def _name(kind: type[enum.IntEnum], value: int) -> str:
    try:
        return kind(value).name
    except ValueError:
        return f'unknown {value}'


def health_values(health: Health | None) -> dict[str, object]:
    """Return the /diagnostics values of the fish's last HEALTH ('none yet' before one)."""
    if health is None:
        return {'fish_reset_cause': 'none yet'}
    values: dict[str, object] = {
        'fish_reset_cause': _name(ResetCause, health.reset_cause),
        'fish_clock': _name(ClockSource, health.clock_source),
        'fish_health_flags': ', '.join(str(f.name) for f in HealthFlags
                                       if f and health.flags & f) or 'none',
        'fish_uptime_s': health.uptime_ms / 1000.0,
        'fish_stack_free_min': f'{health.stack_free_min} of {health.stack_size} bytes',
    }
    if health.flags & HealthFlags.FAULT_RECORD:
        values.update({'fish_fault_pc': f'0x{health.fault_pc:08x}',
                       'fish_fault_lr': f'0x{health.fault_lr:08x}',
                       'fish_fault_cfsr': f'0x{health.fault_cfsr:08x}',
                       'fish_fault_hfsr': f'0x{health.fault_hfsr:08x}'})
    for name in ('uart_rx_overruns', 'tx_bytes_dropped', 'rx_crc', 'rx_frame',
                 'rx_unknown_type', 'rx_length', 'rx_invalid', 'imu_faults', 'imu_recoveries',
                 'i2c_bus_recoveries'):
        values[f'fish_{name}'] = getattr(health, name)
    return values


def status_names(status: int) -> str:
    """Return the names of the set status flags, or 'ok'."""
    names = [str(flag.name) for flag in Status if flag and status & flag]
    return ', '.join(names) or 'ok'


@dataclass
class Outbound:
    """Frames the bridge sent, and those lost because the link was down or the write failed."""

    sent: int = 0
    dropped: int = 0


class RateMeter:
    """Rate of a monotonic counter between two readings."""

    def __init__(self, now: float, count: int = 0) -> None:
        """Start the first window at ``now`` with ``count``."""
        self._time, self._count = now, count

    def rate(self, now: float, count: int) -> float:
        """Return (count - last count) / elapsed since the last reading; start a new window."""
        elapsed = max(now - self._time, 1e-9)
        rate = (count - self._count) / elapsed
        self._time, self._count = now, count
        return rate


class LinkHealth:
    """What the bridge knows of the fish and of its link; the rules of the diagnostic level."""

    def __init__(self, heartbeat_timeout_s: float, now: float) -> None:
        """Nothing heard yet; a fish heartbeat older than ``heartbeat_timeout_s`` is stale."""
        self.heartbeat_timeout_s = heartbeat_timeout_s
        self.out = Outbound()
        self.fish_version: int | None = None
        self.fish_status = 0
        self.fish_errors = 0
        self.telemetry_rejected = 0
        self.last_telemetry_rejected = ''
        self.last_heartbeat: float | None = None
        self.last_telemetry: float | None = None
        self.last_health: Health | None = None
        self.fish_restarts = 0
        self._fish_uptime_ms: int | None = None
        self._rx_rate = RateMeter(now)
        self._tx_rate = RateMeter(now)

    def on_new_device(self) -> None:
        """Forget the fish: the port was (re)opened and another device may be behind it."""
        self.fish_version = None
        self.last_heartbeat = None

    def on_heartbeat(self, heartbeat: Heartbeat, now: float) -> tuple[Level, str] | None:
        """Take a fish heartbeat; return what to log when the fish's version is new."""
        self.last_heartbeat = now
        self._take_uptime(heartbeat.uptime_ms)
        if heartbeat.version == self.fish_version:
            return None
        self.fish_version = heartbeat.version
        if heartbeat.version != PROTOCOL_VERSION:
            return Level.ERROR, (f'fish speaks protocol version {heartbeat.version}, this '
                                 f'bridge {PROTOCOL_VERSION}')
        return Level.OK, f'fish says hello (protocol {heartbeat.version})'

    def _take_uptime(self, uptime_ms: int) -> bool:
        """Take the fish's uptime; return True when it went back (the board restarted)."""
        restarted = self._fish_uptime_ms is not None and uptime_ms < self._fish_uptime_ms
        self._fish_uptime_ms = uptime_ms
        if restarted:
            self.fish_restarts += 1
        return restarted

    def on_health(self, health: Health) -> str | None:
        """Take a HEALTH report; return a line to log when it tells of a fault reset."""
        first = self.last_health is None
        self.last_health = health
        if health.reset_cause in (ResetCause.FAULT, ResetCause.IWDG, ResetCause.BROWN_OUT) \
                and (first or health.uptime_ms < 5000):
            return (f'fish reset by {_name(ResetCause, health.reset_cause)}'
                    + (f' (fault pc 0x{health.fault_pc:08x})'
                       if health.flags & HealthFlags.FAULT_RECORD else ''))
        return None

    def on_telemetry(self, telemetry: Telemetry | TelemetryCompact, now: float) -> str | None:
        """Take a telemetry frame; return why it is impossible (then drop it), or None."""
        problem = telemetry_problem(telemetry)
        if problem is not None:
            self.telemetry_rejected += 1
            self.last_telemetry_rejected = problem
            return problem
        self.last_telemetry = now
        self.fish_status = telemetry.status
        return None

    def on_error_report(self, report: ErrorReport) -> str:
        """Count an ERROR from the fish; return its description."""
        self.fish_errors += 1
        return f'fish reports error {error_name(report.code)} about frame {report.ref_seq}'

    def heartbeat_age(self, now: float) -> float:
        """Return the age of the last fish heartbeat (s), inf if none since the port opened."""
        return math.inf if self.last_heartbeat is None else now - self.last_heartbeat

    def level(self, now: float, state: LinkState, port: str, link: LinkStats,
              failsafe: bool, gait_problem: str | None = None) -> tuple[Level, str]:
        """
        Return the diagnostic level and message; the first rule that applies wins.

        ``failsafe``: stream mode's gate commands neutral; ``gait_problem``: what gait mode
        finds wrong (not acknowledged, refused, diverging), None in stream mode or when fine.
        """
        if state is LinkState.IDENTIFYING:
            return Level.ERROR, (f'{port} is open but sent no fish heartbeat yet: writing '
                                 'nothing to it')
        if state is not LinkState.CONNECTED:
            if link.last_open_unidentified:
                return Level.ERROR, (f'{state.value}: {port} sent no fish heartbeat '
                                     f'({link.last_error}), not a fish?: wrote nothing, '
                                     'retrying')
            detail = f' ({link.last_error})' if link.last_error else ''
            return Level.ERROR, f'{state.value}: {port}{detail}'
        if self.fish_version is not None and self.fish_version != PROTOCOL_VERSION:
            return Level.ERROR, f'protocol version mismatch ({self.fish_version})'
        if self.heartbeat_age(now) > self.heartbeat_timeout_s:
            return Level.WARN, 'connected, fish heartbeat stale'
        if self.fish_status & Status.RESTING:
            return Level.WARN, 'connected, fish RESTING: it lost the link past its coast time'
        if self.fish_status & Status.COASTING:
            return Level.WARN, 'connected, fish COASTING: it lost the link, swims its last gait'
        if gait_problem is not None:
            return Level.WARN, f'connected, {gait_problem}'
        if failsafe:
            return Level.WARN, 'connected, no servo_cmd: commanding neutral'
        return Level.OK, 'connected'

    def values(self, now: float, state: LinkState, port: str, decoder: DecoderStats,
               link: LinkStats, gate: dict[str, object]) -> dict[str, object]:
        """Return the /diagnostics values: link, counters, what the fish said, the gate's."""
        values: dict[str, object] = {
            'link_state': state.value, 'port': port,
            'frames_in_per_s': self._rx_rate.rate(now, decoder.frames_ok),
            'frames_out_per_s': self._tx_rate.rate(now, self.out.sent),
            'frames_out': self.out.sent, 'frames_out_dropped': self.out.dropped,
        }
        values.update(_renamed(decoder.as_dict(), DECODER_KEYS))
        values.update(_renamed(asdict(link), LINK_KEYS))
        last_telemetry = math.inf if self.last_telemetry is None else now - self.last_telemetry
        values.update({
            'last_heartbeat_age_s': self.heartbeat_age(now),
            'last_telemetry_age_s': last_telemetry,
            'fish_protocol_version': ('unknown' if self.fish_version is None
                                      else self.fish_version),
            'fish_status': f'0x{self.fish_status:04x} ({status_names(self.fish_status)})',
            'fish_errors': self.fish_errors,
            'telemetry_rejected': self.telemetry_rejected,
            'last_telemetry_rejected': self.last_telemetry_rejected,
            'fish_restarts': self.fish_restarts,
        })
        values.update(health_values(self.last_health))
        values.update(gate)
        return values


def _renamed(counters: Mapping[str, object],
             names: Mapping[str, str | None]) -> dict[str, object]:
    renamed: dict[str, object] = {}
    for key, value in counters.items():
        name = names.get(key, key)
        if name is not None:
            renamed[name] = value
    return renamed
