# SPDX-License-Identifier: Apache-2.0
"""The two-host harness without root: names, addresses, each side's start, the root check."""

import pytest
from wirefish_bringup.graph import Role
from wirefish_cli.cli import main
from wirefish_launcher import netns
from wirefish_launcher.netns import Discovery, SIDES, TwoHosts
from wirefish_launcher.verb import twohost


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


class _Side:
    """A stand-in for one side's `wirefish up` process: running until stopped, then 0."""

    def __init__(self, args, env, **_popen) -> None:
        self.args, self.env, self.pid, self.returncode = args, env, 0, None

    def poll(self):
        return self.returncode

    def wait(self, timeout=None) -> int:
        self.returncode = 0
        return 0


@pytest.fixture
def started_sides(monkeypatch, capsys):
    """
    Return ``start(discovery)``: run `wirefish twohost` with the pair and its processes stood in.

    It returns each side's stand-in process (its command line and environment), the caller's
    environment holding the settings that would defeat the pair: shared memory on, a static peer
    and localhost-only discovery.
    """
    monkeypatch.setattr(twohost, 'root_problem', lambda: None)
    for action in ('create', 'remove', 'shape'):
        monkeypatch.setattr(TwoHosts, action, lambda self, *args: None)
    sides = []
    monkeypatch.setattr(twohost.subprocess, 'Popen',
                        lambda args, env, **kwargs: sides.append(_Side(args, env, **kwargs))
                        or sides[-1])
    monkeypatch.setattr(twohost.os, 'killpg', lambda pid, signum: None)
    monkeypatch.setattr(twohost.signal, 'signal', lambda signum, handler: None)
    monkeypatch.setenv('FASTDDS_BUILTIN_TRANSPORTS', 'SHM')
    monkeypatch.setenv('ROS_STATIC_PEERS', '192.0.2.7')
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

    def start(discovery: Discovery) -> dict[Role, _Side]:
        assert main(['twohost', '--token', 't', '--subnet', '3', '--discovery', discovery,
                     '--duration', '0.01']) == 0, capsys.readouterr().err
        return dict(zip(SIDES, sides, strict=True))

    return start


def test_each_side_runs_wirefish_up_in_its_role_inside_its_own_network_namespace(
        started_sides):
    link = TwoHosts('t', 3)
    for side, proc in started_sides(Discovery.MULTICAST).items():
        assert proc.args[:4] == ['ip', 'netns', 'exec', link.namespace(side)], side
        assert proc.args[proc.args.index('--role') + 1] == side


@pytest.mark.parametrize('discovery', list(Discovery))
def test_no_side_inherits_the_callers_shared_memory_so_a_cut_link_cuts(started_sides,
                                                                       discovery):
    # Both network namespaces see one /dev/shm: Fast DDS's shared-memory transport would carry
    # data past the veth pair.
    for side, proc in started_sides(discovery).items():
        assert 'SHM' not in proc.env['FASTDDS_BUILTIN_TRANSPORTS'], side


def test_multicast_discovery_reaches_the_subnet_and_drops_the_callers_static_peer(
        started_sides):
    for side, proc in started_sides(Discovery.MULTICAST).items():
        assert proc.env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SUBNET', side
        assert proc.env['ROS_STATIC_PEERS'] == '', side


def test_static_discovery_gives_each_side_the_other_host_as_its_only_peer(started_sides):
    link = TwoHosts('t', 3)
    for side, proc in started_sides(Discovery.STATIC).items():
        assert proc.env['ROS_STATIC_PEERS'] == link.address(TwoHosts.other(side)), side
        assert proc.env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST', side  # no multicast


def test_wirefish_twohost_says_it_needs_root_and_makes_nothing(monkeypatch, capsys):
    monkeypatch.setattr(netns.os, 'geteuid', lambda: 1000)
    made = []
    monkeypatch.setattr(TwoHosts, 'create', lambda self: made.append(self))
    assert main(['twohost']) == 2
    assert 'only root' in capsys.readouterr().err
    assert made == []
