"""
`wirefish compose`: all of one fish's ROS nodes in one process.

The single-process mode of `wirefish up --single-process`: every registry entry with a node
class (`wirefish_bringup.graph.NODES`), with the same names, namespace, parameter file and
extra parameters as the one-process-per-node graph, but one Python interpreter and one DDS
participant instead of four, which is what limits how many fish fit on one machine. An entry
marked ``own_executor`` (the tuner) spins on an executor and thread of its own: a fit then
never stalls the fish's streams, and its apply step, which waits for cpg_node's parameter
service, can be answered.
"""

import argparse
import importlib
import sys
import threading

from wirefish_bringup.graph import (composable_entries, DEFAULT_NAMESPACE, default_params_file,
                                    resolve, ros_arguments, validate_namespace)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish compose`."""
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--port', required=True,
                        help="the fish's serial device (the nodes' {device} parameters)")
    parser.add_argument('--params-file', default=None, help='parameter YAML')
    parser.add_argument('--executor', choices=('single', 'multi'), default='single',
                        help='executor of the bridge, CPG and kinematics nodes: '
                        'SingleThreadedExecutor (default: least overhead per callback) or '
                        'MultiThreadedExecutor; the tuner always has its own')


def node_class(path: str | None) -> type:
    """Return the class named by ``'module:Class'`` (None: the entry is not composable)."""
    if path is None:
        raise ValueError('this graph entry has no node class: it runs as a process of its own')
    module_name, class_name = path.split(':')
    return getattr(importlib.import_module(module_name), class_name)


def run(args: argparse.Namespace) -> int:
    """Run `wirefish compose` until SIGINT/SIGTERM; return the exit code."""
    import signal

    import rclpy
    from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from wirefish_common.parameter_table import InvalidParameters

    try:
        namespace = validate_namespace(args.namespace)
    except ValueError as error:
        print(f'wirefish compose: {error}', file=sys.stderr)
        return 2
    params = str(args.params_file or default_params_file())
    # SIGINT/SIGTERM end the spin loop between callbacks, so no callback ever publishes on a
    # context that is being shut down; then the nodes are destroyed and the context shut down.
    stop_requested = []
    signal.signal(signal.SIGINT, lambda *_: stop_requested.append(True))
    signal.signal(signal.SIGTERM, lambda *_: stop_requested.append(True))
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    nodes = []
    executor = (SingleThreadedExecutor() if args.executor == 'single'
                else MultiThreadedExecutor(num_threads=4))
    # As in its own process (tuner_node.main): a multi-threaded executor, so the service that
    # runs a fit can wait for the answer of cpg_node's parameter service.
    own_executor = MultiThreadedExecutor(num_threads=4)
    own_thread = threading.Thread(target=own_executor.spin, name='own_executor', daemon=True)
    try:
        for entry in composable_entries():
            parameters = {k: resolve(v, device=args.port, namespace=namespace)
                          for k, v in entry.parameters.items()}
            cli_args = list(ros_arguments(entry.name, namespace, params, parameters))
            node = node_class(entry.node_class)(cli_args=cli_args)
            nodes.append(node)
            (own_executor if entry.own_executor else executor).add_node(node)
        own_thread.start()
        while not stop_requested:
            executor.spin_once(timeout_sec=0.1)
    except InvalidParameters as error:
        print(f'wirefish compose: {error}', file=sys.stderr)
        return 1
    finally:
        executor.shutdown()
        own_executor.shutdown()
        if own_thread.is_alive():
            own_thread.join(5.0)
        for node in reversed(nodes):
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
