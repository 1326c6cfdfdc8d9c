"""
Importing a package changes no signal handler; each executable holds its stops itself.

``wirefish_common.startup_signals.hold_stop_signals`` keeps a Ctrl-C that arrives while a node's
modules import. It is called by the function ``console_scripts`` names (the package's
``executables`` module), first, before that function imports anything else: called from a
package's ``__init__`` it would act on every import (a test, a tool), and called after the
node's imports it would hold nothing. Read from the sources and the installed entry points.
"""

import ast
from importlib.metadata import entry_points
from pathlib import Path

import pytest

pytestmark = pytest.mark.linter
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


@pytest.mark.parametrize('init', INITS, ids=[p.parent.name for p in INITS])
def test_no_package_init_touches_the_signal_handlers(init):
    source = init.read_text(encoding='utf-8')
    assert not signal_calls(source) and 'signal' not in _names(ast.parse(source)), (
        f'{init.relative_to(SRC)} sets up signals on import: call it from the entry point')


def test_a_package_init_that_holds_signals_is_found():
    source = ('from wirefish_common.startup_signals import hold_stop_signals\n\n'
              'hold_stop_signals()\n')
    assert signal_calls(source) == {'wirefish_common.startup_signals', HOLD}


def test_every_node_executable_holds_its_stops_first():
    """Every executable a launcher holds the stops of (the registry's, compose) releases them."""
    from wirefish_bringup.graph import NodeSpec
    nodes = [e for e in wirefish_executables()
             if NodeSpec(e.value.split('.')[0], e.name, e.name).releases_stop_signals]
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
