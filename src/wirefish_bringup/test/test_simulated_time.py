# SPDX-License-Identifier: Apache-2.0
"""The virtual fish's graph on simulated time: who owns the clock, who follows it (pure)."""

import pytest
from wirefish_bringup.fleet import fleet_graph
from wirefish_bringup.graph import (clock_topic, COMPOSED_NAME, fish_graph, on_simulated_time,
                                    SIM_TIME_COMMAND_RATE_HZ)


def test_fish_sim_owns_the_clock_and_every_other_node_follows_it():
    specs = on_simulated_time(fish_graph('/tank', sim=True), 'max')
    by_name = {spec.name: spec for spec in specs}
    assert by_name['fish_sim'].arguments[-2:] == ('--speed', 'max')
    assert 'use_sim_time' not in by_name['fish_sim'].parameters  # the clock's owner
    for name, spec in by_name.items():
        if name == 'fish_sim' or spec.namespace is None:
            continue
        assert spec.parameters['use_sim_time'] == 'true', name
        assert spec.remaps == {'/clock': '/tank/clock'}, name
        arguments = spec.command_arguments()
        assert arguments[arguments.index('/clock:=/tank/clock') - 1] == '-r', name
    assert by_name['bridge_node'].parameters['max_command_rate_hz'] == SIM_TIME_COMMAND_RATE_HZ


def test_on_simulated_time_odom_is_the_ground_truth_from_the_first_transform():
    specs = on_simulated_time(fish_graph('/tank', sim=True), '1')
    tf_node = next(spec for spec in specs if spec.executable == 'tf_node')
    assert tf_node.parameters['odom_source'] == 'ground_truth'


def test_the_single_process_host_is_told_the_clock():
    specs = on_simulated_time(fish_graph('/tank', sim=True, single_process=True), '1')
    composed = next(spec for spec in specs if spec.name == COMPOSED_NAME)
    assert composed.arguments[-3:] == ('--sim-time', '--clock', '/tank/clock')


def test_a_fleet_has_one_clock_its_fish_sim_publishes_in_the_base_namespace():
    specs = on_simulated_time(fleet_graph('/school', 3), '1')
    simulators = [spec for spec in specs if spec.executable == 'fish_sim']
    assert len(simulators) == 1 and simulators[0].arguments[-2:] == ('--speed', '1')
    remapped = {spec.remaps.get('/clock') for spec in specs
                if spec.namespace is not None and spec.executable != 'fish_sim'}
    assert remapped == {clock_topic('/school')} == {'/school/clock'}


def test_a_graph_without_the_virtual_fish_has_no_simulated_time():
    with pytest.raises(ValueError, match="virtual fish's clock"):
        on_simulated_time(fish_graph('/tank', sim=False, port='/dev/ttyUSB0'), '1')


def test_the_root_namespaces_clock_is_slash_clock():
    assert clock_topic('/') == '/clock'
