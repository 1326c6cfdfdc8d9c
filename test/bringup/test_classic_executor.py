# SPDX-License-Identifier: Apache-2.0
"""
One fish on the classic executor (WIREFISH_EXECUTOR=classic), the fallback executor.

Every other test runs the graph on the default, the events executor; this one runs it the old
way, one process per node and in one process, and checks that every stream still arrives at the
rate the registry promises in simulated time (as test_whole_graph.py does on the events
executor) and that the graph stops cleanly, so the fallback does not rot.
"""

import signal

from e2e_utils import (descendants, measure_simulated_rates, rate_problem, SimulatedTime,
                       start_graph)
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from wirefish_bringup.graph import expected_rates

pytestmark = pytest.mark.ros
# The registry's streams: nominal rates (Hz) at the default parameters, and the slow topics'
# least rates; measured as test_whole_graph.py measures them.
EXPECTED_RATES_HZ, EXPECTED_MIN_RATES_HZ = expected_rates(sim=True)
RATE_TOLERANCE = 0.05  # over 5 s of the graph's simulated time (see test_whole_graph.py)
WINDOW_S = 5.0


def _full(namespace: str, topic: str) -> str:
    return topic if topic.startswith('/') else f'{namespace}/{topic}'


@pytest.mark.parametrize('options', [(), ('--single-process',)], ids=['per-node', 'single'])
def test_a_fish_on_the_classic_executor_streams_at_the_registry_rates_and_stops_cleanly(
        e2e_domain_id, tmp_path, monkeypatch, options):
    monkeypatch.setenv('WIREFISH_EXECUTOR', 'classic')
    namespace = '/e2e_classic_' + ('single' if options else 'per_node')
    graph = start_graph(e2e_domain_id, tmp_path, *options, namespace=namespace)
    children = descendants(graph.launcher.pid)
    try:
        # The choice reaches every node process through the launcher's environment.
        nodes = [p for p in children if '--ros-args' in p.cmdline()]
        assert nodes and all(p.environ().get('WIREFISH_EXECUTOR') == 'classic' for p in nodes)
        monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        context = rclpy.context.Context()
        rclpy.init(context=context, domain_id=e2e_domain_id)
        node = rclpy.create_node('e2e_classic_probe', context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        wanted = [_full(namespace, t) for t in [*EXPECTED_RATES_HZ, *EXPECTED_MIN_RATES_HZ]]
        try:
            assert spin_until(executor, lambda: all(node.count_publishers(t) for t in wanted),
                              timeout_s=30.0), 'topics missing'
            rates = measure_simulated_rates(node, executor, namespace, WINDOW_S,
                                            SimulatedTime(node, namespace), wall_timeout_s=60.0)
        finally:
            executor.shutdown()
            node.destroy_node()
            rclpy.try_shutdown(context=context)
        measured = {t: rates[_full(namespace, t)][1]
                    for t in [*EXPECTED_RATES_HZ, *EXPECTED_MIN_RATES_HZ]}
        print({t: round(hz, 2) for t, hz in measured.items()})
        off_rate = [problem for t, nominal in EXPECTED_RATES_HZ.items()
                    if (problem := rate_problem(t, measured[t], nominal, RATE_TOLERANCE))]
        too_slow = {t: (round(measured[t], 2), least)
                    for t, least in EXPECTED_MIN_RATES_HZ.items() if measured[t] < least}
        assert not off_rate and not too_slow, (off_rate, '(measured, least) Hz', too_slow)
        graph.launcher.send_signal(signal.SIGINT)
        code = graph.launcher.wait(timeout=15.0)
        output = graph.launcher.stdout.read()
    finally:
        if graph.launcher.poll() is None:
            graph.launcher.kill()
        graph.launcher.stdout.close()
        for child in children:
            if child.is_running():
                child.kill()
    assert code == 0, output
    stopped = next(line for line in output.splitlines() if line.startswith('stopped'))
    assert {item.split('=')[1] for item in stopped.split(': ', 1)[1].split(', ')} == {'0'}
    assert 'Traceback' not in output
    for log in tmp_path.glob('run_*/logs/*.log'):
        assert 'Traceback' not in log.read_text(), log.name
