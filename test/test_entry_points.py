# SPDX-License-Identifier: Apache-2.0
"""
Importing a package changes no signal handler; each executable holds its stops itself.

``wirefish_common.startup_signals.hold_stop_signals`` keeps a Ctrl-C that arrives while a node's
modules import. It is called by the function ``console_scripts`` names (the package's
``executables`` module), first, before that function imports anything else: called from a
package's ``__init__`` it would act on every import (a test, a tool), and called after the
node's imports it would hold nothing. Read from the sources and the installed entry points,
and seen in a process: each executable's SIGTERM handler when its first heavy import (rclpy,
numpy) begins.
"""

import ast
from importlib.metadata import entry_points
from pathlib import Path
import subprocess
import sys

import pytest

SRC = Path(__file__).resolve().parents[1] / 'src'
INITS = sorted(SRC.glob('*/wirefish_*/__init__.py'))
HOLD = 'hold_stop_signals'


def _names(tree: ast.AST) -> set[str]:
    """Return every name and attribute ``tree`` mentions, and every module it imports from."""
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    names |= {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
    names |= {n.module or '' for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    names |= {a.name for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))
              for a in n.names}
    return names


def signal_calls(source: str) -> set[str]:
    """Return the start-up signal names a module's text uses or imports (empty: none)."""
    return {name for name in _names(ast.parse(source))
            if 'startup_signals' in name or 'stop_signals' in name}


def holds_first(source: str, function: str) -> bool:
    """Whether ``function``'s first statement after its docstring is ``hold_stop_signals()``."""
    for node in ast.parse(source).body:
        if isinstance(node, ast.FunctionDef) and node.name == function:
            body = [s for s in node.body if not (isinstance(s, ast.Expr)
                                                 and isinstance(s.value, ast.Constant))]
            first = body[0] if body else None
            return (isinstance(first, ast.Expr) and isinstance(first.value, ast.Call)
                    and isinstance(first.value.func, ast.Name) and first.value.func.id == HOLD)
    return False


def wirefish_executables() -> list:
    """Return the installed ``console_scripts`` of the workspace's packages."""
    return sorted((e for e in entry_points(group='console_scripts')
                   if e.value.startswith('wirefish_')), key=lambda e: e.name)


def held_executables() -> list:
    """Return the entry points of the processes a launcher holds the stops of (the registry)."""
    from wirefish_bringup.graph import NodeSpec
    return [e for e in wirefish_executables()
            if NodeSpec(e.value.split('.')[0], e.name, e.name).releases_stop_signals]


# Runs ``module:function`` (argv[1]) with the arguments after it and prints the SIGTERM handler
# in force when the first heavy import begins (rclpy, numpy, or a module of the entry point's
# package but its ``executables``: the node's own), then ends the process there.
FIRST_HEAVY_IMPORT = """
import importlib, os, signal, sys
module, function = sys.argv[1].split(':')
package = module.split('.')[0]
class FirstHeavyImport:
    def find_spec(self, name, path=None, target=None):
        if name in ('rclpy', 'numpy') or (name.startswith(package + '.')
                                          and name != package + '.executables'):
            handler = signal.getsignal(signal.SIGTERM)
            print(name, getattr(handler, '__module__', ''), getattr(handler, '__name__', handler))
            sys.stdout.flush()
            os._exit(0)
sys.argv = [function, *sys.argv[2:]]
sys.meta_path.insert(0, FirstHeavyImport())
getattr(importlib.import_module(module), function)()
print('no heavy import')
"""


def handler_at_first_heavy_import(target: str, *arguments: str) -> str:
    """Return ``<module> <handler's module> <handler>`` as ``target`` starts its heavy imports."""
    return subprocess.run([sys.executable, '-c', FIRST_HEAVY_IMPORT, target, *arguments],
                          capture_output=True, text=True, timeout=60.0).stdout.strip()


@pytest.mark.linter
@pytest.mark.parametrize('init', INITS, ids=[p.parent.name for p in INITS])
def test_no_package_init_touches_the_signal_handlers(init):
    source = init.read_text(encoding='utf-8')
    assert not signal_calls(source) and 'signal' not in _names(ast.parse(source)), (
        f'{init.relative_to(SRC)} sets up signals on import: call it from the entry point')


def test_a_package_init_that_holds_signals_is_found():
    source = ('from wirefish_common.startup_signals import hold_stop_signals\n\n'
              'hold_stop_signals()\n')
    assert signal_calls(source) == {'wirefish_common.startup_signals', HOLD}


@pytest.mark.linter
def test_every_node_executable_holds_its_stops_first():
    """Every executable a launcher holds the stops of (the registry's, compose) releases them."""
    nodes = held_executables()
    assert len(nodes) >= 11, [e.name for e in nodes]
    wrong = []
    for point in nodes:
        module, _, function = point.value.partition(':')
        path = SRC / module.split('.')[0] / (module.replace('.', '/') + '.py')
        if not holds_first(path.read_text(encoding='utf-8'), function):
            wrong.append(f'{point.name} = {point.value}')
    assert not wrong, f'entry points that do not call {HOLD}() first: {wrong}'


def test_an_entry_point_that_imports_before_it_holds_is_found():
    late = ('def cpg_node() -> None:\n    """Run it."""\n'
            '    from wirefish_cpg.cpg_node import main\n    hold_stop_signals()\n    main()\n')
    early = late.replace('    from wirefish_cpg.cpg_node import main\n    hold_stop_signals()\n',
                         '    hold_stop_signals()\n    from wirefish_cpg.cpg_node import main\n')
    assert (holds_first(late, 'cpg_node'), holds_first(early, 'cpg_node')) == (False, True)


@pytest.mark.parametrize('point', held_executables(), ids=lambda e: e.name)
def test_the_stop_signals_are_held_before_the_heavy_imports(point):
    seen = handler_at_first_heavy_import(point.value)
    assert seen.split()[1:] == ['wirefish_common.startup_signals', '_end_at_once'], seen


def test_a_node_module_imported_without_its_entry_point_is_unheld():
    seen = handler_at_first_heavy_import('wirefish_cpg.cpg_node:main')
    assert seen.split()[0] == 'wirefish_cpg.cpg_node' and '_end_at_once' not in seen, seen
