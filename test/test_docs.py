# SPDX-License-Identifier: Apache-2.0
"""
docs/ and README.md say what the code is (pure: reads files and tables).

Each test names what the docs miss or cite wrongly, so a renamed module, a new topic, node,
parameter, package or message type fails here until the docs follow.
"""

import ast
import importlib
from pathlib import Path
import re

from declared_parameters import tables_declared_in
import pytest
from wirefish_bringup.graph import NODES

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / 'src'
README = ROOT / 'README.md'
ARCHITECTURE = ROOT / 'docs' / 'ARCHITECTURE.md'
CONTRACTS = ROOT / 'docs' / 'CONTRACTS.md'
REFERENCE = ROOT / 'docs' / 'REFERENCE.md'
FAULTS = ROOT / 'docs' / 'FAULTS.md'
PROFILING = ROOT / 'docs' / 'PROFILING.md'
SIM_README = SRC / 'wirefish_sim' / 'README.md'
BOOTSTRAP = ROOT / 'tools' / 'bootstrap.sh'
DOCS = (ARCHITECTURE, CONTRACTS)
# Docs whose cited `wirefish_pkg.module.Name` must exist.
CITING = (*DOCS, PROFILING)
# Every document a user reads: its cited files and its relative links must exist.
USER_DOCS = (README, ARCHITECTURE, CONTRACTS, REFERENCE, FAULTS, PROFILING,
             *sorted(SRC.glob('*/README.md')))
# A topic, service or action name given as a literal where a node or tool creates it.
_CREATED = re.compile(
    r'(?:create_(?:publisher|subscription|service)|ActionServer|ActionClient)'
    r"\(\s*(?:[\w.]+,\s*)?\w+,\s*'([^']+)'")
# A dotted wirefish name in backticks: `wirefish_pkg.module` or `wirefish_pkg.module.Name[.x]`.
_DOTTED = re.compile(r'`(wirefish_[a-z]+(?:\.[A-Za-z_][A-Za-z0-9_]*)+)')
# A repository path in backticks ending in .py or .md.
_PATH = re.compile(r'`((?:src|test|docs)/[\w./-]+\.(?:py|md))`')
# A relative markdown link's target, without its #anchor.
_LINK = re.compile(r'\]\((?!https?://|#)([^)#\s]+)(?:#[^)]*)?\)')


def _text(path: Path) -> str:
    return path.read_text(encoding='utf-8')


def _packages() -> list[str]:
    return sorted(p.name for p in SRC.iterdir() if (p / 'package.xml').exists())


def _source_files() -> list[Path]:
    return sorted(p for pkg in _packages() for p in (SRC / pkg / pkg).glob('*.py'))


def _created_names() -> set[str]:
    return {name for path in _source_files() for name in _CREATED.findall(_text(path))}


def parameter_tables() -> list[tuple[str, str]]:
    """
    Return (module, name) of the table each registry node declares: ``declare(self, NAME, ...)``.

    Read from each node class's module, so a node added to the registry is checked too.
    """
    return [table for entry in NODES if entry.node_class is not None
            for table in tables_declared_in(entry.node_class.split(':')[0])]


def reference_table_names() -> set[str]:
    """Return the names in the first column of REFERENCE.md's table of topics and services."""
    names: set[str] = set()
    in_table = False
    for line in _text(REFERENCE).splitlines():
        if line.startswith('| name | kind |'):
            in_table = True
        elif in_table and not line.startswith('|'):
            break
        elif in_table:
            names |= set(re.findall(r'`([^`]+)`', line.split('|')[1]))
    return names


