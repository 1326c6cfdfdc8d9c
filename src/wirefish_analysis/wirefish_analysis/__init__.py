"""Reproduce, sweep, calibrate and plot the paper's results; the benchmarks."""
