# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``view_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def view_node() -> None:
    """Run ``view_node``, the live view node (``wirefish_view.view_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_view.view_node import main
    main()
