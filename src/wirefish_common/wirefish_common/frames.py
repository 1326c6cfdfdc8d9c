# SPDX-License-Identifier: Apache-2.0
"""
Frame ids that carry the fish's name: the ``frame_prefix`` parameter.

Several fish in one TF tree (a fleet, one RViz) need distinct frames: with ``frame_prefix``
``fish_1`` a node writes ``fish_1/base_link`` where a lone fish writes ``base_link`` (the
tf_prefix convention: prefix, slash, frame). The prefix is fixed at start-up (read-only): a
frame that changed its name mid-run would break every transform already published under it.
"""

from __future__ import annotations

import re

FRAME_PREFIX = 'frame_prefix'
_PREFIX_PATTERN = re.compile(r'^[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*$')
DESCRIPTION = ('Prefix of every frame id this node writes (fish_1 -> fish_1/base_link), so '
               'several fish fit in one TF tree; empty: none. Read-only')


def frame_prefix_problem(prefix: object) -> str | None:
    """Return why ``prefix`` cannot prefix frame ids, or None (empty means no prefix)."""
    if not isinstance(prefix, str):
        return f'{FRAME_PREFIX} must be a string, got {prefix!r}'
    if prefix and not _PREFIX_PATTERN.match(prefix.rstrip('/')):
        return (f'{FRAME_PREFIX} {prefix!r}: use letters, digits and _, tokens separated by /, '
                'each starting with a letter (e.g. fish_1)')
    return None


def prefixed(prefix: str, frame: str) -> str:
    """Return ``frame`` under ``prefix`` (``fish_1``, ``base_link`` -> ``fish_1/base_link``)."""
    prefix = prefix.rstrip('/')
    return f'{prefix}/{frame}' if prefix else frame


def declare_frame_prefix(node) -> str:
    """
    Declare the read-only ``frame_prefix`` parameter on ``node``; return its start-up value.

    Raises ``InvalidParameters`` (one line naming node and value) when it is not a valid prefix.
    """
    from rcl_interfaces.msg import ParameterDescriptor

    from wirefish_common.parameter_table import InvalidParameters

    descriptor = ParameterDescriptor(description=DESCRIPTION, read_only=True)
    value = node.declare_parameter(FRAME_PREFIX, '', descriptor).value
    problem = frame_prefix_problem(value)
    if problem is not None:
        raise InvalidParameters(f'{node.get_name()}: invalid parameter: {problem}')
    return value
