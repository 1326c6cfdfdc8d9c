"""Serial bridge to the fish STM32 board and a virtual fish on a pseudo-terminal."""
