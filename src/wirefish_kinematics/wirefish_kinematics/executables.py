"""
The entry points of ``kinematics_node`` (setup.py's ``console_scripts``).

Each holds the stop signals (``wirefish_common.startup_signals.hold_stop_signals``) before
it imports its node's modules: a Ctrl-C during those imports waits for the node's own
handler instead of raising KeyboardInterrupt. Importing this module changes nothing.
"""

from wirefish_common.startup_signals import hold_stop_signals


def kinematics_node() -> None:
    """Run ``kinematics_node`` (``wirefish_kinematics.kinematics_node.main``)."""
    hold_stop_signals()
    from wirefish_kinematics.kinematics_node import main
    main()
