#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""
Count the stopped nodes another participant keeps listing: with and without a leaving holder.

Each run starts a child process with one node and ``--entities`` publishers (a node's start-up
burst of graph updates), stops it with SIGINT as soon as this probe lists the node, and counts
a ghost when the probe still lists it ``--gone-s`` after the child exited. The child destroys
its node either plainly (``plain``: rmw_fastrtps deletes the participant in the same call) or
with ``wirefish_common.graph_exit.destroy_leaving_the_graph`` (``holder``); the runs alternate
between the two, so both meet the same machine. Load it to see ghosts at all, e.g. beside two
``yes > /dev/null``:

    tools/wfenv python tools/probes/ghost_probe.py --runs 200

A ghost still listed a minute later (``--watch-s 60``) with none of its endpoints is the
participant added back to the probe's graph cache after its goodbye (graph_exit's docstring).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time

MODES = ('plain', 'holder')
NODE_NAME = 'ghost_candidate'


def child(mode: str, namespace: str, entities: int) -> None:
    """Run one node until SIGINT, then destroy it the ``mode`` way and exit at once."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions
    from std_msgs.msg import Empty
    from wirefish_common.graph_exit import destroy_leaving_the_graph

    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(True))
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(NODE_NAME, namespace=namespace)
    for index in range(entities):
        node.create_publisher(Empty, f'topic_{index}', 10)
    while not stop:
        time.sleep(0.005)
    if mode == 'plain':
        node.destroy_node()
    else:
        destroy_leaving_the_graph(node)
    rclpy.try_shutdown()
    os._exit(0)


def main() -> int:
    """Alternate plain and holder stops; print the ghosts of each."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=100, help='stops in all (both modes)')
    parser.add_argument('--domain', type=int, default=83, help='ROS_DOMAIN_ID of the runs')
    parser.add_argument('--entities', type=int, default=20, help="the child's publishers")
    parser.add_argument('--gone-s', type=float, default=3.0,
                        help='how long after the exit a listed node counts as a ghost')
    parser.add_argument('--watch-s', type=float, default=0.0,
                        help='watch each ghost this long more and say whether it went')
    parser.add_argument('--child', choices=MODES, help=argparse.SUPPRESS)
    parser.add_argument('--namespace', help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.namespace, args.entities)

    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    os.environ['ROS_DOMAIN_ID'] = str(args.domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
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
                return (NODE_NAME, namespace) in probe.get_node_names_and_namespaces()

            proc = subprocess.Popen(
                [sys.executable, __file__, '--child', mode, '--namespace', namespace,
                 '--entities', str(args.entities)], stdin=subprocess.DEVNULL)
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
            endpoints = probe.get_publisher_names_and_types_by_node(NODE_NAME, namespace)
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
