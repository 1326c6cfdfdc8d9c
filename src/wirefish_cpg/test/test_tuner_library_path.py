# SPDX-License-Identifier: Apache-2.0
"""Which gait library a graph's tuner uses, as `wirefish up` says at start-up (pure: files)."""

from pathlib import Path

import pytest
from wirefish_cpg.gait_library import default_library_path, tuner_library_path

# The graph's default parameter file, as the workspace ships it (wirefish_bringup/config).
DEFAULT_PARAMS = (Path(__file__).resolve().parents[2] / 'wirefish_bringup' / 'config'
                  / 'wirefish.yaml')


def test_the_default_parameter_file_leaves_the_default_library():
    assert tuner_library_path(DEFAULT_PARAMS) == default_library_path()


@pytest.mark.parametrize('text, expected', [
    ('/**/tuner_node:\n  ros__parameters:\n    library_path: /data/a.yaml\n', '/data/a.yaml'),
    ('/**:\n  ros__parameters:\n    library_path: /data/all.yaml\n', '/data/all.yaml'),
    ('/**/tuner_node:\n  ros__parameters:\n    library_path: /data/tuner.yaml\n'
     '/**:\n  ros__parameters:\n    library_path: /data/all.yaml\n', '/data/tuner.yaml'),
])
def test_a_parameter_file_that_names_a_library_is_followed(tmp_path, text, expected):
    params = tmp_path / 'params.yaml'
    params.write_text(text)
    assert tuner_library_path(params) == Path(expected)


def test_a_parameter_file_without_one_leaves_the_default(tmp_path):
    params = tmp_path / 'params.yaml'
    params.write_text('/**/tuner_node:\n  ros__parameters:\n    swarm_size: 10\n')
    assert tuner_library_path(params) == default_library_path()
