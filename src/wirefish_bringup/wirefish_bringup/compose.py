"""
`wirefish compose`: all of one fish's ROS nodes in one process.

The single-process mode of `wirefish up --single-process`: the same node classes, names,
namespace and parameter file as the one-process-per-node graph, but one Python interpreter and
one DDS participant instead of four, which is what limits how many fish fit on one machine.
The tuner spins on an executor and thread of its own: a fit then never stalls the fish's
streams, and its apply step, which waits for cpg_node's parameter service, can be answered.
"""

import argparse
import importlib
import sys
import threading

from wirefish_bringup.graph import DEFAULT_NAMESPACE, default_params_file, validate_namespace

# node name -> 'module:Class'; each class takes rclpy Node keyword arguments.
NODE_CLASSES = {
    'bridge_node': 'wirefish_bridge.bridge_node:BridgeNode',
    'cpg_node': 'wirefish_cpg.cpg_node:CpgNode',
    'kinematics_node': 'wirefish_kinematics.kinematics_node:KinematicsNode',
    'tuner_node': 'wirefish_cpg.tuner_node:TunerNode',
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish compose`."""
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--port', required=True, help='serial device for the bridge')
    parser.add_argument('--params-file', default=None, help='parameter YAML')
    parser.add_argument('--executor', choices=('single', 'multi'), default='single',
                        help='executor of the bridge, CPG and kinematics nodes: '
                        'SingleThreadedExecutor (default: least overhead per callback) or '
                        'MultiThreadedExecutor; the tuner always has its own')


def node_class(path: str) -> type:
    """Return the class named by ``'module:Class'``."""
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
    tuner_executor = MultiThreadedExecutor(num_threads=4)
    tuner_thread = threading.Thread(target=tuner_executor.spin, name='tuner', daemon=True)
    try:
        for name, path in NODE_CLASSES.items():
            cli_args = ['--ros-args', '-r', f'__ns:={namespace}', '--params-file', params]
            if name == 'bridge_node':
                cli_args += ['-p', f'port:={args.port}']
            node = node_class(path)(cli_args=cli_args)
            nodes.append(node)
            (tuner_executor if name == 'tuner_node' else executor).add_node(node)
        tuner_thread.start()
        while not stop_requested:
            executor.spin_once(timeout_sec=0.1)
    except InvalidParameters as error:
        print(f'wirefish compose: {error}', file=sys.stderr)
        return 1
    finally:
        executor.shutdown()
        tuner_executor.shutdown()
        if tuner_thread.is_alive():
            tuner_thread.join(5.0)
        for node in reversed(nodes):
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
