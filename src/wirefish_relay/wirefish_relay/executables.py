"""
The entry points of ``link_relay`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from wirefish_common.startup_signals import hold_stop_signals


def link_relay() -> None:
    """Run ``link_relay``, the fish's side of the radio (``wirefish_relay.link_relay.main``)."""
    hold_stop_signals()
    from wirefish_relay.link_relay import main
    main()
