# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``link_relay``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def link_relay() -> None:
    """Run ``link_relay``, the fish's side of the radio (``wirefish_relay.link_relay.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_relay.link_relay import main
    main()
