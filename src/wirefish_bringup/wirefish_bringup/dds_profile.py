# SPDX-License-Identifier: Apache-2.0
"""
The workspace's Fast DDS profile (config/fastdds.xml), its transports, and the environment.

rmw_fastrtps reads ``FASTRTPS_DEFAULT_PROFILES_FILE`` when a process creates its first
participant; the profile makes the reply writers of the tuner's and the CPG's services wait for
a new client's reader instead of dropping the answer (the file says which and why). rmw looks a
reply writer's profile up by its topic's full name, so a profile covers given namespaces only:
the installed file covers ``/wirefish`` and the root namespace (``ros2 run`` without one), and
`wirefish up` in any other namespace (a test's, a fleet's ``/fish_<i>``) writes one for its own
namespaces into the run's directory (``graph_environment``). ``render_profile`` makes both;
for ``ros2 launch`` in another namespace:
``python3 -m wirefish_bringup.dds_profile /fish_1 > fastdds.xml``.

Over a radio (``wirefish up --role fish|shore``) the graph's own profile also has a default
participant that announces itself every ANNOUNCE_S (lease LEASE_S) instead of Fast DDS's 3 s
(20 s): the fish's and the shore's participants announcing to each other every 3 s saturated a
100 kbit/s radio (test/launcher/test_two_hosts.py: fish->shore 12.4 kB/s and 26-41 packets
dropped by the bucket in 13 s; every 10 s: 7.5 kB/s, 0-5 dropped). A 10 s radio cut stays
inside the lease. That participant names its UDPv4 transport itself: a default participant
profile otherwise brings the builtin transports (shared memory) back. On one host (role all)
the participant keeps Fast DDS's announcements: there a 10 s period slowed discovery (a full
run: topics and an action not found in their tests' time).

Why no shared memory: with it, a publisher whose subscriber was SIGKILLed and restarted stalls in
``publish()``: the writer reopens the dead reader's shared-memory port and waits out the port's
health check (``healthy_check_timeout_ms``, 1000 ms by default). Measured here
(tools/probes/kill_stall_probe.py, a 100 Hz publisher, 12 kills of a subscriber): with shared
memory its longest publish took 1001 ms (twice, and 334 ms twice), over UDP 6 ms. A CPG stalled
that long starves the bridge past its 500 ms command timeout and the fish goes neutral; messages in
flight to the recorder were lost with it. Loopback UDP costs a copy per reader, which the graph's
small messages afford. A value the user already set, for either variable (even empty), is kept.

Every participant's receiving sockets hold LISTEN_BUFFER_BYTES (the kernel's default is 208 KiB,
and Linux caps a request at ``net.core.rmem_max``: a smaller cap is used as it is). A process
whose receive thread the machine starves for a moment finds its datagrams queued in the socket,
not dropped: a `wirefish record` stopped (SIGSTOP) for 0.6 s and 1 s beside the graph lost 126
of each 100 Hz stream's messages at the kernel's default (912 datagrams dropped by its socket)
and none with 4 MiB. On one host the buffer is the default participant's only setting
(``listenSocketBufferSize``, for the builtin transports that ``FASTDDS_BUILTIN_TRANSPORTS``
still chooses); a participant that names its UDPv4 transport sets it on that transport.

``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` brings shared memory back whatever
``FASTDDS_BUILTIN_TRANSPORTS`` or a participant profile says: each process of a graph started with
it mapped 8 of Fast DDS's shared-memory segments (a private /dev/shm, 10 listeners and a talker),
and one Ctrl-C of such a graph took over 3 s in 8 of 50 rounds, a node's stop waiting on a dying
peer's shared-memory port (tools/probes/sigint_soak.py). So the workspace honours LOCALHOST
(without ROS_STATIC_PEERS) as loopback-only UDPv4: a default participant whose UDPv4 transport
sends and listens on 127.0.0.1 only, and rmw's SYSTEM_DEFAULT range so that rmw leaves it alone
(config/fastdds_loopback.xml, or a graph's own profile). Nothing leaves the host, as with
LOCALHOST, and no segment is mapped. A participant that kept LOCALHOST (a `ros2` CLI call, a test's
own node) still discovers and talks to such a graph, over UDP.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

from ament_index_python.packages import get_package_share_directory

PROFILES_VARIABLE = 'FASTRTPS_DEFAULT_PROFILES_FILE'
PROFILE_FILE_NAME = 'fastdds.xml'
LOOPBACK_PROFILE_FILE_NAME = 'fastdds_loopback.xml'
RANGE_VARIABLE = 'ROS_AUTOMATIC_DISCOVERY_RANGE'
STATIC_PEERS_VARIABLE = 'ROS_STATIC_PEERS'
LOCALHOST = 'LOCALHOST'
SYSTEM_DEFAULT = 'SYSTEM_DEFAULT'
LOOPBACK_ADDRESS = '127.0.0.1'
TRANSPORTS_VARIABLE = 'FASTDDS_BUILTIN_TRANSPORTS'
TRANSPORTS = 'UDPv4'
INSTALLED_NAMESPACES = ('/wirefish', '/')
# Servers whose executor can afford to wait for a new client's reader: the tuner (a
# multi-threaded executor) and the CPG (its oscillator runs on a loop thread of its own). Not
# the bridge: its executor ticks the servo commands, and the fish goes neutral after 500 ms.
WAITING_SERVICES = ('retune_gait', 'retune_gait/_action/send_goal',
                    'retune_gait/_action/cancel_goal', 'retune_gait/_action/get_result',
                    'start', 'stop', 'cpg_node/follow_commands')
WAITING_PARAMETER_SERVERS = ('tuner_node', 'cpg_node')
PARAMETER_SERVICES = ('set_parameters', 'set_parameters_atomically', 'get_parameters',
                      'get_parameter_types', 'list_parameters', 'describe_parameters',
                      'get_type_description')
REPLY_WAIT_S = 5
# 20 s of the graph's ~400 datagrams a second (a datagram costs its socket ~1 KiB); memory is
# taken only while datagrams wait.
LISTEN_BUFFER_BYTES = 4 * 1024 * 1024
LEASE_S = 30
ANNOUNCE_S = 10

_HEADER = """<?xml version="1.0" encoding="UTF-8"?>
<!--
  Fast DDS profile of the wirefish graph (rmw_fastrtps_cpp, Jazzy: Fast DDS 2.14), made by
  wirefish_bringup.dds_profile.render_profile for the namespaces {namespaces}.

  rmw_fastrtps answers a request only once the server's reply writer has matched the client's
  reply reader, waiting at most the writer's reliability max_blocking_time (100 ms by default)
  and otherwise dropping the answer ("client will not receive response"). A fresh client (one
  `ros2 service call`, `ros2 param set`, `ros2 action send_goal`) or a server that has just
  (re)started can need longer than that on a loaded machine. The reply writers below wait up
  to {wait} s: the wait ends as soon as the reader matches, and holds only the executor thread
  answering that request. Only servers whose executor can afford it are listed: the tuner (a
  multi-threaded executor) and the CPG (its oscillator runs on its own loop thread). Not the
  bridge: its executor ticks the servo commands, and the fish goes neutral after 500 ms without.

  Every participant's receiving sockets hold {buffer} bytes (the kernel's default is 212992;
  net.core.rmem_max caps it): a process the machine starves for a moment finds its datagrams
  queued, not dropped.

