"""
The workspace's Fast DDS profile (config/fastdds.xml), its transports, and the environment.

rmw_fastrtps reads ``FASTRTPS_DEFAULT_PROFILES_FILE`` when a process creates its first
participant; the profile makes the reply writers of the tuner's and the CPG's services wait for
a new client's reader instead of dropping the answer (the file says which and why).

``FASTDDS_BUILTIN_TRANSPORTS=UDPv4`` leaves Fast DDS's shared-memory transport out. With it, a
publisher whose subscriber was SIGKILLed and restarted stalls in ``publish()``: the writer
reopens the dead reader's shared-memory port and waits out the port's health check
(``healthy_check_timeout_ms``, 1000 ms by default). Measured here (tools/kill_stall_probe.py,
a 100 Hz publisher, 12 kills of a subscriber): with shared memory its longest publish took
1001 ms (twice, and 334 ms twice), over UDP 6 ms. A CPG stalled that long starves the bridge
past its 500 ms command timeout and the fish goes neutral; messages in flight to the recorder
were lost with it. Loopback UDP costs a copy per reader, which the graph's small messages
afford. A value the user already set, for either variable (even empty), is kept.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ament_index_python.packages import get_package_share_directory

PROFILES_VARIABLE = 'FASTRTPS_DEFAULT_PROFILES_FILE'
PROFILE_FILE_NAME = 'fastdds.xml'
TRANSPORTS_VARIABLE = 'FASTDDS_BUILTIN_TRANSPORTS'
TRANSPORTS = 'UDPv4'


def profile_path() -> Path:
    """Return the installed profile file."""
    return Path(get_package_share_directory('wirefish_bringup'), 'config', PROFILE_FILE_NAME)


def with_profile(env: Mapping[str, str]) -> dict[str, str]:
    """Return ``env`` with the workspace's profile and transports, unless it sets them already."""
    result = dict(env)
    result.setdefault(PROFILES_VARIABLE, str(profile_path()))
    result.setdefault(TRANSPORTS_VARIABLE, TRANSPORTS)
    return result
