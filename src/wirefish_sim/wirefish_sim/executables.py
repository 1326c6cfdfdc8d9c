"""
The entry points of ``fish_sim`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from typing import NoReturn

from wirefish_common.startup_signals import hold_stop_signals


def fish_sim() -> NoReturn:
    """Run ``fish_sim``, the virtual fish (``wirefish_sim.fish_sim.main``)."""
    hold_stop_signals()
    from wirefish_sim.fish_sim import main
    main()
