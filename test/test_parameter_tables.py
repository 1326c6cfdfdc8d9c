# SPDX-License-Identifier: Apache-2.0
"""Every node's parameter table is its package's ``<node>_parameters`` module, without rclpy."""

import importlib
from pathlib import Path
import subprocess
import sys

from declared_parameters import tables_declared_in
import pytest

SRC = Path(__file__).resolve().parents[1] / 'src'
NODE_MODULES = sorted(f'{path.parent.name}.{path.stem}'
                      for path in SRC.glob('*/wirefish_*/*_node.py'))
# (node module, table module, table name) of every node module's declare(self, TABLE, ...).
TABLES = [(node, *table) for node in NODE_MODULES for table in tables_declared_in(node)]


def test_the_nodes_with_tables_are_all_found():
    assert {node for node, _, _ in TABLES} >= {
        'wirefish_bridge.bridge_node', 'wirefish_cpg.cpg_node',
        'wirefish_kinematics.kinematics_node', 'wirefish_planner.planner_node',
        'wirefish_tf.tf_node', 'wirefish_tuner.tuner_node', 'wirefish_view.view_node'}


@pytest.mark.parametrize('node, module, table', TABLES)
def test_a_node_declares_the_table_of_its_parameters_module(node, module, table):
    assert module == f'{node}_parameters'
    assert isinstance(getattr(importlib.import_module(module), table), tuple)


@pytest.mark.parametrize('module', sorted({module for _, module, _ in TABLES}))
def test_a_parameters_module_imports_no_rclpy(module):
    code = f'import sys, {module}; sys.exit("rclpy" in sys.modules)'
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0, module
