"""`make test` deals the longest modules to its workers first (module_order.py)."""

from pathlib import Path
import subprocess

from module_order import LONGEST_MODULES, module_rank

WORKSPACE = Path(__file__).resolve().parents[1]


def test_every_longest_module_exists():
    missing = [name for name in LONGEST_MODULES if not (WORKSPACE / name).is_file()]
    assert not missing, f'renamed or gone (update LONGEST_MODULES): {missing}'


def test_the_longest_modules_rank_first_in_their_order():
    others = [WORKSPACE / 'test' / 'test_docs.py', WORKSPACE / 'test' / 'bridge' / 'test_a.py']
    paths = others + [WORKSPACE / name for name in reversed(LONGEST_MODULES)]
    ordered = sorted(paths, key=module_rank)
    assert ordered == [WORKSPACE / name for name in LONGEST_MODULES] + others


def test_make_test_deals_files_in_collection_order():
    # Without --no-loadscope-reorder xdist deals the files with most tests first, and the
    # one-test long modules come last whatever the collection order. `make -n` prints the
    # commands `make test` runs, without running them.
    commands = subprocess.run(['make', '-n', 'test'], cwd=WORKSPACE, capture_output=True,
                              text=True, check=True).stdout.replace('\\\n', ' ')
    run = next(line for line in commands.splitlines() if '--dist loadfile' in line)
    assert '--no-loadscope-reorder' in run.split() and 'test' in run.split()
