# SPDX-License-Identifier: Apache-2.0
"""The Foxglove/Lichtblick layout shows the dashboard's panels, on topics the view offers."""

import json
from pathlib import Path
import re

import pytest

LAYOUT = json.loads((Path(__file__).resolve().parents[1] / 'layouts' / 'wirefish.json')
                    .read_text())
NAMESPACE = '/wirefish'
# What the view offers under the default namespace: the registry's topics, its own channels
# and services (view_node's docstring, README's table).
OFFERED = {'servo_cmd', 'servo_state', 'body_wave', 'body_wave_markers', 'planner_state',
           'speed_estimate', 'sim/ground_truth', 'battery', 'cmd_vel', 'view/scene',
           'view/retune', 'start', 'stop', 'retune_gait'}
GLOBAL = {'/diagnostics', '/tf', '/tf_static'}


def _panels(tree) -> set[str]:
    if isinstance(tree, str):
        return {tree}
    return _panels(tree['first']) | _panels(tree['second'])


def _names(config: dict) -> set[str]:
    """Return every topic or service a panel's config names (message paths cut at the field)."""
    found = set()
    for key, value in config.items():
        if key in ('topic', 'topicPath', 'serviceName', 'path', 'topicToRender'):
            found.add(value)
        elif key == 'paths':
            found |= {p['value'] for p in value}
        elif key == 'xAxisPath':
            found.add(value['value'])
        elif key == 'topics':
            found |= set(value)
    return {re.split(r'\.[a-z_]', name, maxsplit=1)[0] for name in found if name}


def test_every_panel_is_in_the_layout_and_the_layout_has_no_other():
    assert _panels(LAYOUT['layout']) == set(LAYOUT['configById'])


@pytest.mark.parametrize('kind, count', [
    ('3D', 1), ('Plot', 4), ('Indicator', 1), ('DiagnosticSummary', 1), ('Teleop', 1),
    ('CallService', 2), ('RawMessages', 2)])
def test_the_dashboards_panels_are_there(kind, count):
    assert sum(p.split('!')[0] == kind for p in LAYOUT['configById']) == count


def test_every_name_a_panel_uses_is_offered_by_the_view():
    for panel, config in LAYOUT['configById'].items():
        for name in _names(config):
            relative = name[len(NAMESPACE) + 1:] if name.startswith(NAMESPACE + '/') else None
            assert name in GLOBAL or relative in OFFERED, (panel, name)


def test_the_teleop_panel_stays_within_the_drive_limits():
    teleop = LAYOUT['configById']['Teleop!drive']
    values = {b: teleop[b]['value'] for b in ('upButton', 'downButton', 'leftButton',
                                              'rightButton')}
    assert 0.0 <= values['upButton'] <= 0.4 and values['downButton'] >= 0.0
    assert all(abs(values[b]) <= 0.6 for b in ('leftButton', 'rightButton'))
