# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``cpg_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def cpg_node() -> None:
    """Run ``cpg_node``, the CPG node (``wirefish_cpg.cpg_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_cpg.cpg_node import main
    main()
