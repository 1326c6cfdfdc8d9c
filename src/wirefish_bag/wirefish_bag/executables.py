# SPDX-License-Identifier: Apache-2.0
"""The entry point of ``recorder``: stop signals held, then the node imported and run."""

from wirefish_common.startup_signals import hold_stop_signals


def recorder() -> int:
    """Run the graph's recorder, ``wirefish_bag.recorder.main``."""
    hold_stop_signals()  # before the node's imports: a stop during them is kept
    from wirefish_bag.recorder import main
    return main()
