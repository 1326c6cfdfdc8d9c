# SPDX-License-Identifier: Apache-2.0
"""Roles (fish / shore), frame prefixes and fleets, pure."""

from pathlib import Path

import pytest
from wirefish_bringup.fleet import fleet_graph, fleet_namespaces
from wirefish_bringup.graph import entries, fish_graph, Role


def _names(specs):
    return [s.name for s in specs]


def _option(spec, name: str) -> str:
    args = spec.command_arguments()
    return args[args.index(name) + 1]


def test_the_fish_role_holds_what_keeps_the_fish_swimming_and_the_relay():
    assert _names(fish_graph('/w', role=Role.FISH)) == [
        'fish_sim', 'bridge_node', 'cpg_node', 'kinematics_node', 'tf_node', 'planner_node',
        'link_relay']


def test_the_shore_role_holds_the_tuner_and_the_recorder_of_the_shore_copies():
    specs = fish_graph('/w', role=Role.SHORE, bag=Path('/tmp/b'))
    assert _names(specs) == ['tuner_node', 'wirefish_recorder']
    assert _option(specs[-1], '--namespace') == '/w/shore'


def test_both_roles_together_are_the_one_host_graph_without_a_relay():
    together = set(_names(fish_graph('/w')))
    apart = (set(_names(fish_graph('/w', role=Role.FISH)))
             | set(_names(fish_graph('/w', role=Role.SHORE))))
    assert apart - together == {'link_relay'}


def test_an_unknown_role_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match='fish, shore, all'):
        entries(sim=True, role='boat')


def test_a_frame_prefix_goes_to_every_node_that_writes_frames_and_only_those():
    specs = {s.name: s for s in fish_graph('/w', frame_prefix='fish_7')}
    given = {name for name, s in specs.items() if 'frame_prefix:=fish_7' in s.command_arguments()}
    assert given == {'fish_sim', 'bridge_node', 'kinematics_node', 'tf_node'}


def test_no_frame_prefix_passes_no_parameter():
    assert not any('frame_prefix' in ' '.join(s.command_arguments()) for s in fish_graph('/w'))


def test_a_bad_frame_prefix_is_refused_before_anything_starts():
    with pytest.raises(ValueError, match='frame_prefix'):
        fish_graph('/w', frame_prefix='fish-1')


def test_a_fleet_is_one_namespace_and_one_frame_prefix_per_fish():
    specs = fleet_graph('/tank', 3)
    for i in (1, 2, 3):
        mine = [s for s in specs if s.namespace == f'/tank/fish_{i}']
        assert _names(mine) == [n for n in _names(fish_graph('/w')) if n != 'fish_sim']
        bridge = next(s for s in mine if s.name == 'bridge_node')
        assert f'frame_prefix:=fish_{i}' in bridge.command_arguments()
        assert f'port:=/tmp/wirefish-tank_fish_{i}-tty' in bridge.command_arguments()


def test_a_fleets_virtual_fish_are_one_process_first_with_each_fishs_link_and_name():
    specs = fleet_graph('/tank', 3)
    sims = [s for s in specs if s.name == 'fish_sim']
    assert len(sims) == 1 and specs[0] is sims[0] and sims[0].namespace == '/tank'
    args = sims[0].command_arguments()
    links = [args[i + 1] for i, a in enumerate(args) if a == '--link']
    assert links == [f'/tmp/wirefish-tank_fish_{i}-tty' for i in (1, 2, 3)]
    assert [str(link) for link in sims[0].links] == links
    assert [args[i + 1] for i, a in enumerate(args) if a == '--fish'] == [
        'fish_1', 'fish_2', 'fish_3']
    assert '--ros' in args and not any('frame_prefix' in a for a in args)


def test_the_shore_side_of_a_fleet_has_no_virtual_fish():
    assert 'fish_sim' not in _names(fleet_graph('/tank', 2, role=Role.SHORE))


def test_a_fleet_recording_is_one_recorder_of_the_base_namespace():
    specs = fleet_graph('/tank', 2, bag=Path('/tmp/b'))
    recorders = [s for s in specs if s.name == 'wirefish_recorder']
    assert len(recorders) == 1 and _option(recorders[0], '--namespace') == '/tank'


def _everything_named(specs) -> set[str]:
    """Return every namespace and device path the processes of ``specs`` use."""
    named = set()
    for spec in specs:
        args = spec.command_arguments()
        named |= {a.split(':=', 1)[1] for a in args if a.startswith(('__ns:=', 'port:='))}
        named |= {args[i + 1] for i, a in enumerate(args) if a == '--link'}
    return named


def test_two_fleets_share_no_namespace_and_no_virtual_fish_link():
    one, other = _everything_named(fleet_graph('/tank_a', 3)), _everything_named(
        fleet_graph('/tank_b', 3))
    # The base (the virtual fish's), 3 fish namespaces and 3 links each
    assert len(one) == 7 and len(other) == 7
    assert not one & other


@pytest.mark.parametrize('count', [0, 17])
def test_a_fleet_size_outside_its_bounds_is_refused(count):
    with pytest.raises(ValueError, match='fleet'):
        fleet_namespaces('/tank', count)
