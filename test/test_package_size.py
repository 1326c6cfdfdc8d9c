# SPDX-License-Identifier: Apache-2.0
"""
No package grows past 2,000 lines of code without a reason in ARCHITECTURE.md.

A package that size holds more than one purpose; its reason, if it must, is written in the
**Sizes.** paragraph of docs/ARCHITECTURE.md, which must then name it. How many modules a
package has is not counted: a module holds one idea, and modules are split or merged by what
they hold, at review (the rule is in that paragraph), never to meet a number.
"""

from pathlib import Path
import re

import pytest

pytestmark = pytest.mark.linter
WORKSPACE = Path(__file__).resolve().parents[1]
MAX_LINES = 2000
PACKAGES = sorted(path.parent for path in (WORKSPACE / 'src').glob('*/setup.py'))


def lines_of_code(path: Path) -> int:
    """Return the lines of ``path`` that are neither blank nor a comment."""
    return sum(1 for line in path.read_text().splitlines()
               if line.strip() and not line.strip().startswith('#'))


def size(package: Path) -> int:
    """Return the lines of code of a package's Python modules."""
    return sum(lines_of_code(path) for path in sorted((package / package.name).rglob('*.py')))


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
    lines = size(package)
    if lines > MAX_LINES:
        assert f'`{package.name}`' in excused(), (
            f'{package.name}: {lines} lines of code (limit {MAX_LINES}): split it, or give its '
            f'reason in ARCHITECTURE.md **Sizes.**')
