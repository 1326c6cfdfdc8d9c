# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``tf_node``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def tf_node() -> None:
    """Run ``tf_node``, the TF node (``wirefish_tf.tf_node.main``)."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_tf.tf_node import main
    main()
