# SPDX-License-Identifier: Apache-2.0
"""The launcher's view of a fleet's nodes, pure."""

from wirefish_bringup.fleet import fleet_graph
from wirefish_launcher.verb.up import _registry_nodes


def test_the_launcher_names_a_fleets_nodes_relative_to_its_base():
    names = _registry_nodes(fleet_graph('/tank', 2), '/tank')
    assert 'fish_1/cpg_node' in names and 'fish_2/cpg_node' in names
