"""
The entry points of ``cpg_node`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from wirefish_common.startup_signals import hold_stop_signals


def cpg_node() -> None:
    """Run ``cpg_node``, the CPG node (``wirefish_cpg.cpg_node.main``)."""
    hold_stop_signals()
    from wirefish_cpg.cpg_node import main
    main()
