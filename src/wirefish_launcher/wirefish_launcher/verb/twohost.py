# SPDX-License-Identifier: Apache-2.0
"""
`wirefish twohost`: the fish and the shore on two hosts made of network namespaces (root).

Makes a fish host and a shore host joined by a veth pair (``wirefish_launcher.netns``), starts
``wirefish up --role fish`` on the first and ``wirefish up --role shore`` on the second, prints
how to open a shell on each, how to cut the link and how to shape it, and runs until Ctrl-C
(or ``--duration``); then it stops both sides and deletes both namespaces. ``--rate 100kbit``
starts with a token-bucket limit like a Bluetooth serial link. Needs root (CAP_NET_ADMIN) and
says so otherwise.
"""

import argparse
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

from wirefish_bringup.graph import DEFAULT_NAMESPACE, Role, validate_namespace
from wirefish_cli.api import duration_s
from wirefish_launcher.netns import Discovery, NetnsError, root_problem, SIDES, TwoHosts
from wirefish_launcher.stop_flag import stop_on_signals

STOP_TIMEOUT_S = 30.0  # each side's `wirefish up` stops its own processes first


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish twohost`."""
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--token', default=None,
                        help='names the pair wf<token>f / wf<token>s (default: from the PID)')
    parser.add_argument('--subnet', type=int, default=0,
                        help='addresses 10.213.<subnet>.1 (fish) and .2 (shore); default 0')
    parser.add_argument('--discovery', choices=[d.value for d in Discovery],
                        default=Discovery.MULTICAST.value,
                        help='DDS discovery across the link: multicast (SUBNET) or static '
                        'peers (LOCALHOST + ROS_STATIC_PEERS)')
    parser.add_argument('--rate', default=None,
                        help='token-bucket limit of each direction, e.g. 100kbit (tc tbf)')
    parser.add_argument('--duration', type=duration_s, default=None,
                        help='run this many seconds (default: until Ctrl-C)')
    parser.add_argument('--out', type=Path, default=Path('out'),
                        help='where both sides write their run logs (default: ./out)')


def instructions(link: TwoHosts, domain: str, discovery: str) -> str:
    """Return what a person types to look at, cut and shape the pair."""
    lines = []
    for side in SIDES:
        env = ' '.join(f'{k}={v}' for k, v in
                       {'ROS_DOMAIN_ID': domain, **link.ros_environment(side, discovery)}.items()
                       if v)
        lines.append(f'{side:>5} host {link.address(side)}: ip netns exec '
                     f'{link.namespace(side)} env {env} bash')
    fish_ns, fish_dev = link.namespace(Role.FISH), link.device(Role.FISH)
    lines += [f'cut the link:    ip -n {fish_ns} link set {fish_dev} down   (up: restore)',
              f'shape the link:  ip netns exec {fish_ns} tc qdisc replace dev {fish_dev} root '
              'tbf rate 100kbit burst 16kbit latency 400ms',
              f'bytes crossing:  ip -n {fish_ns} -s link show {fish_dev}']
    return '\n'.join(lines)


def run(args: argparse.Namespace) -> int:
    """Run `wirefish twohost`; return the process exit code."""
    problem = root_problem()
    if problem is not None:
        print(f'wirefish twohost: {problem}', file=sys.stderr)
        return 2
    try:
        namespace = validate_namespace(args.namespace)
        link = TwoHosts(args.token or f'{os.getpid():x}'[-6:], args.subnet)
    except ValueError as error:
        print(f'wirefish twohost: {error}', file=sys.stderr)
        return 2
    domain = os.environ.get('ROS_DOMAIN_ID', '0')
    stop = stop_on_signals()
    sides: dict[Role, subprocess.Popen[bytes]] = {}
    try:
        link.create()
        if args.rate:
            link.shape(args.rate)
        for side in SIDES:
            env = dict(os.environ, ROS_DOMAIN_ID=domain,
                       **link.ros_environment(side, args.discovery))
            sides[side] = subprocess.Popen(
                [*link.exec_prefix(side), sys.executable, '-m', 'wirefish_cli.cli', 'up',
                 '--role', side, '--namespace', namespace, '--no-status', '--out',
                 str(args.out)], env=env, start_new_session=True)
        print(instructions(link, domain, args.discovery), flush=True)
        started = time.monotonic()
        while not stop.requested and all(p.poll() is None for p in sides.values()):
            if args.duration is not None and time.monotonic() - started >= args.duration:
                break
            time.sleep(0.2)
    except NetnsError as error:
        print(f'wirefish twohost: {error}', file=sys.stderr)
        return 1
    finally:
        codes = {side: _stop(proc) for side, proc in sides.items()}
        link.remove()
    print('stopped: ' + ', '.join(f'{side} side {code}' for side, code in codes.items())
          + f'; removed {link.namespace(Role.FISH)} and {link.namespace(Role.SHORE)}')
    return 0 if all(code == 0 for code in codes.values()) else 1


def _stop(proc: subprocess.Popen[bytes]) -> int | None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            return proc.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            return None
    return proc.returncode
