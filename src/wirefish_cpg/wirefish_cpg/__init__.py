"""Ijspeert CPG node and PSO gait tuner service for the wire-driven elastic robotic fish."""
