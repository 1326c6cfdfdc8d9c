"""Process management: wirefish up, its supervisor and status, the emulated board, two hosts."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('compose')
