"""The live view of the fish: a Foxglove WebSocket server over the graph and a dashboard."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('view_node')
