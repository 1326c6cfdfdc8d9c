# SPDX-License-Identifier: Apache-2.0
"""
`wirefish qemu`: one emulated board until Ctrl-C (the fish of `wirefish up --fish qemu`).

The board is ``wirefish_launcher.qemu_board.QemuBoard``: the firmware's ARM build on QEMU's
netduinoplus2, its USART1 on a pty behind the stable symlink ``--link`` (the bridge's port).
"""

import argparse
from pathlib import Path
import signal
import sys
import threading

from wirefish_common.startup_signals import release_stop_signals
from wirefish_launcher.errors import QemuBoardError
from wirefish_launcher.qemu_board import build_image, MACHINE, QEMU, QemuBoard


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish qemu`."""
    parser.add_argument('--link', type=Path, required=True,
                        help="symlink to point at the board's USART1 pty (the bridge's port)")
    parser.add_argument('--image', type=Path, default=None,
                        help='firmware ELF (default: build firmware/build/qemu/wirefish.elf '
                        'with make if it is out of date)')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish qemu` until SIGINT/SIGTERM; 1 if QEMU ends by itself or cannot start."""
    stop = threading.Event()

    def request_stop(signum: int, _frame: object) -> None:
        stop.set()

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    release_stop_signals()  # held by `wirefish up` until here; QEMU inherits them unblocked
    try:
        image = args.image if args.image is not None else build_image()
        board = QemuBoard(image, link=args.link)
        ports = board.start()
    except QemuBoardError as error:
        print(f'wirefish qemu: {error}', file=sys.stderr)
        return 1
    print(f'wirefish qemu: {image} on {MACHINE} (pid {board.pid}); USART1 on {ports.link}, '
          f'linked from {args.link}', flush=True)
    code = 0
    while not stop.wait(0.2):
        if not board.running():
            print(f'wirefish qemu: {QEMU} ended by itself:\n{board.output()}', file=sys.stderr)
            code = 1
            break
    board.stop()
    board.remove_link()
    return code


def main() -> int:
    """Entry point of the ``qemu_board`` executable (the graph's registry starts it)."""
    from wirefish_cli.api import verb_main
    return verb_main(add_arguments, run, 'qemu_board', __doc__.strip().splitlines()[0])
