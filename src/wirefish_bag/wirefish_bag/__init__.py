"""Rosbag2 (MCAP) recording, recovery, replay and reports: the recorder and the bag verbs."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('recorder')
