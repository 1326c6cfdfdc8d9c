# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``kinematics_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def kinematics_node() -> None:
    """Run ``kinematics_node`` (``wirefish_kinematics.kinematics_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_kinematics.kinematics_node import main
    main()
