# SPDX-License-Identifier: Apache-2.0
"""The node executables the benchmarks start are where the packages install them."""

import os

from wirefish_bench.bench_retune import tuner_executable


def test_the_retune_benchmarks_tuner_node_is_installed_and_executable():
    path = tuner_executable()
    assert path.is_file() and os.access(path, os.X_OK), path
