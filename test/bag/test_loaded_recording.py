# SPDX-License-Identifier: Apache-2.0
"""
A recording on a loaded machine keeps up, or says it did not.

One fish's graph is recorded for 30 s while a second graph runs beside it (same domain: its
discovery and traffic reach the recorder's participant too) and two busy loops hold both cores
(at nice 19, so the other tests of a full run are slowed no more than a batch job would slow
them; the graphs still share the cores with them). What the bag holds is checked from the bag
alone: no number missing from the publishers' sequences of the 100 Hz and 20 Hz streams, no
message that waited more than a second between its publication and the bag (the bound a
recording is held to; the recorder's poll is 0.05 s), and everything published before the
stop is in it.
"""

from pathlib import Path
import subprocess

from bag_utils import assert_bag_readable, publish_lags, sequence_gaps
from e2e_utils import OWN_NAMESPACE
import pytest

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

RECORDED, BESIDE = '/wf_loaded', '/wf_loaded_beside'
DURATION_S = 30
STREAMS = ('servo_cmd', 'imu/data', 'body_wave')
LAG_BOUND_S = 1.0
# A busy loop at the lowest priority: it takes whatever CPU nobody else wants.
HOG = 'import os\nos.nice(19)\nwhile True:\n    pass\n'


def _graph(spawn, python, namespace: str, out: Path):
    return spawn([python, '-m', 'wirefish_cli.cli', 'up', '--sim', '--no-status',
                  *OWN_NAMESPACE, '--namespace', namespace, '--out', str(out)])


def _assert_started(proc, namespace: str) -> None:
    """Assert that a graph started and still runs (its output so far is in the pipe)."""
    assert proc.poll() is None, f'{namespace} stopped'
    lines = []
    for line in proc.stdout:
        lines.append(line)
        if line.startswith('started '):
            return
    raise AssertionError(f'{namespace} never started:\n' + ''.join(lines))


def test_a_loaded_recording_loses_nothing_lags_little_and_drains(tmp_path, spawn, python,
                                                                 ros_env):
    # All at once: the recording's duration counts from its first message, once the graph
    # it records is up; the second graph and the busy loops load the machine from the start.
    graphs = {ns: _graph(spawn, python, ns, tmp_path / ns.strip('/')) for ns in (RECORDED, BESIDE)}
    for _ in range(2):
        spawn([python, '-c', HOG])
    bag = tmp_path / 'bag'
    result = subprocess.run(
        [python, '-m', 'wirefish_cli.cli', 'record', '-o', str(bag), '--namespace',
         RECORDED, '--duration', str(DURATION_S)],
        env=ros_env, capture_output=True, text=True, timeout=DURATION_S + 90)
    print(result.stdout)
    assert result.returncode == 0, result.stdout + result.stderr
    for namespace, proc in graphs.items():
        _assert_started(proc, namespace)
    assert 'cannot record' not in result.stderr, result.stderr
    counts = assert_bag_readable(bag)
    # Action topics are recorded too (their types are the workspace's own).
    assert {f'{RECORDED}/retune_gait/_action/feedback',
            f'{RECORDED}/retune_gait/_action/status'} <= set(counts)
    gaps, runs = sequence_gaps(bag)
    streams = [f'{RECORDED}/{s}' for s in STREAMS]
    assert [g for g in gaps if g.topic in streams] == []
    assert {s: runs.get(s) for s in streams} == {s: 1 for s in streams}  # one publisher each
    lags = publish_lags(bag)
    start_s = min(min(received) for received, _ in lags.values())
    for stream in streams:
        received, published = lags[stream]
        waited = [r - p for r, p in zip(received, published)]
        assert max(waited) <= LAG_BOUND_S, (stream, max(waited))
        # Drained: what was published until the stop, DURATION_S after the first message
        # taken, is in the bag (the slowest stream, body_wave, publishes every 50 ms).
        assert max(published) >= start_s + DURATION_S - LAG_BOUND_S, stream
    assert 'recording: 0 lost on' in result.stdout
