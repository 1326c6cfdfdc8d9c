# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``planner_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def planner_node() -> None:
    """Run ``planner_node``, the planner node (``wirefish_planner.planner_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_planner.planner_node import main
    main()
