# SPDX-License-Identifier: Apache-2.0
"""The shore-side PSO gait tuner (eqs 23-27): the retune_gait service and action."""
