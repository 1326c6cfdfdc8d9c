"""
The workspace's Fast DDS profile (config/fastdds.xml) and the environment that loads it.

rmw_fastrtps reads ``FASTRTPS_DEFAULT_PROFILES_FILE`` when a process creates its first
participant; the profile makes the reply writers of the tuner's and the CPG's services wait for
a new client's reader instead of dropping the answer (the file says which and why). A value the
user already set (even empty: no profile) is kept.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ament_index_python.packages import get_package_share_directory

PROFILES_VARIABLE = 'FASTRTPS_DEFAULT_PROFILES_FILE'
PROFILE_FILE_NAME = 'fastdds.xml'


def profile_path() -> Path:
    """Return the installed profile file."""
    return Path(get_package_share_directory('wirefish_bringup'), 'config', PROFILE_FILE_NAME)


def with_profile(env: Mapping[str, str]) -> dict[str, str]:
    """Return ``env`` with the workspace's profile, unless it names one (or none) already."""
    result = dict(env)
    result.setdefault(PROFILES_VARIABLE, str(profile_path()))
    return result
