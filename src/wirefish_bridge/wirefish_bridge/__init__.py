# SPDX-License-Identifier: Apache-2.0
"""Serial bridge to the fish STM32 board (protocol, codec, transport, bridge_node)."""
