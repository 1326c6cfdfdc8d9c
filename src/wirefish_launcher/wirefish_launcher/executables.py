# SPDX-License-Identifier: Apache-2.0
"""The entry points of ``compose`` and ``qemu_board``: stop signals held, then imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def compose() -> int:
    """Run ``compose``, the fish's nodes in one process (``wirefish_launcher.verb.compose``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_launcher.verb.compose import main
    return main()


def qemu_board() -> int:
    """Run ``qemu_board``, the emulated board (``wirefish_launcher.verb.qemu.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_launcher.verb.qemu import main
    return main()
