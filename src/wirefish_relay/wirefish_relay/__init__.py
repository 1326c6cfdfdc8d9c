"""The fish's side of the radio link: the decimated copies the shore sees."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('link_relay')
