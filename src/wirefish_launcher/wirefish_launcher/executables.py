"""
The entry points of ``compose`` and ``qemu_board`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from wirefish_common.startup_signals import hold_stop_signals


def compose() -> int:
    """Run ``compose``, the fish's nodes in one process (``wirefish_launcher.compose.main``)."""
    hold_stop_signals()
    from wirefish_launcher.compose import main
    return main()


def qemu_board() -> int:
    """Run ``qemu_board``, the emulated board (``wirefish_launcher.qemu_board.main``)."""
    hold_stop_signals()
    from wirefish_launcher.qemu_board import main
    return main()
