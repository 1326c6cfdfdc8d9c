# SPDX-License-Identifier: Apache-2.0
"""`wirefish up --params-file`: a refused parameter is said on the terminal, never restarted."""

import subprocess
import sys

from declared_parameters import declared_specs
from e2e_utils import lines_until_running
import pytest
from ros_utils import stop_process

NAMESPACE = '/params_warn'
BAD = """
cpg_node:                 # no namespace: rcl reads /cpg_node, not /params_warn/cpg_node
  ros__parameters:
    amplitude_1: 0.3
/**/cpg_node:
  ros__parameters:
    amplitude_1: 5.0      # beyond pi/2: cpg_node refuses it at start-up
/**:
  ros__parameters:
    l9: 0.1               # no node declares it
"""


def test_the_launchers_tables_are_the_nodes_declarations():
    from wirefish_bringup.graph import NODES
    from wirefish_launcher.params_overlay import declared_parameters

    for entry in NODES:
        names = {spec.name for spec in declared_specs(entry)}
        if names:
            assert names <= (declared_parameters(entry.name) or set()), entry.name


@pytest.mark.ros
def test_a_bad_params_file_is_said_on_the_terminal_and_not_restarted(ros_env, tmp_path):
    params = tmp_path / 'bad.yaml'
    params.write_text(BAD)
    up = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--no-status', '--namespace', NAMESPACE,
         '--out', str(tmp_path / 'out'), '--params-file', str(params)],
        env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    try:
        lines = lines_until_running(up, 120.0)
        text = ''.join(lines)
        assert "'cpg_node' matches no node" in text and '/**/cpg_node' in text, text
        assert "'l9' is no parameter" in text, text
        assert 'cpg_node refused its start-up parameters and is not restarted' in text, text
        assert 'amplitude_1' in text and 'out of range' in text, text
        assert 'restarting it' not in text, text
    finally:
        stop_process(up, timeout_s=15.0)
        up.stdout.close()
