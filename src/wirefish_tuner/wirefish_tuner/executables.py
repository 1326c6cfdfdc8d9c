# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``tuner_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def tuner_node() -> None:
    """Run ``tuner_node``, the gait tuner node (``wirefish_tuner.tuner_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_tuner.tuner_node import main
    main()
