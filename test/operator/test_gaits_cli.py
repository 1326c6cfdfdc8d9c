# SPDX-License-Identifier: Apache-2.0
"""`wirefish gaits build | list | plot` on a library file of the test's own."""

from pathlib import Path
import subprocess
import sys

import pytest
from wirefish_cpg.gait_library import load_library


def gaits(python: str, library, *options: str) -> subprocess.CompletedProcess:
    action, *rest = options
    return subprocess.run([python, '-m', 'wirefish_cli.cli', 'gaits', action, '--library',
                           str(library), *rest], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope='module')
def built(tmp_path_factory, python_module):
    library = tmp_path_factory.mktemp('gaits') / 'gaits.yaml'
    result = gaits(python_module, library, 'build', '--frequencies', '1,2.5',
                   '--scales', '1,1.5', '--workers', '2')
    return library, result


@pytest.fixture(scope='module')
def python_module():
    import sys
    return sys.executable


def test_build_fits_the_grid_stores_the_feasible_gaits_and_prints_the_table(built):
    library, result = built
    assert result.returncode == 0, result.stderr
    assert '3 of 4 gaits stored' in result.stdout
    assert 'rejected: the wave asks for servo rates' in result.stdout  # 2.5 Hz x 1.5
    assert result.stderr.splitlines()[-1].startswith('gaits build: 4/4, done in')  # no tty
    waves = sorted((g.wave.frequency_hz, g.wave.c1) for g in load_library(library).gaits)
    assert waves == [(1.0, 0.15), (1.0, 0.15 * 1.5), (2.5, 0.15)]


def test_list_shows_every_gait_with_its_scale_and_predicted_speed(built, python_module):
    library, _ = built
    result = gaits(python_module, library, 'list')
    assert result.returncode == 0, result.stderr
    rows = [line.split() for line in result.stdout.splitlines()[1:-1]]
    assert [(row[0], row[4]) for row in rows] == [('1', '1'), ('1', '1.5'), ('2.5', '1')]
    speeds = [float(row[7]) for row in rows]
    assert speeds[0] < speeds[1] and speeds[0] < speeds[2]  # larger or faster beats: faster
    assert '3 gaits in' in result.stdout


def test_plot_writes_the_speed_png(built, python_module, tmp_path):
    library, _ = built
    out = tmp_path / 'speed.png'
    result = gaits(python_module, library, 'plot', '--out', str(out))
    assert result.returncode == 0, result.stderr
    assert out.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


def test_plot_writes_into_out_by_default(built, tmp_path):
    library, _ = built
    result = subprocess.run([sys.executable, '-m', 'wirefish_cli.cli', 'gaits', 'plot',
                             '--library', str(library)], capture_output=True, text=True,
                            timeout=300, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert [p.relative_to(tmp_path) for p in tmp_path.rglob('*.png')] == [
        Path('out', 'gaits_speed.png')]


def test_an_unreadable_library_is_one_line_not_a_traceback(python_module, tmp_path):
    library = tmp_path / 'gaits.yaml'
    library.write_text('format: something else\n')
    result = gaits(python_module, library, 'list')
    assert result.returncode == 1
    assert 'not a wirefish_gait_library' in result.stderr and 'Traceback' not in result.stderr
