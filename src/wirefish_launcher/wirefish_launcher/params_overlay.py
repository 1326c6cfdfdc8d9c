# SPDX-License-Identifier: Apache-2.0
"""
The parameter file `wirefish up` gives its nodes: the defaults, the user's file on top of them.

A user's ``--params-file`` names only what it changes (the fish's geometry, one gain): its
values replace the defaults' value by value, key by key, and what it does not name keeps the
installed default (``config/wirefish.yaml``). The result is written once into the run's
directory and every process reads it (the virtual fish too).

A key of a ROS parameter file is a node's fully qualified name, with ``*`` (one token's
characters) and ``/**`` (any number of namespace tokens) as wildcards; a key without a leading
``/`` is read from the root (rcl prepends it), so ``cpg_node:`` matches ``/cpg_node`` only,
never ``/wirefish/cpg_node``. Nothing in ROS says when a key matches no node or a name is no
parameter of the nodes it matches (the value is silently unused): ``unused_entries`` says it,
with the closest name.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
import difflib
import importlib
import re
from typing import Any

PARAMETERS_KEY = 'ros__parameters'
# Where each registry node's parameter table is (module, attribute: its ParameterTable, or a
# function returning ParameterSpecs); the parameters every rclpy node takes are added to all.
PARAMETER_TABLES: dict[str, tuple[str, str]] = {
    'fish_sim': ('wirefish_kinematics.geometry_parameters', 'geometry_parameters'),
    'bridge_node': ('wirefish_bridge.bridge_node_parameters', 'TABLE'),
    'cpg_node': ('wirefish_cpg.cpg_node_parameters', 'TABLE'),
    'kinematics_node': ('wirefish_kinematics.kinematics_node_parameters', 'TABLE'),
    'tf_node': ('wirefish_tf.tf_node_parameters', 'TABLE'),
    'planner_node': ('wirefish_planner.planner_node_parameters', 'TABLE'),
    'tuner_node': ('wirefish_tuner.tuner_node_parameters', 'TABLE'),
    'view_node': ('wirefish_view.view_node_parameters', 'TABLE'),
}
EVERY_NODE = frozenset({'use_sim_time', 'frame_prefix', 'start_type_description_service'})


def overlaid(defaults: Mapping[str, Any], user: Mapping[str, Any]) -> dict[str, Any]:
    """Return ``defaults`` with every value ``user`` names replaced (a key it adds is added)."""
    merged = {key: {PARAMETERS_KEY: dict(block.get(PARAMETERS_KEY) or {})}
              for key, block in defaults.items()}
    for key, block in user.items():
        merged.setdefault(key, {PARAMETERS_KEY: {}})[PARAMETERS_KEY].update(
            block.get(PARAMETERS_KEY) or {})
    return merged


def key_pattern(key: str) -> re.Pattern[str]:
    """Return the regular expression of the node names a parameter-file key matches."""
    name = key if key.startswith('/') else '/' + key
    parts = []
    for token in name.split('/')[1:]:
        if token == '**':
            parts.append('(/[^/]+)*')
        else:
            parts.append('/' + '[^/]*'.join(re.escape(piece) for piece in token.split('*')))
    return re.compile('^' + ''.join(parts) + '$')


def matched_nodes(key: str, node_names: Iterable[str]) -> list[str]:
    """Return the fully qualified node names ``key`` matches."""
    pattern = key_pattern(key)
    return [name for name in node_names if pattern.match(name)]


def declared_parameters(node: str) -> frozenset[str] | None:
    """Return the names node ``node`` (its registry name) declares; None if it is not known."""
    where = PARAMETER_TABLES.get(node)
    if where is None:
        return None
    try:
        table = getattr(importlib.import_module(where[0]), where[1])
    except ImportError:  # a host without that package (a fish has no tuner or view)
        return None
    specs = table() if callable(table) else table
    return frozenset(spec.name for spec in specs) | EVERY_NODE


def unused_entries(user: Mapping[str, Any], node_names: Iterable[str]) -> list[str]:
    """
    Return one warning per key of ``user`` that matches no node and per unknown parameter.

    ``node_names`` are the graph's fully qualified node names (``/wirefish/cpg_node``). A
    parameter is unknown when none of the nodes its key matches declares it.
    """
    nodes = list(node_names)
    warnings = []
    for key, block in user.items():
        matched = matched_nodes(key, nodes)
        if not matched:
            base = key.rstrip('/').rsplit('/', 1)[-1]
            hint = (f"; a key is a node's full name: write /**/{base} to match it in any "
                    'namespace' if any(n.rsplit('/', 1)[-1] == base for n in nodes) else '')
            warnings.append(f'{key!r} matches no node of this graph (its nodes: '
                            f'{", ".join(nodes)}){hint}: its values are not used')
            continue
        known: set[str] = set()
        unknown_tables = False
        for name in matched:
            declared = declared_parameters(name.rsplit('/', 1)[-1])
            if declared is None:
                unknown_tables = True
            else:
                known |= declared
        if unknown_tables:
            continue  # a node whose table is not known here: nothing to judge against
        for parameter in (block.get(PARAMETERS_KEY) or {}):
            if parameter in known:
                continue
            close = difflib.get_close_matches(parameter, sorted(known), n=1)
            hint = f' (did you mean {close[0]}?)' if close else ''
            warnings.append(f'{key}: {parameter!r} is no parameter of '
                            f'{", ".join(n.rsplit("/", 1)[-1] for n in matched)}{hint}: '
                            'it is not used')
    return warnings
