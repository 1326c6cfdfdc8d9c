# SPDX-License-Identifier: Apache-2.0
"""
Missions: timed cmd_vel legs read from YAML (pure; no rclpy).

A mission file::

    name: square
    rest_s: 2.0          # cmd_vel 0 before the first leg (the fish at rest), default 2
    coast_s: 6.0         # recorded after the last leg with no cmd_vel (the fish stops), default 6
    legs:
      - {duration_s: 8.0, speed: 0.2}                 # m/s, straight (heading held)
      - {duration_s: 5.236, speed: 0.2, yaw_rate: 0.3}  # rad/s, + turns left (REP-103)
      - {repeat: 3}      # optional: the legs so far, repeated 3 more times

Every value is checked (finite, speed >= 0, duration > 0) and a bad file is refused with the
leg and field named.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path

import yaml

LEG_FIELDS = {'duration_s', 'speed', 'yaw_rate'}


@dataclass(frozen=True)
class MissionLeg:
    """cmd_vel (speed m/s, yaw rate rad/s) held for ``duration_s``."""

    duration_s: float
    speed: float
    yaw_rate: float = 0.0


@dataclass(frozen=True)
class Mission:
    """A named list of legs, with rest before and coasting after (s)."""

    name: str
    legs: tuple[MissionLeg, ...]
    rest_s: float = 2.0
    coast_s: float = 6.0

    @property
    def duration_s(self) -> float:
        """Return the time from the first leg's start to the last leg's end (s)."""
        return sum(leg.duration_s for leg in self.legs)

    def command_at(self, t: float) -> tuple[float, float] | None:
        """Return the (speed, yaw rate) of the leg at ``t`` s after the first leg's start."""
        if t < 0.0:
            return (0.0, 0.0)
        start = 0.0
        for leg in self.legs:
            if t < start + leg.duration_s:
                return (leg.speed, leg.yaw_rate)
            start += leg.duration_s
        return None  # the mission is over: no more cmd_vel

    def leg_starts(self) -> list[float]:
        """Return each leg's start time (s after the first leg's start)."""
        starts, t = [], 0.0
        for leg in self.legs:
            starts.append(t)
            t += leg.duration_s
        return starts


def _number(where: str, name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not math.isfinite(value):
        raise ValueError(f'{where}: {name} must be a finite number, got {value!r}')
    return float(value)


def mission_from(data: object, default_name: str = 'mission') -> Mission:
    """Return the Mission of parsed YAML ``data``; raise ValueError naming what is wrong."""
    if not isinstance(data, dict) or not isinstance(data.get('legs'), list) or \
            not data['legs']:
        raise ValueError('a mission is a mapping with a non-empty list "legs"')
    legs: list[MissionLeg] = []
    for index, entry in enumerate(data['legs'], start=1):
        where = f'leg {index}'
        if isinstance(entry, dict) and set(entry) == {'repeat'}:
            count = entry['repeat']
            if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= 100:
                raise ValueError(f'{where}: repeat must be an integer in [1, 100], got {count!r}')
            legs = legs * (count + 1)
            continue
        if not isinstance(entry, dict) or not {'duration_s', 'speed'} <= set(entry) or \
                set(entry) - LEG_FIELDS:
            raise ValueError(f'{where}: needs duration_s and speed (and optionally yaw_rate), '
                             f'got {entry!r}')
        duration = _number(where, 'duration_s', entry['duration_s'])
        speed = _number(where, 'speed', entry['speed'])
        yaw_rate = _number(where, 'yaw_rate', entry.get('yaw_rate', 0.0))
        if duration <= 0.0:
            raise ValueError(f'{where}: duration_s must be > 0, got {duration:g}')
        if speed < 0.0:
            raise ValueError(f'{where}: speed must be >= 0 (the fish cannot swim backwards), '
                             f'got {speed:g}')
        legs.append(MissionLeg(duration, speed, yaw_rate))
    extra = {}
    for name in ('rest_s', 'coast_s'):
        if name in data:
            extra[name] = _number('mission', name, data[name])
            if extra[name] < 0.0:
                raise ValueError(f'mission: {name} must be >= 0, got {extra[name]:g}')
    name = data.get('name', default_name)
    if not isinstance(name, str) or not name:
        raise ValueError(f'mission: name must be a non-empty string, got {name!r}')
    return Mission(name, tuple(legs), **extra)


def load_mission(path: Path) -> Mission:
    """Return the mission of a YAML file; raise ValueError (with the file) if it is invalid."""
    try:
        data = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as error:
        raise ValueError(f'{path}: {error}') from error
    try:
        return mission_from(data, Path(path).stem)
    except ValueError as error:
        raise ValueError(f'{path}: {error}') from error
