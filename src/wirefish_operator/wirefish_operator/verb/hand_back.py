# SPDX-License-Identifier: Apache-2.0
"""
`wirefish hand-back`: give the gait back to the planner after a manual override of the CPG.

A set of cpg_node's eq 1 parameters (``wirefish retune --apply``, ``ros2 param set``) is a
manual override: the CPG runs those parameters and the planner does not drive it (planner_state
says mode ``manual``). This calls cpg_node's ``follow_commands`` service, the same as
``ros2 service call /wirefish/cpg_node/follow_commands std_srvs/srv/Trigger``; the planner's next
cpg_command then sets the targets.
"""

import argparse
import sys

from wirefish_bringup.graph import DEFAULT_NAMESPACE
from wirefish_cli.ros_session import ros_session

WAIT_S = 10.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish hand-back`."""
    from wirefish_cli.api import duration_s

    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE,
                        help='ROS namespace of the graph (default %(default)s)')
    parser.add_argument('--timeout', type=duration_s, default=WAIT_S,
                        help='seconds to wait for the service and its answer (default '
                             '%(default)s)')


def run(args: argparse.Namespace) -> int:
    """Call follow_commands once; return 0 when the CPG answered."""
    from std_srvs.srv import Trigger

    with ros_session('wirefish_hand_back', args.namespace) as session:
        client = session.node.create_client(
            Trigger, f'{session.namespace.rstrip("/")}/cpg_node/follow_commands')
        try:
            if not client.wait_for_service(timeout_sec=args.timeout):
                print(f'wirefish hand-back: no {client.srv_name} service: is the graph running '
                      '(wirefish up)?', file=sys.stderr)
                return 1
            future = client.call_async(Trigger.Request())
            if not session.spin_until(future.done, args.timeout):
                print(f'wirefish hand-back: {client.srv_name} did not answer within '
                      f'{args.timeout:g} s', file=sys.stderr)
                return 1
            print(f'cpg_node: {future.result().message}')
            return 0
        except KeyboardInterrupt:
            return 130
        finally:
            session.node.destroy_client(client)
