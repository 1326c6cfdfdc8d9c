# SPDX-License-Identifier: Apache-2.0
"""
What crosses the fish-shore radio link: the table of config/crossing.yaml (pure, no rclpy).

Each ``CrossingTopic`` is a fish topic the shore sees as a copy under ``shore/`` at a rate of
its own (``link_relay`` publishes it). ``LatestHold`` is the decimation rule: the newest message
since the last send goes out on each tick of the topic's rate, older ones are dropped, and a
tick with nothing new sends nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path
from typing import Any

import yaml

SHORE_PREFIX = 'shore'
QOS_KINDS = ('sensor', 'reliable', 'latched')
CROSSING_FILE_NAME = 'crossing.yaml'


@dataclass(frozen=True)
class CrossingTopic:
    """One relayed topic: fish-side name (relative), type, rate (0: every message), QoS kind."""

    topic: str
    type_name: str
    rate_hz: float
    qos: str

    @property
    def shore_topic(self) -> str:
        """Return the name the shore sees it under (``imu/data`` -> ``shore/imu/data``)."""
        return f'{SHORE_PREFIX}/{self.topic}'


def crossing_topic(row: Any) -> CrossingTopic:
    """Return one row of the table as a CrossingTopic, or raise ValueError saying what is wrong."""
    if not isinstance(row, dict) or set(row) != {'topic', 'type', 'rate_hz', 'qos'}:
        raise ValueError(f'a crossing row needs exactly topic, type, rate_hz and qos: {row!r}')
    topic, type_name, rate, qos = row['topic'], row['type'], row['rate_hz'], row['qos']
    if not isinstance(topic, str) or not topic or topic.startswith(('/', '~')):
        raise ValueError(f'crossing topic {topic!r}: a relative topic name (e.g. imu/data)')
    if not isinstance(type_name, str) or len(type_name.split('/')) != 3:
        raise ValueError(f'{topic}: type {type_name!r} is not like sensor_msgs/msg/Imu')
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (
            math.isfinite(rate) and rate >= 0.0):
        raise ValueError(f'{topic}: rate_hz must be a finite number >= 0, got {rate!r}')
    if qos not in QOS_KINDS:
        raise ValueError(f'{topic}: qos must be one of {", ".join(QOS_KINDS)}, got {qos!r}')
    return CrossingTopic(topic, type_name, float(rate), qos)


def crossing_table(document: Any) -> tuple[CrossingTopic, ...]:
    """Return the ``relayed`` table of a parsed crossing YAML, or raise ValueError."""
    if not isinstance(document, dict) or not isinstance(document.get('relayed'), list):
        raise ValueError('a crossing file holds a list under "relayed"')
    table = tuple(crossing_topic(row) for row in document['relayed'])
    names = [t.topic for t in table]
    if len(names) != len(set(names)):
        raise ValueError(f'a topic is relayed twice: {names}')
    return table


def load_crossing(path: Path | str) -> tuple[CrossingTopic, ...]:
    """Return the table of the crossing file ``path``, or raise ValueError naming the file."""
    try:
        return crossing_table(yaml.safe_load(Path(path).read_text()))
    except (OSError, yaml.YAMLError, ValueError) as error:
        raise ValueError(f'crossing file {path}: {error}') from error


def default_crossing_file() -> Path:
    """Return the installed crossing table."""
    from ament_index_python.packages import get_package_share_directory

    return Path(get_package_share_directory('wirefish_relay'), 'config', CROSSING_FILE_NAME)


class LatestHold:
    """The newest message not yet sent (the decimation of one relayed topic)."""

    def __init__(self) -> None:
        """Start empty."""
        self._latest: Any = None

    def put(self, message: Any) -> None:
        """Keep ``message``, replacing an unsent older one."""
        self._latest = message

    def take(self) -> Any:
        """Return the newest unsent message and forget it, or None if nothing new came."""
        message, self._latest = self._latest, None
        return message
