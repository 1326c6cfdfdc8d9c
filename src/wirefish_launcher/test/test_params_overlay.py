# SPDX-License-Identifier: Apache-2.0
"""The run's parameter file: a partial file on top of the defaults, and what matches no node."""

from pathlib import Path

from wirefish_launcher.params_overlay import (key_pattern, overlaid, PARAMETER_TABLES,
                                              unused_entries)
from wirefish_launcher.supervisor import Supervisor

NODES = ['/wirefish/fish_sim', '/wirefish/bridge_node', '/wirefish/cpg_node',
         '/wirefish/kinematics_node', '/wirefish/planner_node']


def _block(**values):
    return {'ros__parameters': values}


def test_a_partial_file_overrides_only_what_it_names():
    defaults = {'/**': _block(l1=0.08, l2=0.1), '/**/cpg_node': _block(amplitude_1=0.38)}
    merged = overlaid(defaults, {'/**': _block(l2=0.12), '/**/tf_node': _block(imu_x=0.1)})
    assert merged == {'/**': _block(l1=0.08, l2=0.12), '/**/cpg_node': _block(amplitude_1=0.38),
                      '/**/tf_node': _block(imu_x=0.1)}
    assert defaults['/**'] == _block(l1=0.08, l2=0.1)  # the defaults are not changed


def test_keys_match_as_rcl_reads_them():
    assert key_pattern('/**').match('/wirefish/cpg_node')
    assert key_pattern('/**/cpg_node').match('/wirefish/cpg_node')
    assert key_pattern('/**/cpg_node').match('/cpg_node')
    assert key_pattern('/*/cpg_*').match('/wirefish/cpg_node')
    assert not key_pattern('cpg_node').match('/wirefish/cpg_node')  # rcl reads /cpg_node
    assert key_pattern('cpg_node').match('/cpg_node')


def test_a_key_without_its_namespace_and_an_unknown_parameter_are_warned_about():
    user = {'cpg_node': _block(amplitude_1=0.3),
            '/**/cpg_node': _block(amplitude_1=0.3, amplitud_2=0.4),
            '/**': _block(l1=0.09, l9=1.0),
            '/**/planer_node': _block(turn_gain=1.0)}
    warnings = unused_entries(user, NODES)
    assert len(warnings) == 4, warnings
    assert "'cpg_node' matches no node" in warnings[0] and '/**/cpg_node' in warnings[0]
    assert "'amplitud_2' is no parameter of cpg_node (did you mean amplitude_2?)" in warnings[1]
    assert "'l9' is no parameter" in warnings[2]
    assert "'/**/planer_node' matches no node" in warnings[3]
    assert unused_entries({'/**/cpg_node': _block(amplitude_1=0.3, use_sim_time=True)},
                          NODES) == []


def test_every_registry_node_with_parameters_has_its_table():
    from wirefish_bringup.graph import NODES as REGISTRY

    with_parameters = {e.name for e in REGISTRY if e.node_class is not None} | {'fish_sim'}
    assert with_parameters <= set(PARAMETER_TABLES)


def test_a_refusal_of_start_up_parameters_is_read_from_the_last_start(tmp_path: Path):
    supervisor = Supervisor(tmp_path)
    log = tmp_path / 'cpg_node.log'
    log.write_text('[FATAL] [1.0] [wirefish]: cpg_node: amplitude_1 out of range\n')
    assert supervisor.refusal('cpg_node') == 'cpg_node: amplitude_1 out of range'
    log.write_text('[FATAL] [1.0] [wirefish]: old\n--- cpg_node restarted by wirefish up ---\n'
                   'Traceback (most recent call last):\n  ...\nRuntimeError: boom\n')
    assert supervisor.refusal('cpg_node') is None  # a crash: restarted by its policy
