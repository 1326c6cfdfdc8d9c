"""
No package grows past 2,000 lines of code or 15 modules without a reason in ARCHITECTURE.md.

A package that size holds more than one purpose; its reason, if it must, is written in the
**Sizes.** paragraph of docs/ARCHITECTURE.md, which must then name it.
"""

from pathlib import Path
import re

import pytest

pytestmark = pytest.mark.linter
WORKSPACE = Path(__file__).resolve().parents[1]
MAX_LINES = 2000
MAX_MODULES = 15
PACKAGES = sorted(path.parent for path in (WORKSPACE / 'src').glob('*/setup.py'))


def lines_of_code(path: Path) -> int:
    """Return the lines of ``path`` that are neither blank nor a comment."""
    return sum(1 for line in path.read_text().splitlines()
               if line.strip() and not line.strip().startswith('#'))


def size(package: Path) -> tuple[int, int]:
    """Return (lines of code, modules) of a package; an ``__init__`` is not a module."""
    modules = sorted((package / package.name).rglob('*.py'))
    return (sum(lines_of_code(path) for path in modules),
            sum(1 for path in modules if path.name != '__init__.py'))


def excused() -> str:
    """Return the **Sizes.** paragraph of ARCHITECTURE.md."""
    text = (WORKSPACE / 'docs' / 'ARCHITECTURE.md').read_text()
    match = re.search(r'\*\*Sizes\.\*\*(.*?)\n\n', text, re.DOTALL)
    assert match, 'docs/ARCHITECTURE.md has no **Sizes.** paragraph'
    return match.group(1)


def test_lines_of_code_leave_out_blanks_and_comments(tmp_path):
    path = tmp_path / 'm.py'
    path.write_text('import os\n\n# why\n    # indented why\nx = 1  # trailing\n')
    assert lines_of_code(path) == 2


@pytest.mark.parametrize('package', PACKAGES, ids=lambda p: p.name)
def test_a_package_is_small_or_says_why(package):
    lines, modules = size(package)
    if lines > MAX_LINES or modules > MAX_MODULES:
        assert f'`{package.name}`' in excused(), (
            f'{package.name}: {lines} lines of code in {modules} modules (limits {MAX_LINES}, '
            f'{MAX_MODULES}): split it, or give its reason in ARCHITECTURE.md **Sizes.**')
