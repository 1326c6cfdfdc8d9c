"""
The entry points of ``recorder`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from wirefish_common.startup_signals import hold_stop_signals


def recorder() -> int:
    """Run ``recorder``, the graph's recorder (``wirefish_bag.record.main``)."""
    hold_stop_signals()
    from wirefish_bag.record import main
    return main()
