"""Serial bridge to the fish STM32 board (protocol, codec, transport, bridge_node)."""
