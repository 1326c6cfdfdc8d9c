# SPDX-License-Identifier: Apache-2.0
"""
Two hosts on one machine: two network namespaces joined by a veth pair.

``TwoHosts(token, subnet)`` names everything it creates with ``wf`` + ``token`` (the namespaces
``wf<token>f`` for the fish and ``wf<token>s`` for the shore, the veth ends ``wf<token>a`` and
``wf<token>b``) and addresses only 10.213.<subnet>.1 (fish) and .2 (shore). ``create()`` builds
it, ``remove()`` takes it all down again (also half-built, also twice); ``cut()``/``restore()``
set both veth ends down/up (a radio that fails); ``shape()`` puts a token-bucket (tbf) limit on
both ends' egress; ``tx_bytes()`` reads a side's transmitted byte counter. Everything goes
through the ``ip`` and ``tc`` commands and needs root (CAP_NET_ADMIN): ``root_problem()`` says
why it cannot run here.

DDS across the pair: ``ros_environment()`` is what each side sets, as two real hosts would
(README, "Fish and shore on two hosts"): ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST (no multicast
over the radio; the nodes on one host find each other locally), ROS_STATIC_PEERS=<the other
host> (unicast discovery of the other side), and FASTDDS_BUILTIN_TRANSPORTS=UDPv4: the two
namespaces share /dev/shm, and Fast DDS's shared-memory transport would otherwise carry data
between them past the veth, so a cut link would not cut.
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
import json
import os
import re
import shutil
import subprocess

from wirefish_bringup.graph import Role

# The two hosts are the two roles of a graph apart (each runs `wirefish up --role <side>`).
SIDES = (Role.FISH, Role.SHORE)


class Discovery(enum.StrEnum):
    """How DDS discovers across the link (`wirefish twohost --discovery`)."""

    MULTICAST = 'multicast'
    STATIC = 'static'


_TOKEN = re.compile(r'^[a-z0-9]{1,8}$')  # wf + token + one letter fits IFNAMSIZ (15)
COMMAND_TIMEOUT_S = 10.0
MULTICAST_ROUTE = '224.0.0.0/4'  # IPv4 multicast, routed over the veth (see create())


class NetnsError(RuntimeError):
    """An ip/tc command failed; the message holds the command and what it printed."""


def root_problem() -> str | None:
    """Return why network namespaces cannot be made here (not root, no ip/tc), or None."""
    if os.geteuid() != 0:
        return ('two hosts need network namespaces and a veth pair, which only root can make '
                '(run as root, e.g. sudo, or in CI)')
    missing = [tool for tool in ('ip', 'tc') if shutil.which(tool) is None]
    if missing:
        return f'two hosts need the {" and ".join(missing)} command (iproute2)'
    return None


def _run(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    try:
        done = subprocess.run(args, capture_output=True, text=True, timeout=COMMAND_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise NetnsError(f'{" ".join(args)}: {error}') from error
    if check and done.returncode != 0:
        raise NetnsError(f'{" ".join(args)} failed ({done.returncode}): '
                         f'{(done.stderr or done.stdout).strip()}')
    return done


@dataclass(frozen=True)
class TwoHosts:
    """A fish host and a shore host joined by one veth pair (see the module docstring)."""

    token: str
    subnet: int = 0

    def __post_init__(self) -> None:
        """Refuse names that would not fit or addresses outside 10.213.0.0/16."""
        if not _TOKEN.match(self.token):
            raise ValueError(f'token {self.token!r}: 1 to 8 lower-case letters or digits')
        if not 0 <= self.subnet <= 255:
            raise ValueError(f'subnet {self.subnet}: 0 to 255 (10.213.<subnet>.0/24)')

    def namespace(self, side: Role) -> str:
        """Return the network namespace of ``side`` (Role.FISH or Role.SHORE)."""
        return f'wf{self.token}{"f" if side == Role.FISH else "s"}'

    def device(self, side: Role) -> str:
        """Return the veth end inside ``side``'s namespace."""
        return f'wf{self.token}{"a" if side == Role.FISH else "b"}'

    def address(self, side: Role) -> str:
        """Return the IPv4 address of ``side``."""
        return f'10.213.{self.subnet}.{1 if side == Role.FISH else 2}'

    @staticmethod
    def other(side: Role) -> Role:
        """Return the other side."""
        return Role.SHORE if side == Role.FISH else Role.FISH

    def exec_prefix(self, side: Role) -> list[str]:
        """Return the command prefix that runs a program on ``side``'s host."""
        return ['ip', 'netns', 'exec', self.namespace(side)]

    def ros_environment(self, side: Role, discovery: str = Discovery.MULTICAST
                        ) -> dict[str, str]:
        """
        Return the DDS settings of ``side``'s processes.

        ``discovery`` MULTICAST: ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET (each participant
        announces itself to one multicast group); STATIC: LOCALHOST plus ROS_STATIC_PEERS=<the
        other host> (unicast, for links that carry no multicast; Fast DDS then announces every
        participant to each participant port the peer may use, see the README's figures).
        """
        if discovery not in tuple(Discovery):
            raise ValueError(f'discovery {discovery!r}: {Discovery.MULTICAST} or '
                             f'{Discovery.STATIC}')
        env = {'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4', 'ROS_STATIC_PEERS': ''}
        if discovery == Discovery.MULTICAST:
            return {**env, 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SUBNET'}
        return {**env, 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
                'ROS_STATIC_PEERS': self.address(self.other(side))}

    def create(self) -> None:
        """Make both namespaces, the veth pair between them, addresses, routes; bring all up."""
        try:
            for side in SIDES:
                _run('ip', 'netns', 'add', self.namespace(side))
            _run('ip', 'link', 'add', self.device(Role.FISH), 'netns', self.namespace(Role.FISH),
                 'type', 'veth', 'peer', 'name', self.device(Role.SHORE),
                 'netns', self.namespace(Role.SHORE))
            for side in SIDES:
                ns = self.namespace(side)
                _run('ip', '-n', ns, 'addr', 'add', f'{self.address(side)}/24',
                     'dev', self.device(side))
                _run('ip', '-n', ns, 'link', 'set', 'lo', 'up')
                _run('ip', '-n', ns, 'link', 'set', self.device(side), 'up')
                self._route_multicast(side)
        except NetnsError:
            self.remove()
            raise

    def remove(self) -> None:
        """Delete both namespaces (their veth ends go with them); what is not there is skipped."""
        for side in SIDES:
            _run('ip', 'netns', 'delete', self.namespace(side), check=False)

    def exists(self) -> list[str]:
        """Return which of this pair's namespaces exist now."""
        listed = _run('ip', 'netns', 'list').stdout.split()
        return [self.namespace(s) for s in SIDES if self.namespace(s) in listed]

    def _route_multicast(self, side: Role) -> None:
        # A real host sends multicast along its default route; a fresh namespace has only the
        # veth's subnet route, so every multicast send fails (ENETUNREACH) and Fast DDS
        # discovers nothing across the pair, with static peers too (its participant announces
        # multicast locators). The kernel drops this route when the link goes down.
        _run('ip', '-n', self.namespace(side), 'route', 'replace', MULTICAST_ROUTE,
             'dev', self.device(side))

    def _set_links(self, state: str) -> None:
        for side in SIDES:
            _run('ip', '-n', self.namespace(side), 'link', 'set', self.device(side), state)
            if state == 'up':
                self._route_multicast(side)

    def cut(self) -> None:
        """Set both veth ends down: nothing crosses (the radio is gone)."""
        self._set_links('down')

    def restore(self) -> None:
        """Set both veth ends up again; the subnet route returns by itself, multicast's here."""
        self._set_links('up')

    def shape(self, rate: str = '100kbit', burst: str = '16kbit', latency: str = '400ms'
              ) -> None:
        """Limit both ends' egress with a token bucket (tc tbf): a Bluetooth-like serial link."""
        for side in SIDES:
            _run('ip', 'netns', 'exec', self.namespace(side), 'tc', 'qdisc', 'replace', 'dev',
                 self.device(side), 'root', 'tbf', 'rate', rate, 'burst', burst,
                 'latency', latency)

    def unshape(self) -> None:
        """Remove the token-bucket limits (back to the veth's own qdisc)."""
        for side in SIDES:
            _run('ip', 'netns', 'exec', self.namespace(side), 'tc', 'qdisc', 'del', 'dev',
                 self.device(side), 'root', check=False)

    def qdisc(self, side: Role) -> str:
        """Return `tc -s qdisc show` of ``side``'s veth end (drops, overlimits...)."""
        return _run('ip', 'netns', 'exec', self.namespace(side), 'tc', '-s', 'qdisc', 'show',
                    'dev', self.device(side)).stdout

    def tx_bytes(self, side: Role) -> int:
        """Return the bytes ``side``'s veth end has transmitted (towards the other side)."""
        out = _run('ip', '-n', self.namespace(side), '-j', '-s', 'link', 'show',
                   'dev', self.device(side)).stdout
        return int(json.loads(out)[0]['stats64']['tx']['bytes'])