def _defined_names(module_path: Path) -> dict[str, set[str]]:
    """Return the top-level names of a module, each with its class's attributes (if a class)."""
    names: dict[str, set[str]] = {}
    for node in ast.parse(_text(module_path)).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names[node.name] = set()
        elif isinstance(node, ast.ClassDef):
            names[node.name] = {n.name for n in node.body
                                if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
            names[node.name] |= {t.id for n in node.body if isinstance(n, ast.AnnAssign)
                                 for t in [n.target] if isinstance(t, ast.Name)}
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update({t.id: set() for t in targets if isinstance(t, ast.Name)})
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update({(a.asname or a.name).split('.')[0]: set() for a in node.names})
    return names


def _dotted_problem(dotted: str) -> str | None:
    """Return why ``dotted`` names nothing in src/, or None if it does."""
    package, *rest = dotted.split('.')
    if not rest:
        return None
    if package == 'wirefish_msgs' or not (SRC / package).is_dir():
        return None if (SRC / package).is_dir() else f'no package {package}'
    folder = SRC / package / package
    while len(rest) > 1 and (folder / rest[0] / '__init__.py').is_file():  # a subpackage
        folder, package, rest = folder / rest[0], f'{package}.{rest[0]}', rest[1:]
    module = folder / f'{rest[0]}.py'
    if not module.exists():
        return f'no module {package}.{rest[0]}'
    if len(rest) == 1:
        return None
    defined = _defined_names(module)
    if rest[1] not in defined:
        return f'{package}.{rest[0]} defines no {rest[1]}'
    if len(rest) > 2 and defined[rest[1]] and rest[2] not in defined[rest[1]]:
        return f'{package}.{rest[0]}.{rest[1]} has no {rest[2]}'
    return None


@pytest.mark.parametrize('package', _packages())
def test_every_package_has_its_row_in_the_architecture(package):
    assert f'| `{package}` |' in _text(ARCHITECTURE)


def readme_packages(text: str) -> list[str]:
    """Return the packages the first column of README.md's package table names, in order."""
    rows = [line.split('|')[1] for line in text.splitlines()
            if line.startswith('| ') and 'wirefish_' in line.split('|')[1]]
    return [name for row in rows for name in re.findall(r'`(wirefish_\w+)`', row)]


def reference_packages(text: str) -> list[str]:
    """Return the packages REFERENCE.md's source layout names (lines ``src/wirefish_x ...``)."""
    return [name for line in text.splitlines() if line.startswith('src/wirefish_')
            for name in re.findall(r'src/(wirefish_\w+)', line.split('  ')[0])]


PACKAGE_LISTS = ((README, readme_packages), (REFERENCE, reference_packages))


@pytest.mark.parametrize('doc, listed', PACKAGE_LISTS, ids=[d.name for d, _ in PACKAGE_LISTS])
def test_the_package_list_names_every_package_once(doc, listed):
    names = listed(_text(doc))
    repeated = sorted({n for n in names if names.count(n) > 1})
    missing, unknown = set(_packages()) - set(names), set(names) - set(_packages())
    assert names and not (missing or unknown or repeated), (
        f'{doc.name}: the package list misses {sorted(missing)}, '
        f'no such package {sorted(unknown)}, named twice {repeated}')


def test_a_package_list_is_read_from_its_table_and_its_layout():
    table = ('| package | what |\n|---|---|\n| [`wirefish_cpg`](x) | the CPG |\n'
             '| `wirefish_bag`, `wirefish_operator` | verbs |\n| `other` | `wirefish_tf` |\n')
    layout = ('src/wirefish_msgs         msgs\nsrc/wirefish_fish, src/wirefish_shore   hosts\n'
              'test/                     not src/wirefish_x\n')
    assert readme_packages(table) == ['wirefish_cpg', 'wirefish_bag', 'wirefish_operator']
    assert reference_packages(layout) == ['wirefish_msgs', 'wirefish_fish', 'wirefish_shore']


def setup_needs(bootstrap: str) -> list[str]:
    """Return the commands ``tools/bootstrap.sh`` stops without (its ``need CMD PKG`` lines)."""
    return re.findall(r'(?m)^need (\S+) \S+$', bootstrap)


def readme_setup_needs(readme: str) -> str:
    """Return README.md's paragraph that begins "Setup needs"."""
    match = re.search(r'(?ms)^Setup needs.*?(?:\n\n|\Z)', readme)
    assert match, 'README.md has no "Setup needs" paragraph'
    return match.group(0)


def test_the_readme_names_every_tool_the_setup_stops_without():
    bootstrap = _text(BOOTSTRAP)
    needs, paragraph = setup_needs(bootstrap), readme_setup_needs(_text(README))
    python = re.search(r'WIREFISH_PYTHON:-python(3\.\d+)', bootstrap)
    missing = [cmd for cmd in needs if f'`{cmd}`' not in paragraph]
    assert needs and python, 'tools/bootstrap.sh: no need lines or no default Python'
    assert not missing and f'CPython {python.group(1)}' in paragraph, (
        f'README.md "Setup needs" leaves out {missing} (or CPython {python.group(1)})')


def test_a_setup_need_is_read_from_the_bootstrap():
    assert setup_needs('need cmake cmake\nneed c++ g++\n  need x y\nneeded z\n') == [
        'cmake', 'c++']


@pytest.mark.parametrize('doc', DOCS, ids=[d.name for d in DOCS])
def test_every_registry_entry_is_named(doc):
    missing = [e.name for e in NODES if f'`{e.name}`' not in _text(doc)
               and e.name not in _text(doc)]
    assert not missing, f'{doc.name} does not name the registry entries {missing}'


def test_the_code_creates_topics_services_and_actions_to_be_found():
    assert {'servo_cmd', 'imu/data', 'retune_gait', 'start'} <= _created_names()


def test_every_topic_service_and_action_the_code_creates_is_in_the_contracts():
    missing = sorted(n for n in _created_names() if f'`{n}`' not in _text(CONTRACTS))
    assert not missing, f'CONTRACTS.md lacks {missing}'


def test_every_node_class_of_the_registry_declares_a_table_found_here():
    found = {module.split('.')[0] for module, _ in parameter_tables()}
    assert found == {e.package for e in NODES if e.node_class is not None}


def test_the_reference_topic_table_lists_what_the_code_creates():
    listed, created = reference_table_names(), _created_names()
    stale, missing = listed - created, created - listed
    assert listed and not stale and not missing, (
        f'REFERENCE.md topic table: {sorted(stale)} created nowhere, {sorted(missing)} not listed')


@pytest.mark.parametrize('module, table', parameter_tables())
def test_every_declared_parameter_is_in_the_contracts(module, table):
    specs = getattr(importlib.import_module(module), table)
    missing = [s.name for s in specs if f'`{s.name}`' not in _text(CONTRACTS)]
    assert not missing, f'CONTRACTS.md lacks the {module} parameters {missing}'


def test_every_message_type_is_in_the_contracts():
    kinds = [f'{p.parent.name}/{p.stem}' for p in sorted((SRC / 'wirefish_msgs').glob('*/*'))
             if p.suffix in ('.msg', '.srv', '.action')]
    missing = [k for k in kinds if f'`{k}`' not in _text(CONTRACTS)]
    assert kinds and not missing, f'CONTRACTS.md lacks the message types {missing}'


@pytest.mark.parametrize('doc', CITING, ids=[d.name for d in CITING])
def test_every_cited_module_and_name_exists(doc):
    cited = sorted(set(_DOTTED.findall(_text(doc))))
    problems = [p for p in map(_dotted_problem, cited) if p is not None]
    assert cited and not problems, f'{doc.name}: {problems}'


@pytest.mark.parametrize('doc', USER_DOCS, ids=[d.name for d in USER_DOCS])
def test_every_cited_file_exists(doc):
    missing = [p for p in _PATH.findall(_text(doc)) if not (ROOT / p).exists()
               and 'foo_node' not in p]
    assert not missing, f'{doc.name} cites files that do not exist: {missing}'


@pytest.mark.parametrize('doc', USER_DOCS, ids=[d.name for d in USER_DOCS])
def test_every_relative_link_leads_to_a_file(doc):
    missing = [target for target in _LINK.findall(_text(doc))
               if not (doc.parent / target).exists()]
    assert not missing, f'{doc.name} links to files that do not exist: {missing}'


@pytest.mark.parametrize('dotted, problem', [
    ('wirefish_bridge.codec.FrameEncoder.encode', None),
    ('wirefish_bridge.codec.FrameDecoder', 'wirefish_bridge.codec defines no FrameDecoder'),
    ('wirefish_bridge.nothing', 'no module wirefish_bridge.nothing'),
    ('wirefish_launcher.verb.nothing', 'no module wirefish_launcher.verb.nothing'),
    ('wirefish_launcher.verb.up.nothing', 'wirefish_launcher.verb.up defines no nothing'),
    ('wirefish_bridge.codec.FrameEncoder.decode',
     'wirefish_bridge.codec.FrameEncoder has no decode'),
])
def test_a_wrong_citation_is_found(dotted, problem):
    assert _dotted_problem(dotted) == problem


def documented_flags(text: str, heading: str) -> set[str]:
    """Return the --flags in the first column of the flag tables under ``## <heading>...``."""
    flags: set[str] = set()
    for section in re.split(r'(?m)^## ', text)[1:]:
        if section.startswith(heading):
            rows = [line.split('|')[1] for line in section.splitlines()
                    if line.startswith('| `--')]
            flags |= {flag for row in rows for flag in re.findall(r'`(--[a-z-]+)', row)}
    return flags


def _fish_sim_flags() -> set[str]:
    from wirefish_sim.fish_sim import build_parser

    return {a.option_strings[-1] for a in build_parser()._actions
            if a.option_strings and a.dest != 'help'}


def test_the_sim_readme_documents_exactly_fish_sims_flags():
    flags, documented = _fish_sim_flags(), documented_flags(_text(SIM_README), 'fish_sim')
    assert documented == flags, (f'not flags of fish_sim: {sorted(documented - flags)}; '
                                 f'undocumented: {sorted(flags - documented)}')


@pytest.mark.parametrize('readme', sorted(SRC.glob('*/README.md')),
                         ids=[p.parent.name for p in sorted(SRC.glob('*/README.md'))])
def test_no_readme_documents_a_flag_fish_sim_lacks(readme):
    stale = sorted(documented_flags(_text(readme), 'fish_sim') - _fish_sim_flags())
    assert not stale, f'{readme.relative_to(ROOT)} documents fish_sim flags it lacks: {stale}'


def test_a_stale_flag_is_found():
    text = '## fish_sim (virtual fish)\n| `--speed-time-constant` | 0.75 s | |\n## Other\n'
    assert documented_flags(text, 'fish_sim') == {'--speed-time-constant'}


# The folders of test/ that name no package: the firmware's two roads and the shared helpers.
TEST_FOLDERS_BESIDE_PACKAGES = {'firmware', 'firmware_qemu', 'support'}


def workspace_test_modules(text: str) -> set[str]:
    """Return the top-level test modules that ARCHITECTURE's Tests table lists."""
    tests = text.split('\n## Tests\n', 1)[1].split('\n## ', 1)[0]
    return set(re.findall(r'^\| `(test_\w+\.py)` \|', tests, flags=re.MULTILINE))


def test_every_folder_of_test_names_a_package_or_the_firmware():
    packages = {p.name.removeprefix('wirefish_') for p in SRC.iterdir()
                if (p / 'package.xml').is_file()}
    folders = {p.name for p in (ROOT / 'test').iterdir()
               if p.is_dir() and not p.name.startswith(('.', '__'))}
    strays = folders - packages - TEST_FOLDERS_BESIDE_PACKAGES
    assert folders and not strays, f'test/ folders naming no package: {sorted(strays)}'


def test_every_module_at_the_top_of_test_is_a_listed_workspace_wide_one():
    listed = workspace_test_modules(_text(ARCHITECTURE))
    found = {p.name for p in (ROOT / 'test').glob('test_*.py')}
    assert listed and found == listed, (
        f'ARCHITECTURE.md Tests: unlisted {sorted(found - listed)}, gone {sorted(listed - found)}')
