"""The two-host harness without root: names, addresses, DDS settings, the non-root refusal."""

import pytest
from wirefish_bringup.graph import Role
from wirefish_cli.cli import main
from wirefish_launcher import netns
from wirefish_launcher.netns import Discovery, TwoHosts


def test_every_name_carries_the_wf_prefix_and_the_token_and_fits_an_interface_name():
    link = TwoHosts('abc12345', 7)
    names = [link.namespace(Role.FISH), link.namespace(Role.SHORE), link.device(Role.FISH),
             link.device(Role.SHORE)]
    assert all(n.startswith('wfabc12345') and len(n) <= 15 for n in names)
    assert len(set(names)) == 4


def test_the_addresses_are_the_pairs_own_subnet_of_10_213():
    link = TwoHosts('t', 42)
    assert (link.address(Role.FISH), link.address(Role.SHORE)) == ('10.213.42.1', '10.213.42.2')


@pytest.mark.parametrize('token, subnet', [('', 0), ('UPPER', 0), ('toolongtoken', 0),
                                           ('ok', 256), ('ok', -1)])
def test_a_token_or_subnet_that_would_not_fit_is_refused(token, subnet):
    with pytest.raises(ValueError):
        TwoHosts(token, subnet)


def test_static_discovery_names_the_other_host_as_peer_and_stays_local_otherwise():
    env = TwoHosts('t', 3).ros_environment(Role.FISH, Discovery.STATIC)
    assert env['ROS_STATIC_PEERS'] == '10.213.3.2'
    assert env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'


@pytest.mark.parametrize('discovery', [Discovery.MULTICAST, Discovery.STATIC])
def test_both_discoveries_force_udp_so_a_cut_link_cuts(discovery):
    env = TwoHosts('t').ros_environment(Role.SHORE, discovery)
    assert env['FASTDDS_BUILTIN_TRANSPORTS'] == 'UDPv4'


def test_multicast_discovery_clears_any_static_peer_of_the_callers_environment():
    env = TwoHosts('t').ros_environment(Role.SHORE, Discovery.MULTICAST)
    assert env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SUBNET' and env['ROS_STATIC_PEERS'] == ''


def test_wirefish_twohost_says_it_needs_root_and_makes_nothing(monkeypatch, capsys):
    monkeypatch.setattr(netns.os, 'geteuid', lambda: 1000)
    made = []
    monkeypatch.setattr(TwoHosts, 'create', lambda self: made.append(self))
    assert main(['twohost']) == 2
    assert 'only root' in capsys.readouterr().err
    assert made == []
