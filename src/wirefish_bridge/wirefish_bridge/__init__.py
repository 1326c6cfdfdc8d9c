"""Serial bridge to the fish STM32 board (protocol, codec, transport, bridge_node)."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('bridge_node')
