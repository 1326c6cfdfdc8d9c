# SPDX-License-Identifier: Apache-2.0
"""
One parameter mechanism: each node's table, bound one way, and the graph file's defaults.

Every node's parameters are one ``ParameterTable`` in its ``<node>_parameters`` module (no
rclpy), bound by ``NodeParameters`` and nothing else; ``config/wirefish.yaml`` repeats only
the tables' defaults (and the graph's choices listed below).
"""

import ast
import importlib
from pathlib import Path
import subprocess
import sys

from declared_parameters import tables_declared_in
import pytest
from wirefish_common.parameter_table import ParameterSpec, ParameterTable
from wirefish_launcher.params_overlay import PARAMETER_TABLES, PARAMETERS_KEY
import yaml

SRC = Path(__file__).resolve().parents[1] / 'src'
# Every module that makes a node with parameters: the *_node.py ones, the virtual fish and the
# fish's relay (their executables are in the registry under other names).
NODE_MODULES = sorted([f'{path.parent.name}.{path.stem}'
                       for path in SRC.glob('*/wirefish_*/*_node.py')]
                      + ['wirefish_sim.fish_sim', 'wirefish_relay.link_relay'])
# (node module, table module, table name) of every node module's NodeParameters(self, TABLE).
TABLES = [(node, *table) for node in NODE_MODULES for table in tables_declared_in(node)]
DEFAULTS_FILE = SRC / 'wirefish_bringup' / 'config' / 'wirefish.yaml'
# Values the graph's file sets on purpose away from the table's default: the graph's fish
# starts still (`wirefish up --start-swimming` sets them back), a cpg_node alone swims Table 1.
GRAPH_CHOICES = {('/**/cpg_node', 'amplitude_1'), ('/**/cpg_node', 'amplitude_2'),
                 ('/**/cpg_node', 'autostart')}
# What a node module may take from parameter_table: the binding and its start-up refusal.
_BINDING = {'NodeParameters', 'InvalidParameters'}
# Calls that declare, judge or apply parameters beside the binding.
_OTHER_WAYS = {'declare', 'declare_parameter', 'declare_parameters', 'validate_update',
               'add_on_set_parameters_callback', 'add_pre_set_parameters_callback',
               'add_post_set_parameters_callback'}


def other_declarations(source: str) -> list[str]:
    """
    Return each place ``source`` (a node module) handles parameters other than by the binding.

    The binding is one ``NodeParameters(self, TABLE, ...)``; ``declare_frame_prefix``
    (``wirefish_common.frames``) is the shared declaration of ``frame_prefix``, not a table's.
    """
    tree = ast.parse(source)
    problems = [f'line {node.lineno}: imports {alias.name} from parameter_table'
                for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                and (node.module or '').endswith('parameter_table')
                for alias in node.names if alias.name not in _BINDING]
    bindings = 0
    for call in ast.walk(tree):
        if not isinstance(call, ast.Call):
            continue
        name = (call.func.attr if isinstance(call.func, ast.Attribute)
                else call.func.id if isinstance(call.func, ast.Name) else '')
        bindings += name == 'NodeParameters'
        if name in _OTHER_WAYS:
            problems.append(f'line {call.lineno}: {name}(...)')
    if bindings > 1:
        problems.append(f'{bindings} NodeParameters: a node binds one table')
    return problems


def table_specs(node: str) -> dict[str, ParameterSpec]:
    """Return the specs of registry node ``node``'s table (PARAMETER_TABLES) by name."""
    module, attribute = PARAMETER_TABLES[node]
    table = getattr(importlib.import_module(module), attribute)
    return {spec.name: spec for spec in (table() if callable(table) else table)}


