"""fish_graph: the one description of a fish's processes that the launcher and launch file use."""

import pytest
from wirefish_bringup.graph import fish_graph, sim_tty_link, validate_namespace


def test_the_virtual_fish_starts_first_and_the_bridge_opens_its_link():
    specs = fish_graph('/tank/fish_1', sim=True, params_file='p.yaml')
    assert [s.executable for s in specs] == [
        'fish_sim', 'bridge_node', 'cpg_node', 'kinematics_node', 'tuner_node']
    link = str(sim_tty_link('/tank/fish_1'))
    assert specs[0].arguments[:2] == ('--link', link)
    assert f'port:={link}' in specs[1].arguments
    for spec in specs:
        assert '__ns:=/tank/fish_1' in spec.arguments
        assert spec.arguments[spec.arguments.index('--params-file') + 1] == 'p.yaml'


def test_a_real_fish_has_no_virtual_fish_and_the_bridge_opens_the_port():
    specs = fish_graph('/wirefish', sim=False, port='/dev/ttyUSB0')
    assert 'fish_sim' not in [s.executable for s in specs]
    assert 'port:=/dev/ttyUSB0' in specs[0].arguments


def test_single_process_is_the_virtual_fish_and_one_composed_process():
    specs = fish_graph('/wirefish', sim=True, single_process=True)
    assert [s.name for s in specs] == ['fish_sim', 'fish_nodes']


@pytest.mark.parametrize('sim, port, reason', [
    (False, None, 'needs its serial port'),
    (True, '/dev/ttyUSB0', 'choose sim or a port'),
])
def test_contradictory_targets_are_refused(sim, port, reason):
    with pytest.raises(ValueError, match=reason):
        fish_graph('/wirefish', sim=sim, port=port)


@pytest.mark.parametrize('given, normalised', [('wirefish', '/wirefish'), ('/a/b/', '/a/b'),
                                               ('/', '/')])
def test_namespaces_are_normalised(given, normalised):
    assert validate_namespace(given) == normalised


@pytest.mark.parametrize('bad', ['/1fish', '/a//b', '/fish-1', '/a b'])
def test_invalid_namespaces_are_refused(bad):
    with pytest.raises(ValueError, match='invalid ROS namespace'):
        validate_namespace(bad)
