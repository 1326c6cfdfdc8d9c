# SPDX-License-Identifier: Apache-2.0
"""The benchmarks of `make bench`: each figure old against new in one run, into BENCHMARKS.md."""
