# SPDX-License-Identifier: Apache-2.0
"""The fixtures of the cpg_node and tuner_node process tests, shared with test/support."""

from cpg_fixtures import library_path, probe, tuner  # noqa: F401 (fixtures, found by name)
