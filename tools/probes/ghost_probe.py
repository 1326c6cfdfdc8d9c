#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""
Count the stopped nodes another participant keeps listing: with and without a leaving holder.

Each run starts one of the graph's node executables (``--node``, as `ros2 launch` starts it, in
a namespace of its own), stops it with SIGINT as soon as this probe lists the node, and counts
a ghost when the probe still lists it ``--gone-s`` after the process exited. The node's stop is
``run_node``'s own, but for its last step: ``plain`` destroys the node at once (rmw_fastrtps
deletes the participant in the same call), ``holder`` uses ``wirefish_common.graph_exit`` (the
participant outlives the node). The runs alternate between the two, so both meet the same
machine. Ghosts need load, e.g. two ``yes > /dev/null`` beside it:

    tools/wfenv python tools/probes/ghost_probe.py --runs 200

A ghost still listed past the participant's 20 s lease (``--watch-s 60``), with none of its
endpoints, is the participant added back to the probe's graph cache after its goodbye
(graph_exit's docstring).
"""

from __future__ import annotations

import argparse
import os
import runpy
import signal
import subprocess
import sys
import time

MODES = ('plain', 'holder')
DEVICE = '/tmp/wirefish-ghost-probe-no-such-device'


def _spec(node: str, namespace: str):
    from wirefish_bringup.graph import fish_graph
    return next(spec for spec in fish_graph(namespace, sim=False, port=DEVICE)
                if spec.name == node)


def child(mode: str, node: str, namespace: str) -> None:
    """Run ``node``'s executable in this process; ``plain``: its node destroyed at once."""
    import wirefish_common.node_main as node_main

    if mode == 'plain':
        node_main.destroy_leaving_the_graph = lambda node: node.destroy_node()
    spec = _spec(node, namespace)
    sys.argv = [str(spec.executable_path()), *spec.command_arguments()]
    runpy.run_path(sys.argv[0], run_name='__main__')


def main() -> int:
    """Alternate plain and holder stops; print the ghosts of each."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=100, help='stops in all (both modes)')
    parser.add_argument('--node', default='cpg_node', help='a node of the fish graph')
    parser.add_argument('--domain', type=int, default=83, help='ROS_DOMAIN_ID of the runs')
    parser.add_argument('--gone-s', type=float, default=3.0,
                        help='how long after the exit a listed node counts as a ghost')
    parser.add_argument('--watch-s', type=float, default=0.0,
                        help='watch each ghost this long more and say whether it went')
    parser.add_argument('--child', choices=MODES, help=argparse.SUPPRESS)
    parser.add_argument('--namespace', help=argparse.SUPPRESS)
    args = parser.parse_args()
    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    if args.child:
        child(args.child, args.node, args.namespace)
        return 0

    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    context = Context()
    rclpy.init(context=context, domain_id=args.domain)
    probe = rclpy.create_node('ghost_probe', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(probe)

    def spin_until(condition, timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while not condition() and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
        return condition()

    ghosts = dict.fromkeys(MODES, 0)
    runs = dict.fromkeys(MODES, 0)
    try:
        for run in range(args.runs):
            mode = MODES[run % 2]
            namespace = f'/ghost_{os.getpid()}_{run}'

            def listed(namespace: str = namespace) -> bool:
                return (args.node, namespace) in probe.get_node_names_and_namespaces()

            proc = subprocess.Popen(
                [sys.executable, __file__, '--child', mode, '--node', args.node,
                 '--namespace', namespace, '--domain', str(args.domain)],
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, start_new_session=True)
            try:
                if not spin_until(listed, 30.0):
                    print(f'run {run}: the node never showed; skipped', flush=True)
                    continue
                proc.send_signal(signal.SIGINT)
                code = proc.wait(timeout=20.0)
            finally:
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()
            exited = time.monotonic()
            runs[mode] += 1
            if spin_until(lambda: not listed(), args.gone_s):
                continue
            ghosts[mode] += 1
            endpoints = probe.get_publisher_names_and_types_by_node(args.node, namespace)
            print(f'run {run} ({mode}, exit {code}): a ghost, {len(endpoints)} publishers '
                  'listed', flush=True)
            if args.watch_s > 0:
                gone = spin_until(lambda: not listed(), args.watch_s)
                print(f'  {"gone" if gone else "still listed"} '
                      f'{time.monotonic() - exited:.1f} s after the exit', flush=True)
    finally:
        executor.shutdown()
        probe.destroy_node()
        rclpy.try_shutdown(context=context)
    for mode in MODES:
        print(f'{mode}: {ghosts[mode]} ghosts in {runs[mode]} stops')
    return 0


if __name__ == '__main__':
    sys.exit(main())
