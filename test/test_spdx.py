# SPDX-License-Identifier: Apache-2.0
"""
Every source file names the workspace's licence in an SPDX line, as ament_copyright expects.

The licence is the one every package.xml declares (``<license>``); each source file (Python, C,
shell, JavaScript, CSS, HTML, linker scripts, Makefiles, CMake) carries
``SPDX-License-Identifier: <id>`` in its first lines, in its language's comment. Data (YAML,
JSON, message definitions, package.xml, Markdown) carries none: the licence covers it from the
repository. Files are read from git (tracked, and new files it does not ignore).
"""

from pathlib import Path
import re
import subprocess

import pytest

pytestmark = pytest.mark.linter
ROOT = Path(__file__).resolve().parents[1]
# The comment each kind of source file writes its SPDX line in.
COMMENT = {'.py': '# {}', '.sh': '# {}', '.mk': '# {}', '.cmake': '# {}', '.c': '/* {} */',
           '.h': '/* {} */', '.ld': '/* {} */', '.css': '/* {} */', '.js': '// {}',
           '.html': '<!-- {} -->'}
NAMED = {'Makefile': '# {}', 'CMakeLists.txt': '# {}'}
HEAD_LINES = 3  # after a shebang or a doctype, the line may be the second or third
_SPDX = re.compile(r'SPDX-License-Identifier: (\S+)')


def licence_ids(root: Path = ROOT) -> set[str]:
    """Return the licences the package.xml files declare."""
    return {match for path in sorted((root / 'src').glob('*/package.xml'))
            for match in re.findall(r'<license>([^<]+)</license>', path.read_text())}


def comment_of(path: Path) -> str | None:
    """Return the comment form of a source file's SPDX line, or None if it is not source."""
    if path.name in NAMED:
        return NAMED[path.name]
    if path.suffix in COMMENT:
        return COMMENT[path.suffix]
    if not path.suffix and path.is_file():  # a script: a shebang names its language
        with path.open('rb') as stream:
            first = stream.readline()
        if first.startswith(b'#!') and (b'sh' in first or b'python' in first):
            return '# {}'
    return None


def source_files(root: Path = ROOT) -> list[Path]:
    """Return the source files git knows of below ``root`` (tracked and not ignored)."""
    listed = subprocess.run(['git', '-C', str(root), 'ls-files', '--cached', '--others',
                             '--exclude-standard'], capture_output=True, text=True,
                            check=True).stdout.splitlines()
    paths = [root / name for name in sorted(set(listed))]
    return [p for p in paths if p.is_file() and comment_of(p) is not None]


def declared_licence(path: Path) -> str | None:
    """Return the SPDX id of ``path``'s first lines, or None."""
    with path.open(encoding='utf-8', errors='replace') as stream:
        head = [stream.readline() for _ in range(HEAD_LINES)]
    found = _SPDX.search(''.join(head))
    return found.group(1).rstrip('*/->') if found else None


def test_every_package_declares_the_same_licence():
    assert len(licence_ids()) == 1, licence_ids()


def test_every_source_file_carries_the_licence_in_an_spdx_line():
    (licence,) = licence_ids()
    files = source_files()
    wrong = [f'{p.relative_to(ROOT)}: {declared_licence(p)}' for p in files
             if declared_licence(p) != licence]
    assert len(files) > 400 and not wrong, (
        f'{len(wrong)} source files lack "SPDX-License-Identifier: {licence}" in their first '
        f'{HEAD_LINES} lines (after a shebang), e.g. {wrong[:10]}')


@pytest.mark.parametrize('name, text, licence', [
    ('a.py', '# SPDX-License-Identifier: Apache-2.0\n"""Doc."""\n', 'Apache-2.0'),
    ('run', '#!/usr/bin/env bash\n# SPDX-License-Identifier: MIT\nset -e\n', 'MIT'),
    ('a.c', '/* SPDX-License-Identifier: Apache-2.0 */\n#include <x.h>\n', 'Apache-2.0'),
    ('a.py', '"""Doc."""\n\n\n# SPDX-License-Identifier: Apache-2.0\n', None),
    ('a.h', '#pragma once\n', None),
])
def test_the_spdx_line_is_read_from_the_first_lines_only(tmp_path, name, text, licence):
    path = tmp_path / name
    path.write_text(text)
    assert comment_of(path) is not None
    assert declared_licence(path) == licence


def test_data_files_are_not_source(tmp_path):
    for name in ('a.yaml', 'b.json', 'C.msg', 'package.xml', 'README.md'):
        (tmp_path / name).write_text('x\n')
        assert comment_of(tmp_path / name) is None, name
