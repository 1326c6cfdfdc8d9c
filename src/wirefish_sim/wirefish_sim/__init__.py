"""The virtual fish: firmware, physics and servos on a pseudo-terminal."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('fish_sim')
