# SPDX-License-Identifier: Apache-2.0
"""
`wirefish calibrate`: trim each servo's neutral, gain and direction on the fish, from the shore.

``show`` reads both servos' calibration (the board's pulse is ``neutral_us + direction *
us_per_rad * angle``), ``set SERVO`` changes one live (``--save``: and stores it on the board;
an option not given keeps the servo's current value), ``factory SERVO`` goes back to the
build's defaults (live and stored), ``sweep SERVO`` turns one servo 0 -> +a -> -a -> 0 to check
its wiring (stream mode only; Ctrl-C stops it). Through bridge_node's ``servo_trim`` and
``servo_sweep`` services, the same as ``ros2 service call /wirefish/servo_trim
wirefish_msgs/srv/ServoTrim "{servo: 1, op: 1, direction: 1, neutral_us: 1550.0, us_per_rad:
600.0}"``. A change is refused while the fish runs a gait (gait mode): the answer says how to
switch the bridge to stream mode.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
import math
import sys
import time

from wirefish_bringup.graph import DEFAULT_NAMESPACE
from wirefish_cli.ros_session import ros_session, RosSession

WAIT_S = 10.0
SOURCES = {0: 'DEFAULTS', 1: 'STORED', 2: 'LIVE'}
OP_READ, OP_SET, OP_SAVE, OP_FACTORY = 0, 1, 2, 3
# The servo_trim call itself waits up to 2 s for the fish (bridge_node) and then answers either
# way: the rest is the bridge's and DDS's time, seconds on a loaded machine.
ANSWER_MARGIN_S = 10.0


@dataclass(frozen=True)
class Cal:
    """One servo's calibration as the bridge's answer gives it."""

    servo: int
    source: int
    direction: int
    neutral_us: float
    us_per_rad: float
    min_us: float
    max_us: float


def cal_of(message) -> Cal:
    """Return the Cal of a wirefish_msgs/ServoTrimReport."""
    return Cal(message.servo, message.source, message.direction, message.neutral_us,
               message.us_per_rad, message.min_us, message.max_us)


def table(cals: list[Cal]) -> str:
    """Return the servos' calibrations aligned in columns: servo, source, the values."""
    rows = [('servo', 'source', 'neutral_us', 'us_per_rad', 'direction', 'min_us', 'max_us')]
    for c in cals:
        rows.append((str(c.servo), SOURCES.get(c.source, f'source {c.source}'),
                     f'{c.neutral_us:.1f}', f'{c.us_per_rad:.2f}', f'{c.direction:+d}',
                     f'{c.min_us:.1f}', f'{c.max_us:.1f}'))
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    return '\n'.join('  '.join(value.ljust(width) for value, width in zip(row, widths)).rstrip()
                     for row in rows)


def merged(current: Cal, neutral_us: float | None, us_per_rad: float | None,
           direction: int | None) -> tuple[int, float, float]:
    """Return (direction, neutral_us, us_per_rad): the given values, the current for the rest."""
    return (current.direction if direction is None else direction,
            current.neutral_us if neutral_us is None else neutral_us,
            current.us_per_rad if us_per_rad is None else us_per_rad)


def servo_number(text: str) -> int:
    """Return a SERVO argument: 1 or 2 (argparse type)."""
    if text not in ('1', '2'):
        raise argparse.ArgumentTypeError(f'a servo is 1 or 2, got {text!r}')
    return int(text)


def finite(text: str) -> float:
    """Return a finite number (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a number: {text!r}') from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f'must be finite, got {text}')
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the sub-commands and options of `wirefish calibrate`."""
    from wirefish_cli.api import duration_s

    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE,
                        help='ROS namespace of the bridge (default %(default)s)')
    parser.add_argument('--timeout', type=duration_s, default=WAIT_S,
                        help='seconds to wait for the bridge to appear (default %(default)s)')
    actions = parser.add_subparsers(dest='action', required=True, metavar='ACTION')
    described = {
        'show': "print both servos' calibration and where it comes from",
        'set': "change one servo's calibration (live; --save: also stored on the board)",
        'factory': "one servo back to the build's defaults, live and stored",
        'sweep': 'turn one servo 0 -> +a -> -a -> 0 to check its wiring (stream mode)',
    }
    parsers = {name: actions.add_parser(name, help=text, description=text)
               for name, text in described.items()}
    change = parsers['set']
    change.add_argument('servo', type=servo_number, metavar='SERVO', help='1 or 2')
    change.add_argument('--neutral-us', type=finite, help='pulse at 0 rad (us)')
    change.add_argument('--us-per-rad', type=finite, help='pulse change per rad (us/rad, > 0)')
    change.add_argument('--direction', type=int, choices=(1, -1),
                        help='+1, or -1 for a servo mounted the other way')
    change.add_argument('--save', action='store_true',
                        help='store it on the board (kept after a reboot)')
    parsers['factory'].add_argument('servo', type=servo_number, metavar='SERVO', help='1 or 2')
    sweep = parsers['sweep']
    sweep.add_argument('servo', type=servo_number, metavar='SERVO', help='1 or 2')
    sweep.add_argument('--amplitude', type=finite, default=0.3, metavar='RAD',
                       help='peak reel angle (rad, default %(default)s)')
    sweep.add_argument('--period', type=finite, default=4.0, metavar='S',
                       help='duration of the sweep (s, default %(default)s)')


