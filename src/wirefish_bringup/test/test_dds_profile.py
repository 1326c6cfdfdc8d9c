# SPDX-License-Identifier: Apache-2.0
"""The graph's Fast DDS profile: the installed file, a graph's own, and who wins."""

from pathlib import Path
import xml.etree.ElementTree as ElementTree

import pytest
from wirefish_bringup.dds_profile import (graph_environment, INSTALLED_NAMESPACES,
                                          LISTEN_BUFFER_BYTES, profile_path,
                                          PROFILES_VARIABLE, render_profile,
                                          reply_writer_names, TRANSPORTS_VARIABLE,
                                          with_profile, write_profile)

INSTALLED = Path(__file__).resolve().parents[1] / 'config' / 'fastdds.xml'
NS = '{http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles}'


def _writer_names(xml_text: str) -> list[str]:
    root = ElementTree.fromstring(xml_text)
    return [w.get('profile_name') for w in root.iter(f'{NS}data_writer')]


def test_the_installed_profile_is_the_rendered_one_of_its_namespaces():
    assert INSTALLED.read_text() == render_profile(INSTALLED_NAMESPACES)


def test_the_installed_loopback_profile_is_the_rendered_one_of_its_namespaces():
    loopback = INSTALLED.with_name('fastdds_loopback.xml')
    assert loopback.read_text() == render_profile(INSTALLED_NAMESPACES, loopback=True)


def test_localhost_is_loopback_udp_under_the_range_rmw_leaves_alone():
    env = with_profile({'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'})
    assert env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SYSTEM_DEFAULT'
    assert env[PROFILES_VARIABLE].endswith('fastdds_loopback.xml')
    root = ElementTree.fromstring(Path(env[PROFILES_VARIABLE]).read_text())
    addresses = [e.text for e in root.iter() if e.tag.endswith('address')]
    assert addresses == ['127.0.0.1']


def test_localhost_with_static_peers_keeps_its_range():
    env = with_profile({'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
                        'ROS_STATIC_PEERS': '10.0.0.2'})
    assert env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert env[PROFILES_VARIABLE].endswith('fastdds.xml')


@pytest.mark.parametrize('namespace, reply', [
    ('/wirefish', 'rr/wirefish/retune_gaitReply'),
    ('/', 'rr/retune_gaitReply'),
    ('/fish_2', 'rr/fish_2/cpg_node/set_parametersReply'),
    ('/a/b', 'rr/a/b/retune_gait/_action/send_goalReply'),
])
def test_reply_writer_names_follow_the_namespace(namespace, reply):
    assert reply in reply_writer_names(namespace)


def test_every_reply_writer_waits_the_same_five_seconds():
    root = ElementTree.fromstring(render_profile(['/x']))
    waits = {e.text for w in root.iter(f'{NS}data_writer') for e in w.iter(f'{NS}sec')}
    assert waits == {'5'}
    assert len(_writer_names(render_profile(['/x']))) == len(reply_writer_names('/x'))


def test_one_side_of_a_radio_gets_a_participant_over_udp_announcing_every_ten_seconds():
    root = ElementTree.fromstring(render_profile(['/x'], radio=True))
    (participant,) = root.iter(f'{NS}participant')
    assert participant.get('is_default_profile') == 'true'
    assert participant.find(f'.//{NS}useBuiltinTransports').text == 'false'
    (transport,) = root.iter(f'{NS}transport_descriptor')
    assert transport.find(f'{NS}type').text == 'UDPv4'
    discovery = participant.find(f'.//{NS}discovery_config')
    lease = int(discovery.find(f'{NS}leaseDuration/{NS}sec').text)
    announce = int(discovery.find(f'{NS}leaseAnnouncement/{NS}sec').text)
    assert (lease, announce) == (30, 10)
    assert lease > 10 + announce  # a 10 s radio cut never ends a lease


def test_one_host_sets_only_the_listen_buffer_so_builtin_transports_still_apply():
    root = ElementTree.fromstring(render_profile(['/x']))
    (participant,) = root.iter(f'{NS}participant')
    assert participant.get('is_default_profile') == 'true'
    (rtps,) = participant
    assert [(e.tag, e.text) for e in rtps] == [
        (f'{NS}listenSocketBufferSize', str(LISTEN_BUFFER_BYTES))]
    assert list(root.iter(f'{NS}transport_descriptor')) == []


@pytest.mark.parametrize('side', ({'radio': True}, {'loopback': True}))
def test_a_participant_naming_its_transport_sets_the_buffer_on_it(side):
    root = ElementTree.fromstring(render_profile(['/x'], **side))
    (transport,) = root.iter(f'{NS}transport_descriptor')
    assert transport.find(f'{NS}receiveBufferSize').text == str(LISTEN_BUFFER_BYTES)
    assert LISTEN_BUFFER_BYTES > 212992  # the kernel's default, which a stall overflowed


def test_a_radio_side_writes_its_own_profile_even_in_the_installed_namespace(tmp_path):
    env, own = graph_environment({PROFILES_VARIABLE: str(profile_path())}, {'/wirefish'},
                                 tmp_path, radio=True)
    assert env[PROFILES_VARIABLE] == str(tmp_path / 'fastdds.xml')
    assert 'leaseAnnouncement' in own


def test_a_graph_in_the_installed_namespaces_uses_the_installed_profile(tmp_path):
    env, own = graph_environment({}, {'/wirefish'}, tmp_path)
    assert env[PROFILES_VARIABLE] == str(profile_path())
    assert own is None
    assert env[TRANSPORTS_VARIABLE] == 'UDPv4'


def test_a_graph_in_other_namespaces_writes_and_names_its_own_profile(tmp_path):
    env, own = graph_environment({}, {'/fish_1', '/fish_2'}, tmp_path / 'run')
    assert env[PROFILES_VARIABLE] == str(tmp_path / 'run' / 'fastdds.xml')
    assert not (tmp_path / 'run').exists()  # written only when the graph starts
    write_profile(env, own)
    names = _writer_names((tmp_path / 'run' / 'fastdds.xml').read_text())
    assert 'rr/fish_1/retune_gaitReply' in names
    assert 'rr/fish_2/cpg_node/follow_commandsReply' in names


def test_the_users_profile_is_kept_even_empty(tmp_path):
    env, own = graph_environment({PROFILES_VARIABLE: ''}, {'/fish_1'}, tmp_path)
    assert env[PROFILES_VARIABLE] == ''
    assert own is None
