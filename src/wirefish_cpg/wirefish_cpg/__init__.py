"""Ijspeert CPG node and PSO gait tuner service for the wire-driven elastic robotic fish."""

from wirefish_common.startup_signals import hold_stop_signals_for

hold_stop_signals_for('cpg_node', 'tuner_node')
