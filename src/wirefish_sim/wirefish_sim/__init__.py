"""The virtual fish: firmware, physics and servos on a pseudo-terminal."""
