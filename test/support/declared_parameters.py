# SPDX-License-Identifier: Apache-2.0
"""The parameters each registry entry's node declares, read from its ``NodeParameters`` table."""

import ast
import importlib
from pathlib import Path

from wirefish_bringup.graph import NodeEntry
from wirefish_common.parameter_table import ParameterSpec

SRC = Path(__file__).resolve().parents[2] / 'src'
# Entries without a node class: the module of the table their process binds.
_TABLES_OF_PROCESSES = {'fish_sim': 'wirefish_sim.fish_sim_parameters'}


def tables_declared_in(module: str) -> list[tuple[str, str]]:
    """Return (module, name) of each table ``module`` binds (``NodeParameters(self, NAME)``)."""
    package, name = module.split('.')
    tree = ast.parse((SRC / package / package / f'{name}.py').read_text(encoding='utf-8'))
    imported = {a.asname or a.name: n.module for n in ast.walk(tree)
                if isinstance(n, ast.ImportFrom) for a in n.names}
    return [(imported.get(call.args[1].id, module), call.args[1].id) for call in ast.walk(tree)
            if isinstance(call, ast.Call) and isinstance(call.func, ast.Name)
            and call.func.id == 'NodeParameters' and len(call.args) >= 2
            and isinstance(call.args[1], ast.Name)]


def declared_specs(entry: NodeEntry) -> list[ParameterSpec]:
    """Return the ParameterSpecs the node of ``entry`` declares (empty if none is known)."""
    if entry.name in _TABLES_OF_PROCESSES:
        return list(importlib.import_module(_TABLES_OF_PROCESSES[entry.name]).TABLE)
    if entry.node_class is None:
        return []
    specs: list[ParameterSpec] = []
    for module, table in tables_declared_in(entry.node_class.split(':')[0]):
        specs += list(getattr(importlib.import_module(module), table))
    return specs
