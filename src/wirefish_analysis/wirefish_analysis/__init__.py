# SPDX-License-Identifier: Apache-2.0
"""Reproduce, sweep, calibrate and plot the paper's results; the benchmarks."""
