# SPDX-License-Identifier: Apache-2.0
"""The entry points of ``fish_sim`` and ``radio_relay``: stop signals held, then run."""

from typing import NoReturn

from wirefish_common.startup_signals import hold_stop_signals


def fish_sim() -> NoReturn:
    """Run ``fish_sim``, the virtual fish (``wirefish_sim.fish_sim.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_sim.fish_sim import main
    main()


def radio_relay() -> NoReturn:
    """Run ``radio_relay``, the radio between the bridge and a fish (``radio_relay.main``)."""
    hold_stop_signals()  # released by its SignalShutdown once its handler is in place
    from wirefish_sim.radio_relay import main
    main()
