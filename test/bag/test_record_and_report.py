# SPDX-License-Identifier: Apache-2.0
"""`wirefish record` writes a rosbag2 MCAP bag that rosbags reads back, and `report` reads it."""

import subprocess

import numpy as np
import pytest
from ros_utils import PEERS
from wirefish_bag.bagfile import read_bag
from wirefish_bag.report import topic_stats, write_report

# It mostly waits (0.24 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]


def test_recorded_bag_holds_every_published_message(tmp_path, spawn, python, ros_env):
    talker = spawn([python, PEERS, 'body_wave_talker', '--ros-args', '-r', '__ns:=/wf_test'])
    assert talker.stdout.readline().strip() == 'ready'
    bag_path = tmp_path / 'bag'
    result = subprocess.run(
        [python, '-m', 'wirefish_cli.cli', 'record', '-o', str(bag_path),
         '--namespace', '/wf_test', '--duration', '3'],
        env=ros_env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert (bag_path / 'metadata.yaml').is_file()
    assert list(bag_path.glob('*.mcap'))
    bag = read_bag(bag_path)
    assert bag.types['/wf_test/body_wave'] == 'wirefish_msgs/msg/BodyWave'
    counters = [msg.y[2] for _, msg in bag.messages['/wf_test/body_wave']]
    assert len(counters) >= 40  # 20 Hz for about 3 s
    # The talker counts up by one per message: consecutive values prove nothing was lost.
    assert np.all(np.diff(counters) == 1.0)
    assert f'{len(counters)}' in result.stdout
    # The recorder's own account agrees: no number missing from the talker's DDS sequence.
    assert "missing from the publishers' sequences: 0" in result.stdout, result.stdout
    # Its progress, off a terminal: a line now and then, with the time left, then 'done'.
    progress = [line for line in result.stderr.splitlines() if line.startswith('record bag: ')]
    assert progress and progress[-1].startswith('record bag: 3/3, done in'), result.stderr


def test_report_writes_summary_from_a_bag(tmp_path, spawn, python, ros_env):
    talker = spawn([python, PEERS, 'body_wave_talker', '--ros-args', '-r', '__ns:=/wf_test'])
    assert talker.stdout.readline().strip() == 'ready'
    bag_path = tmp_path / 'bag'
    subprocess.run([python, '-m', 'wirefish_cli.cli', 'record', '-o', str(bag_path),
                    '--namespace', '/wf_test', '--duration', '2'],
                   env=ros_env, capture_output=True, text=True, timeout=60, check=True)
    stats = write_report(bag_path, tmp_path / 'report')
    by_topic = {s.topic: s for s in stats}
    assert by_topic['/wf_test/body_wave'].drops == 0
    assert by_topic['/wf_test/body_wave'].rate_hz == pytest.approx(20.0, rel=0.2)
    assert (tmp_path / 'report' / 'body_wave.png').stat().st_size > 0
    summary = (tmp_path / 'report' / 'summary.txt').read_text()
    assert '/wf_test/body_wave' in summary
    # The recorder's own account, from the bag: what it lost (nothing here).
    assert summary.splitlines()[-1].startswith('recording: 0 lost on'), summary


JITTERED = np.arange(0, 1, 0.01)
JITTERED[[10, 40, 70]] += 0.006  # late samples (a 16 ms gap, then a 4 ms one): nothing lost


@pytest.mark.parametrize('stamps, drops', [
    (np.arange(0, 1, 0.01), 0),
    (np.delete(np.arange(0, 1, 0.01), [10, 11, 50]), 3),
    (JITTERED, 0),
])
def test_topic_stats_counts_drops_from_stamp_gaps(stamps, drops):
    assert topic_stats('/t', 'x', stamps).drops == drops