def default_problems(document: dict) -> list[str]:
    """
    Return each value of a parameter file that is not its table's default (type and value).

    A ``/**`` value is held against every table that declares its name; a name no table of
    its key's node declares is a problem too. A table entry the file leaves out runs on its
    table's default: the file is a readable subset of the tables, never a second source.
    """
    problems = []
    for key, block in document.items():
        node = key.rstrip('/').rsplit('/', 1)[-1]
        tables = ({name: table_specs(name) for name in PARAMETER_TABLES} if node == '**'
                  else {node: table_specs(node)})
        for name, value in (block.get(PARAMETERS_KEY) or {}).items():
            declaring = {n: specs[name] for n, specs in tables.items() if name in specs}
            if not declaring:
                problems.append(f'{key}: {name} is in no table of {", ".join(tables)}')
            for table, spec in declaring.items():
                same = type(value) is type(spec.default) and value == spec.default
                if (key, name) in GRAPH_CHOICES and same:
                    problems.append(f'{key}: {name} is listed as a graph choice but is the '
                                    f'{table} default')
                elif (key, name) not in GRAPH_CHOICES and not same:
                    problems.append(f'{key}: {name} = {value!r}, {table} default '
                                    f'{spec.default!r}')
    return problems


def test_the_nodes_with_tables_are_all_found():
    assert {node for node, _, _ in TABLES} >= {
        'wirefish_bridge.bridge_node', 'wirefish_cpg.cpg_node',
        'wirefish_kinematics.kinematics_node', 'wirefish_planner.planner_node',
        'wirefish_tf.tf_node', 'wirefish_tuner.tuner_node', 'wirefish_view.view_node',
        'wirefish_sim.fish_sim', 'wirefish_relay.link_relay'}


@pytest.mark.parametrize('node, module, table', TABLES)
def test_a_node_declares_the_table_of_its_parameters_module(node, module, table):
    assert module == f'{node}_parameters'
    assert isinstance(getattr(importlib.import_module(module), table), ParameterTable)


@pytest.mark.parametrize('module', sorted({module for _, module, _ in TABLES}))
def test_a_parameters_module_exports_its_table_and_its_rule(module):
    parameters = importlib.import_module(module)
    assert isinstance(parameters.TABLE, ParameterTable)
    assert parameters.TABLE.rule is parameters.RULE


@pytest.mark.parametrize('module', sorted({module for _, module, _ in TABLES}))
def test_a_parameters_module_imports_no_rclpy(module):
    code = f'import sys, {module}; sys.exit("rclpy" in sys.modules)'
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0, module


@pytest.mark.parametrize('node', NODE_MODULES)
def test_a_node_takes_its_parameters_only_through_the_binding(node):
    package, name = node.split('.')
    problems = other_declarations((SRC / package / package / f'{name}.py').read_text())
    assert not problems, f'{node}: {problems}'


def test_a_parameter_declared_beside_the_binding_is_found():
    source = ('from wirefish_common.parameter_table import declare, NodeParameters\n'
              'class N:\n'
              '    def __init__(self):\n'
              '        self._parameters = NodeParameters(self, TABLE)\n'
              "        self.declare_parameter('rate', 1.0)\n"
              '        self.add_on_set_parameters_callback(self._check)\n')
    assert other_declarations(source) == [
        'line 1: imports declare from parameter_table', 'line 5: declare_parameter(...)',
        'line 6: add_on_set_parameters_callback(...)']


def test_the_graph_parameter_file_repeats_the_tables_defaults():
    problems = default_problems(yaml.safe_load(DEFAULTS_FILE.read_text(encoding='utf-8')))
    assert not problems, problems


def test_a_file_value_away_from_its_default_is_found():
    document = {'/**/kinematics_node': {PARAMETERS_KEY: {'station_count': 51, 'wave_k': 8}},
                '/**': {PARAMETERS_KEY: {'l1': 0.08, 'nonsense': 1.0}},
                '/**/cpg_node': {PARAMETERS_KEY: {'autostart': True}}}
    assert default_problems(document) == [
        '/**/kinematics_node: station_count = 51, kinematics_node default 50',
        '/**/kinematics_node: wave_k = 8, kinematics_node default 8.0',
        f'/**: nonsense is in no table of {", ".join(PARAMETER_TABLES)}',
        '/**/cpg_node: autostart is listed as a graph choice but is the cpg_node default']
