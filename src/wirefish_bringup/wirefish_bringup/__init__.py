# SPDX-License-Identifier: Apache-2.0
"""The graph's registry (every process, its role and rates), its launch file and parameters."""
