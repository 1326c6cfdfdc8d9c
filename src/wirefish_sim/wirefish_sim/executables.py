"""The entry point of ``fish_sim``: stop signals held, then the node imported and run."""

from typing import NoReturn

from wirefish_common.startup_signals import hold_stop_signals


def fish_sim() -> NoReturn:
    """Run ``fish_sim``, the virtual fish (``wirefish_sim.fish_sim.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_sim.fish_sim import main
    main()
