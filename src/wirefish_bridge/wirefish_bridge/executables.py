# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``bridge_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def bridge_node() -> None:
    """Run ``bridge_node``, the serial bridge node (``wirefish_bridge.bridge_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_bridge.bridge_node import main
    main()
