"""The shore-side PSO gait tuner (eqs 23-27): the retune_gait service and action."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('tuner_node')