class _Bridge:
    """The bridge's calibration services, called one at a time."""

    def __init__(self, session: RosSession) -> None:
        from wirefish_msgs.srv import ServoSweep, ServoTrim
        self.node, self.executor, self._session = session.node, session.executor, session
        base = session.namespace.rstrip('/')
        self.trim = self.node.create_client(ServoTrim, f'{base}/servo_trim')
        self.sweep = self.node.create_client(ServoSweep, f'{base}/servo_sweep')
        self.trim_type, self.sweep_type = ServoTrim, ServoSweep

    def wait(self, timeout_s: float) -> bool:
        return self._session.spin_until(
            lambda: self.trim.service_is_ready() and self.sweep.service_is_ready(), timeout_s)

    def call(self, client, request):
        future = client.call_async(request)
        self._session.spin_until(future.done, ANSWER_MARGIN_S)
        return future.result() if future.done() else None

    def trim_call(self, servo: int, op: int, direction: int = 0, neutral_us: float = 0.0,
                  us_per_rad: float = 0.0):
        return self.call(self.trim, self.trim_type.Request(
            servo=servo, op=op, direction=direction, neutral_us=neutral_us,
            us_per_rad=us_per_rad))

    def destroy(self) -> None:
        self.node.destroy_client(self.trim)
        self.node.destroy_client(self.sweep)


def _fail(text: str) -> int:
    print(f'wirefish calibrate: {text}', file=sys.stderr)
    return 1


def run(args: argparse.Namespace) -> int:
    """Run `wirefish calibrate ACTION`; return 0 when the fish did what was asked."""
    with ros_session('wirefish_calibrate', args.namespace) as session:
        bridge = _Bridge(session)
        try:
            if not bridge.wait(args.timeout):
                return _fail(f'no bridge found in {session.namespace}: waited '
                             f'{args.timeout:g} s for its {bridge.trim.srv_name} and '
                             f'{bridge.sweep.srv_name} services; is the graph running '
                             '(wirefish up), in this namespace (--namespace)?')
            return _ACTIONS[args.action](args, bridge)
        except KeyboardInterrupt:
            return 130
        finally:
            bridge.destroy()


def _read(bridge: _Bridge, servo: int) -> tuple[Cal | None, str]:
    answer = bridge.trim_call(servo, OP_READ)
    if answer is None:
        return None, f'{bridge.trim.srv_name} did not answer within {ANSWER_MARGIN_S:g} s'
    if not answer.accepted:
        return None, f'servo {servo}: {answer.reason}'
    return cal_of(answer.calibration), ''


def _show(args: argparse.Namespace, bridge: _Bridge) -> int:
    cals = []
    for servo in (1, 2):
        cal, why = _read(bridge, servo)
        if cal is None:
            return _fail(why)
        cals.append(cal)
    print(table(cals))
    return 0


def _change(bridge: _Bridge, servo: int, op: int, values: tuple[int, float, float]) -> int:
    direction, neutral_us, us_per_rad = values
    answer = bridge.trim_call(servo, op, direction, neutral_us, us_per_rad)
    if answer is None:
        return _fail(f'{bridge.trim.srv_name} did not answer within {ANSWER_MARGIN_S:g} s')
    if not answer.accepted:
        return _fail(f'servo {servo}: {answer.reason}')
    print(table([cal_of(answer.calibration)]))
    return 0


def _set(args: argparse.Namespace, bridge: _Bridge) -> int:
    values = (args.neutral_us, args.us_per_rad, args.direction)
    if all(v is None for v in values) and not args.save:
        return _fail('nothing to set: give --neutral-us, --us-per-rad, --direction or --save')
    current, why = _read(bridge, args.servo)
    if current is None:
        return _fail(why)
    return _change(bridge, args.servo, OP_SAVE if args.save else OP_SET,
                   merged(current, args.neutral_us, args.us_per_rad, args.direction))


def _factory(args: argparse.Namespace, bridge: _Bridge) -> int:
    return _change(bridge, args.servo, OP_FACTORY, (0, 0.0, 0.0))


def _sweep(args: argparse.Namespace, bridge: _Bridge) -> int:
    request = bridge.sweep_type.Request(servo=args.servo, amplitude_rad=args.amplitude,
                                        period_s=args.period)
    answer = bridge.call(bridge.sweep, request)
    if answer is None:
        return _fail(f'{bridge.sweep.srv_name} did not answer within {ANSWER_MARGIN_S:g} s')
    if not answer.accepted:
        return _fail(f'servo {args.servo}: {answer.reason}')
    print(f'servo {args.servo}: 0 -> +{args.amplitude:g} -> -{args.amplitude:g} -> 0 rad over '
          f'{args.period:g} s (the other servo at 0; servo_cmd is not forwarded meanwhile); '
          'Ctrl-C stops it', flush=True)
    try:
        end = time.monotonic() + args.period
        while time.monotonic() < end:
            bridge.executor.spin_once(timeout_sec=0.1)
    except KeyboardInterrupt:
        bridge.call(bridge.sweep, bridge.sweep_type.Request(servo=args.servo,
                                                            amplitude_rad=0.0, period_s=0.0))
        print('wirefish calibrate: sweep stopped', file=sys.stderr)
        return 130
    print(f'servo {args.servo}: sweep done')
    return 0


_ACTIONS = {'show': _show, 'set': _set, 'factory': _factory, 'sweep': _sweep}
