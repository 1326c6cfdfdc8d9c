"""`wirefish up --single-process`: a retune with apply reaches the CPG in the same process."""

import signal
import subprocess
import sys

from e2e_utils import start_graph
import pytest

pytestmark = pytest.mark.ros


def test_retune_with_apply_succeeds_when_all_nodes_share_one_process(e2e_domain_id, tmp_path,
                                                                     monkeypatch):
    # A gait library of this test's own: a wave fitted by an earlier run is not fitted again.
    monkeypatch.setenv('ROS_HOME', str(tmp_path / 'ros_home'))
    graph = start_graph(e2e_domain_id, tmp_path, '--single-process',
                        namespace='/e2e_single_process')
    try:
        result = subprocess.run(
            [sys.executable, '-m', 'wirefish_cli.cli', 'retune', '--namespace',
             graph.namespace, '--apply', '--iterations', '30', '--timeout', '60'],
            env=graph.env, capture_output=True, text=True, timeout=120)
    finally:
        graph.launcher.send_signal(signal.SIGINT)
        code = graph.launcher.wait(timeout=20.0)
        output = graph.launcher.stdout.read()
        graph.launcher.stdout.close()
    assert result.returncode == 0, result.stderr
    assert 'fitted and applied' in result.stdout
    assert code == 0, output
    for log in tmp_path.glob('run_*/logs/*.log'):
        assert 'Traceback' not in log.read_text(), log.name
