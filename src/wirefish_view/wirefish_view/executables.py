"""
The entry points of ``view_node`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from wirefish_common.startup_signals import hold_stop_signals


def view_node() -> None:
    """Run ``view_node``, the live view node (``wirefish_view.view_node.main``)."""
    hold_stop_signals()
    from wirefish_view.view_node import main
    main()
