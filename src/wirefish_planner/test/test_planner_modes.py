# SPDX-License-Identifier: Apache-2.0
"""Every planner mode is documented where PlannerState.mode is read: the message, the README."""

from pathlib import Path
import re

from wirefish_planner import planner_core
from wirefish_planner.planner_core import PlannerMode

SRC = Path(__file__).resolve().parents[2]
MESSAGE = SRC / 'wirefish_msgs' / 'msg' / 'PlannerState.msg'
README = SRC / 'wirefish_planner' / 'README.md'


def _comment_above(field: str) -> str:
    """Return the comment block just above ``field`` in PlannerState.msg, as one line."""
    lines = MESSAGE.read_text().splitlines()
    comment: list[str] = []
    for line in reversed(lines[:lines.index(field)]):
        if not line.startswith('#'):
            break
        comment.insert(0, line.lstrip('#').strip())
    return ' '.join(comment)


def test_the_message_lists_every_mode_and_no_other():
    # 'rest | turn | ... | open_loop (see ...), or manual: the CPG is under a manual override'
    comment = _comment_above('string mode')
    listed = set(re.findall(r'(\w+) \|', comment)) | set(re.findall(r'\| (\w+)', comment))
    listed |= set(re.findall(r', or (\w+):', comment))
    assert listed == {mode.value for mode in PlannerMode}, comment


def test_the_readme_and_the_rules_explain_every_mode():
    modes = next(line for line in README.read_text().split('\n- ')
                 if line.startswith('**Modes**'))
    assert {mode.value for mode in PlannerMode} <= set(re.findall(r'`(\w+)`', modes)), modes
    assert planner_core.__doc__ is not None
    explained = set(re.findall(r'^    ``(\w+)``', planner_core.__doc__, re.MULTILINE))
    assert explained == {mode.value for mode in PlannerMode}
