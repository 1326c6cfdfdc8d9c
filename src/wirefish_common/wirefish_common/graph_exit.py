# SPDX-License-Identifier: Apache-2.0
"""
A stopping node leaves every other participant's graph, and stays gone.

On rmw_fastrtps the process's DDS participant lives as long as its last node: destroying the
only node publishes the graph update that drops it (on ``ros_discovery_info``) and deletes the
participant in the same call. Another process then sees two things at once, on two threads:
the update, and the participant's goodbye. Its graph cache (rmw_dds_common, Jazzy) forgets the
participant on the goodbye, but an update of that participant handled after it adds the
participant back with what the update lists. On a loaded machine the goodbye overtook the last
update, and an earlier one, that still listed the node, came after: the node stayed in that
process's ``ros2 node list`` for good (``tools/probes/ghost_probe.py`` beside two CPU hogs:
5 of 100 stops of cpg_node, each still listed 33 s after its exit, past the 20 s lease, with
none of its endpoints; 0 of the 100 stops made with the holder, in the same run).

``destroy_leaving_the_graph`` keeps the participant for ``linger_s`` after the node's own
update, with a hidden node that holds it (``_<name>_leaving``, no services, no rosout, none of
the process's arguments): the update that drops the node reaches the others before the
goodbye does.
"""

from __future__ import annotations

from collections.abc import Sequence
import time

from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.type_description_service import START_TYPE_DESCRIPTION_SERVICE_PARAM

# How long the participant outlives the node: with 0.3 s no stop of 100 left a ghost beside two
# CPU hogs (the probe above), and a stop waits it once.
LEAVE_LINGER_S = 0.3


def holder_name(node_name: str) -> str:
    """Return the hidden name of the node that holds the participant while ``node_name`` goes."""
    return f'_{node_name}_leaving'


def destroy_leaving_the_graph(nodes: Node | Sequence[Node],
                              linger_s: float = LEAVE_LINGER_S) -> None:
    """Destroy ``nodes`` (of one context), its participant ``linger_s`` after (see above)."""
    nodes = [nodes] if isinstance(nodes, Node) else list(nodes)
    if not nodes:
        return
    first = nodes[0]
    if not first.context.ok():  # shut down already: no node can be made to hold it
        for node in nodes:
            node.destroy_node()
        return
    holder = Node(holder_name(first.get_name()), namespace=first.get_namespace(),
                  context=first.context, use_global_arguments=False, enable_rosout=False,
                  start_parameter_services=False,
                  parameter_overrides=[Parameter(START_TYPE_DESCRIPTION_SERVICE_PARAM,
                                                 value=False)])
    for node in nodes:
        node.destroy_node()
    time.sleep(linger_s)
    holder.destroy_node()
