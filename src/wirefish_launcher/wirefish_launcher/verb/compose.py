# SPDX-License-Identifier: Apache-2.0
"""
`wirefish compose`: all of one fish's ROS nodes in one process.

The single-process mode of `wirefish up --single-process`: every registry entry with a node
class (`wirefish_bringup.graph.NODES`), with the same names, namespace, parameter file and
extra parameters as the one-process-per-node graph, but one Python interpreter and one DDS
participant instead of one per node, which is what limits how many fish fit on one machine. An
entry marked ``own_executor`` (the tuner) spins on an executor and thread of its own: a fit then
never stalls the fish's streams, and its apply step, which waits for cpg_node's parameter
service, can be answered.
"""

import argparse
import importlib
import sys
import threading

from wirefish_bringup.graph import (composable_entries, DEFAULT_NAMESPACE, default_params_file,
                                    resolve, ros_arguments, simulated_time_parameters,
                                    validate_namespace)
from wirefish_common.executors import ExecutorKind

# Beside the executors a node process may spin on (ExecutorKind), the one process of all the
# nodes may spin on rclpy's MultiThreadedExecutor.
MULTI = 'multi'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish compose`."""
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--port', required=True,
                        help="the fish's serial device (the nodes' {device} parameters)")
    parser.add_argument('--params-file', default=None, help='parameter YAML')
    parser.add_argument('--executor', choices=[*(kind.value for kind in ExecutorKind), MULTI],
                        default=None,
                        help='executor of the bridge, CPG and kinematics nodes: events '
                        '(rclpy.experimental.EventsExecutor), classic '
                        '(SingleThreadedExecutor) or multi (MultiThreadedExecutor); default: '
                        'the one WIREFISH_EXECUTOR names, events if unset, as in one process '
                        'per node; the tuner always has its own')
    parser.add_argument('--sim-time', action='store_true',
                        help='every node on simulated time (use_sim_time: the clock fish_sim '
                        'publishes, wirefish up --sim --speed)')
    parser.add_argument('--clock', default='/clock',
                        help='with --sim-time: the topic of that clock (fish_sim publishes '
                        '<its namespace>/clock)')


def node_class(path: str | None) -> type:
    """Return the class named by ``'module:Class'`` (None: the entry is not composable)."""
    if path is None:
        raise ValueError('this graph entry has no node class: it runs as a process of its own')
    module_name, class_name = path.split(':')
    return getattr(importlib.import_module(module_name), class_name)


def run(args: argparse.Namespace) -> int:
    """Run `wirefish compose` until SIGINT/SIGTERM; return the exit code."""
    import rclpy
    from rclpy.executors import MultiThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from wirefish_common.executors import executor_kind, make_executor, spin_until_stopped
    from wirefish_common.graph_exit import destroy_leaving_the_graph
    from wirefish_common.parameter_table import InvalidParameters
    from wirefish_common.shutdown import SignalShutdown

    try:
        namespace = validate_namespace(args.namespace)
        kind = args.executor or executor_kind()
    except ValueError as error:
        print(f'wirefish compose: {error}', file=sys.stderr)
        return 2
    params = str(args.params_file or default_params_file())
    # SIGINT/SIGTERM end the spin loop between callbacks (as run_node does for one node), so
    # no callback ever publishes on a context that is being shut down; then the nodes are
    # destroyed and the context shut down.
    signals = SignalShutdown()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    nodes = []
    executor = (MultiThreadedExecutor(num_threads=4) if kind == MULTI
                else make_executor(kind))
    signals.attach_executor(executor)
    # As in its own process (tuner_node.main): a multi-threaded executor, so the service that
    # runs a fit can wait for the answer of cpg_node's parameter service.
    own_executor = MultiThreadedExecutor(num_threads=4)
    own_thread = threading.Thread(target=own_executor.spin, name='own_executor', daemon=True)
    try:
        for entry in composable_entries():
            parameters = {k: resolve(v, device=args.port, namespace=namespace)
                          for k, v in entry.parameters.items()}
            if args.sim_time:  # as on_simulated_time sets them for one process per node
                parameters.update(simulated_time_parameters(entry.name))
            cli_args = list(ros_arguments(entry.name, namespace, params, parameters,
                                          {'/clock': args.clock} if args.sim_time else None))
            node = node_class(entry.node_class)(cli_args=cli_args)
            nodes.append(node)
            (own_executor if entry.own_executor else executor).add_node(node)
        own_thread.start()
        spin_until_stopped(executor, lambda: signals.requested)
    except InvalidParameters as error:
        print(f'wirefish compose: {error}', file=sys.stderr)
        return 1
    finally:
        signals.attach_executor(None)
        own_executor.shutdown()
        if own_thread.is_alive():
            own_thread.join(5.0)
        # Nodes go before the executor: their threads are joined while it can take a task.
        for node in nodes:
            if node.executor is executor:
                executor.remove_node(node)
        destroy_leaving_the_graph(list(reversed(nodes)))
        executor.shutdown()
        rclpy.try_shutdown()
    return 0


def main() -> int:
    """Entry point of the ``compose`` executable (the registry's single-process mode)."""
    from wirefish_cli.api import verb_main
    return verb_main(add_arguments, run, 'compose', __doc__.strip().splitlines()[0])
