# SPDX-License-Identifier: Apache-2.0
"""
link_relay's parameters as one table (no rclpy import), and the rule of their combination.

``crossing_file``: the YAML table of the topics that cross to shore, read at start-up
(read-only). ``RULE``: the file loads as a crossing table (``load_crossing``'s reason if not).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from wirefish_common.parameter_table import builds, ParameterSpec, ParameterTable, Rule
from wirefish_relay.crossing import default_crossing_file, load_crossing


def _crossing(values: Mapping[str, Any]) -> object:
    return load_crossing(values['crossing_file'])


RULE: Rule = builds(_crossing)
TABLE = ParameterTable((
    ParameterSpec('crossing_file', str(default_crossing_file()),
                  'YAML table of the topics that cross to shore (see config/crossing.yaml); '
                  'read at start-up', read_only=True),
), RULE)
