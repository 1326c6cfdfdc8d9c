# SPDX-License-Identifier: Apache-2.0
"""The gait library: records, look-up by wave and geometry, the YAML file written atomically."""

import math
import os
from pathlib import Path

import pytest
from wirefish_cpg.gait_library import (default_library_path, Gait, GaitLibrary, LibraryFile,
                                       load_library, save_library)
from wirefish_cpg.oscillator import CpgParameters
from wirefish_kinematics.wave_spec import WaveSpec

GEOMETRY = {'l1': 0.08, 'l2': 0.1, 'l3': 0.06, 'r1': 0.02, 'r2': 0.012, 'rd1': 0.018,
            'rd2': 0.018}


def gait(wave=WaveSpec(), geometry=None, loss=4.13e-4) -> Gait:
    params = CpgParameters(frequency_hz=1.155, amplitude=(0.518, -0.6004), w12=-3.1,
                           w21=7.2, phi12=0.3, phi21=-2.9, alpha=20.0)
    return Gait(wave=wave, geometry=tuple(sorted((geometry or GEOMETRY).items())),
                params=params, loss=loss, rmse_theta_deg=(0.2529, 0.8636))


def test_a_gait_is_found_for_its_wave_and_geometry_only():
    library = GaitLibrary().with_gait(gait())
    assert library.find(WaveSpec(), GEOMETRY) == library.gaits[0]
    assert library.find(WaveSpec(frequency_hz=1.5), GEOMETRY) is None
    assert library.find(WaveSpec(), {**GEOMETRY, 'l2': 0.11}) is None


def test_a_new_fit_of_the_same_wave_replaces_the_old_one():
    library = GaitLibrary().with_gait(gait(loss=1e-3)).with_gait(gait(loss=4e-4))
    assert len(library.gaits) == 1 and library.gaits[0].loss == 4e-4


def test_the_file_round_trips_exactly(tmp_path):
    wave = WaveSpec(c1=0.1 + 0.2, c2=1.0 / 3.0, k=8.0, frequency_hz=1.1)  # floats with tails
    library = GaitLibrary().with_gait(gait()).with_gait(gait(wave=wave))
    path = tmp_path / 'sub' / 'gaits.yaml'
    save_library(library, path)
    assert load_library(path) == library
    text = path.read_text()
    assert text.startswith('format: wirefish_gait_library\nversion: 1\n')
    assert 'rmse_theta_deg: [0.2529, 0.8636]' in text


def test_saving_leaves_no_temporary_file_and_replaces_the_old(tmp_path):
    path = tmp_path / 'gaits.yaml'
    save_library(GaitLibrary().with_gait(gait()), path)
    save_library(GaitLibrary(), path)
    assert os.listdir(tmp_path) == ['gaits.yaml']
    assert load_library(path) == GaitLibrary()


def test_a_missing_file_is_an_empty_library(tmp_path):
    assert load_library(tmp_path / 'none.yaml') == GaitLibrary()


@pytest.mark.parametrize('text, words', [
    ('format: other\nversion: 1\n', 'not a wirefish_gait_library'),
    ('format: wirefish_gait_library\nversion: 7\n', 'version 7'),
    ('format: wirefish_gait_library\nversion: 1\ngaits: [{wave: {}}]\n', 'lacks'),
    ('{{{', 'not YAML'),
])
def test_a_bad_file_is_refused_with_the_reason(tmp_path, text, words):
    path = tmp_path / 'gaits.yaml'
    path.write_text(text)
    with pytest.raises(ValueError, match=words):
        load_library(path)


def test_a_ros_home_of_ones_own_holds_the_library(tmp_path):
    environ = {'ROS_HOME': '/data/ros', 'HOME': '/home/u'}
    workspace = tmp_path / 'ws'
    (workspace / 'src').mkdir(parents=True)
    prefix = workspace / 'install' / 'wirefish_cpg'
    assert default_library_path(environ, prefix) == Path('/data/ros/wirefish/gaits.yaml')


@pytest.mark.parametrize('prefix', ['install/wirefish_cpg', 'install'])  # isolated, merged
def test_each_workspace_has_its_library_in_its_out(tmp_path, prefix):
    libraries = []
    for clone in ('clone_a', 'clone_b'):
        (tmp_path / clone / 'src').mkdir(parents=True)
        libraries.append(default_library_path({'HOME': '/home/u'}, tmp_path / clone / prefix))
    assert libraries == [tmp_path / 'clone_a' / 'out' / 'gaits.yaml',
                         tmp_path / 'clone_b' / 'out' / 'gaits.yaml']


def test_outside_a_workspace_the_library_is_the_users(tmp_path):
    prefix = Path('/opt/ros/jazzy')
    assert default_library_path({'HOME': '/home/u'}, prefix) == Path(
        '/home/u/.ros/wirefish/gaits.yaml')


def test_this_workspaces_library_is_found_from_the_ament_index():
    root = Path(__file__).resolve().parents[3]
    assert default_library_path({'HOME': '/home/u'}) == root / 'out' / 'gaits.yaml'


def test_a_record_with_a_non_finite_loss_is_refused():
    record = gait().to_record()
    record['loss'] = math.inf
    with pytest.raises(ValueError):
        Gait.from_record(record)


def test_the_shared_file_merges_what_another_writer_added(tmp_path):
    path = tmp_path / 'gaits.yaml'
    mine, theirs = LibraryFile(path), LibraryFile(path)
    mine.add([gait()])
    theirs.add([gait(wave=WaveSpec(frequency_hz=1.5))])
    assert len(mine.current().gaits) == 2  # re-read: the file changed
    mine.add([gait(wave=WaveSpec(frequency_hz=2.0))])
    assert len(load_library(path).gaits) == 3


def test_a_writer_removes_the_temporary_file_a_killed_writer_left(tmp_path):
    path = tmp_path / 'gaits.yaml'
    stale = tmp_path / '.gaits.yaml.abc123.tmp'
    stale.write_text('format: wirefish_gait_lib')  # cut short by a SIGKILL
    LibraryFile(path).add([gait()])
    assert sorted(p.name for p in tmp_path.iterdir()) == ['gaits.yaml', 'gaits.yaml.lock']
