# SPDX-License-Identifier: Apache-2.0
"""
`wirefish view`: the live view of a running fish, Foxglove WebSocket server and dashboard.

Open http://127.0.0.1:8080/ in a browser for the dashboard, or connect Foxglove or
Lichtblick to ws://127.0.0.1:8765 (layout: share/wirefish_view/layouts/wirefish.json). Both
bind this machine only unless ``--address`` says otherwise (a warning then: anyone who
reaches the address can drive the fish).
"""

from __future__ import annotations

import argparse

from wirefish_bringup.graph import DEFAULT_NAMESPACE, validate_namespace


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish view`."""
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='the fish to view')
    parser.add_argument('--address', default='127.0.0.1',
                        help='address to bind (default: this machine only)')
    parser.add_argument('--port', type=int, default=8765, help='Foxglove WebSocket port')
    parser.add_argument('--http-port', type=int, default=8080,
                        help='dashboard port (-1: no dashboard)')
    parser.add_argument('--frame-prefix', default='', help="the fish's frame_prefix, if any")


def ros_arguments(args: argparse.Namespace) -> list[str]:
    """Return the view node's ROS arguments for the options."""
    values = {'address': args.address, 'port': args.port, 'http_port': args.http_port}
    ros = ['--ros-args', '-r', '__node:=view_node', '-r',
           f'__ns:={validate_namespace(args.namespace)}']
    for key, value in values.items():
        ros += ['-p', f'{key}:={value}']
    if args.frame_prefix:
        ros += ['-p', f'frame_prefix:={args.frame_prefix}']
    return ros


def run(args: argparse.Namespace) -> int:
    """Run the view node until Ctrl-C."""
    from wirefish_view.view_node import main

    try:
        ros = ros_arguments(args)
    except ValueError as error:
        print(f'wirefish view: {error}')
        return 2
    main(['view_node', *ros])
    return 0