{radio}{loopback}\
  rmw_fastrtps looks a reply writer's profile up by its topic name, rr<service name>Reply.
  Loaded through FASTRTPS_DEFAULT_PROFILES_FILE (wirefish up, the launch file,
  tools/activate.sh).
-->
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
"""
_WRITER = """    <data_writer profile_name="{name}">
      <qos><reliability><max_blocking_time><sec>{wait}</sec></max_blocking_time></reliability></qos>
    </data_writer>
"""
_RADIO = """  Over a radio (role fish or shore) the default participant: UDPv4 only, and discovery
  announcements every {announce} s with a {lease} s lease (every 3 s with 20 s by default: the
  fish's and the shore's participants announcing to each other saturated a 100 kbit/s radio).

"""
_LOOPBACK = """\
  On one host with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST: the default participant sends and
  listens on {address} only, over UDPv4 (rmw's LOCALHOST would bring shared memory back); the
  processes run with ROS_AUTOMATIC_DISCOVERY_RANGE=SYSTEM_DEFAULT so that rmw keeps it.

"""
_TRANSPORTS = """    <transport_descriptors>
      <transport_descriptor>
        <transport_id>wirefish_udp</transport_id>
        <type>UDPv4</type>
        <receiveBufferSize>{buffer}</receiveBufferSize>
{whitelist}      </transport_descriptor>
    </transport_descriptors>
"""
_PARTICIPANT = """    <participant profile_name="wirefish_participant" is_default_profile="true">
      <rtps>
        <userTransports><transport_id>wirefish_udp</transport_id></userTransports>
        <useBuiltinTransports>false</useBuiltinTransports>
{builtin}      </rtps>
    </participant>
"""
_BUFFER_PARTICIPANT = """\
    <participant profile_name="wirefish_participant" is_default_profile="true">
      <rtps>
        <listenSocketBufferSize>{buffer}</listenSocketBufferSize>
      </rtps>
    </participant>
"""
_WHITELIST = """        <interfaceWhiteList><address>{address}</address></interfaceWhiteList>
"""
_ANNOUNCEMENTS = """        <builtin>
          <discovery_config>
            <leaseDuration><sec>{lease}</sec></leaseDuration>
            <leaseAnnouncement><sec>{announce}</sec></leaseAnnouncement>
          </discovery_config>
        </builtin>
"""
_FOOTER = """  </profiles>
</dds>
"""


def profile_path(loopback: bool = False) -> Path:
    """Return the installed profile file (the loopback one for LOCALHOST)."""
    return Path(get_package_share_directory('wirefish_bringup'), 'config',
                LOOPBACK_PROFILE_FILE_NAME if loopback else PROFILE_FILE_NAME)


def on_loopback(env: Mapping[str, str]) -> bool:
    """
    Return whether ``env`` asks for one host only.

    LOCALHOST without static peers, or the installed loopback profile (tools/activate.sh
    names it for LOCALHOST).
    """
    return ((env.get(RANGE_VARIABLE) == LOCALHOST and not env.get(STATIC_PEERS_VARIABLE))
            or env.get(PROFILES_VARIABLE) == str(profile_path(loopback=True)))


def reply_writer_names(namespace: str) -> list[str]:
    """Return the reply topics of the waiting services in ``namespace`` (absolute)."""
    prefix = namespace.rstrip('/')
    services = [*WAITING_SERVICES,
                *(f'{node}/{service}' for node in WAITING_PARAMETER_SERVERS
                  for service in PARAMETER_SERVICES)]
    return [f'rr{prefix}/{service}Reply' for service in services]


def render_profile(namespaces: Iterable[str], radio: bool = False,
                   loopback: bool = False) -> str:
    """
    Return the profile XML: reply writers of ``namespaces`` and the default participant.

    ``radio``: one side of a radio link (slow announcements); ``loopback``: one host over
    loopback UDPv4 (``on_loopback``). Either names the participant's UDPv4 transport itself.
    """
    chosen = list(dict.fromkeys(namespaces))
    writers = ''.join(_WRITER.format(name=name, wait=REPLY_WAIT_S)
                      for namespace in chosen for name in reply_writer_names(namespace))
    participant = _BUFFER_PARTICIPANT.format(buffer=LISTEN_BUFFER_BYTES)
    if radio or loopback:
        whitelist = _WHITELIST.format(address=LOOPBACK_ADDRESS) if loopback else ''
        builtin = (_ANNOUNCEMENTS.format(lease=LEASE_S, announce=ANNOUNCE_S)
                   if radio else '')
        participant = (_TRANSPORTS.format(whitelist=whitelist, buffer=LISTEN_BUFFER_BYTES)
                       + _PARTICIPANT.format(builtin=builtin))
    header = _HEADER.format(
        namespaces=', '.join(chosen), wait=REPLY_WAIT_S, buffer=LISTEN_BUFFER_BYTES,
        radio=_RADIO.format(lease=LEASE_S, announce=ANNOUNCE_S) if radio else '',
        loopback=_LOOPBACK.format(address=LOOPBACK_ADDRESS) if loopback else '')
    return header + participant + writers + _FOOTER


def _installed(path: str | None) -> bool:
    return path in (str(profile_path()), str(profile_path(loopback=True)))


def with_profile(env: Mapping[str, str]) -> dict[str, str]:
    """
    Return ``env`` with the installed profile and transports, unless it sets them already.

    LOCALHOST (``on_loopback``) with no profile of the user's: the loopback profile and the
    SYSTEM_DEFAULT range that keeps it.
    """
    result = dict(env)
    result.setdefault(TRANSPORTS_VARIABLE, TRANSPORTS)
    chosen = result.setdefault(PROFILES_VARIABLE, str(profile_path()))
    if _installed(chosen):
        loopback = on_loopback(env)
        result[PROFILES_VARIABLE] = str(profile_path(loopback))
        if loopback:
            result[RANGE_VARIABLE] = SYSTEM_DEFAULT
    return result


def graph_environment(env: Mapping[str, str], namespaces: Iterable[str], run_dir: Path,
                      radio: bool = False) -> tuple[dict[str, str], str | None]:
    """
    Return ``env`` for a graph in ``namespaces``, and the profile it needs of its own, if any.

    When the user set no profile and the installed one does not fit (a namespace it does not
    cover, or ``radio``: one side of a radio link), the environment names
    ``run_dir``/fastdds.xml and the second value is that file's text: ``write_profile`` writes
    it once the graph really starts (a refused start leaves no run directory).
    """
    chosen = set(namespaces)
    # tools/activate.sh names the installed profile: that is the workspace's, not the user's.
    if not _installed(env.get(PROFILES_VARIABLE, str(profile_path()))) or (
            chosen <= set(INSTALLED_NAMESPACES) and not radio):
        return with_profile(env), None
    loopback = on_loopback(env) and not radio
    path = Path(run_dir) / PROFILE_FILE_NAME
    own = {**env, PROFILES_VARIABLE: str(path)}
    if loopback:
        own[RANGE_VARIABLE] = SYSTEM_DEFAULT
    return (with_profile(own),
            render_profile(sorted(chosen), radio=radio, loopback=loopback))


def write_profile(env: Mapping[str, str], text: str | None) -> None:
    """Write a graph's own profile ``text`` (if any) where ``env`` names it."""
    if text is None:
        return
    path = Path(env[PROFILES_VARIABLE])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def main(argv: list[str] | None = None) -> int:
    """Print the profile of the namespaces given on the command line."""
    import sys
    from wirefish_bringup.graph import validate_namespace
    names = sys.argv[1:] if argv is None else argv
    if not names:
        print('usage: python3 -m wirefish_bringup.dds_profile NAMESPACE [NAMESPACE ...]',
              file=sys.stderr)
        return 2
    try:
        namespaces = [validate_namespace(name) for name in names]
    except ValueError as error:
        print(f'dds_profile: {error}', file=sys.stderr)
        return 2
    sys.stdout.write(render_profile(namespaces))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
