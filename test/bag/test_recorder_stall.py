# SPDX-License-Identifier: Apache-2.0
"""
A recorder the machine stops for seconds loses nothing of a best-effort stream.

A starved process does not read its sockets; what arrives meanwhile waits in the kernel's
socket buffer, and a full buffer drops datagrams, which a best-effort stream never resends. The
graph's Fast DDS profile gives every participant's receiving sockets a buffer for that
(wirefish_bringup.dds_profile). Here `wirefish record` is stopped outright (SIGSTOP) for
STALL_S while a talker publishes Imu at 200 Hz best effort: the bag must hold every number of
the talker's sequence, and the recorder must say that its oldest message waited about the
stall (so the stall did hold the messages back).
"""

import os
import re
import signal
import sys
import time

import pytest
from ros_utils import PEERS
from wirefish_bringup.dds_profile import with_profile

pytestmark = pytest.mark.ros
NAMESPACE = '/wf_stall'
STALL_S = 3.0
RECORD_S = 8.0


def _stop_for(pid: int, seconds: float) -> None:
    os.kill(pid, signal.SIGSTOP)
    try:
        time.sleep(seconds)
    finally:
        os.kill(pid, signal.SIGCONT)


@pytest.mark.parametrize('range_', ('LOCALHOST', 'SUBNET'))
def test_a_stopped_recorder_loses_nothing_of_a_best_effort_stream(
        spawn, ros_env, python, tmp_path, range_):
    # The range as a shell sets it after tools/activate.sh: `wirefish` itself gives its
    # participant the graph's profile (LOCALHOST: the loopback one, its UDPv4 transport named
    # in it; SUBNET: the installed one, the builtin transports).
    env = {**ros_env, 'ROS_AUTOMATIC_DISCOVERY_RANGE': range_}
    talker = spawn([python, PEERS, 'imu_talker', '--ros-args', '-r', f'__ns:={NAMESPACE}'],
                   env=with_profile(env))
    assert talker.stdout.readline().strip() == 'ready'
    recorder = spawn([sys.executable, '-m', 'wirefish_cli.cli', 'record', '-o',
                      str(tmp_path / 'bag'), '--namespace', NAMESPACE, '--duration',
                      str(RECORD_S)], env=env)
    lines = []
    for line in recorder.stdout:  # the recorder says each topic it subscribes
        lines.append(line)
        if f'recording {NAMESPACE}/imu/data' in line:
            break
    time.sleep(1.0)  # the stream flows into the recorder
    _stop_for(recorder.pid, STALL_S)
    out = ''.join(lines) + recorder.stdout.read()
    assert recorder.wait(timeout=60) == 0, out
    imu = re.search(rf'{NAMESPACE}/imu/data +(\d+) \(missing (\d+), lag max ([\d.]+) s\)', out)
    assert imu, out
    count, missing, lag = int(imu[1]), int(imu[2]), float(imu[3])
    assert lag >= 0.8 * STALL_S, out  # the stall held the stream back
    print(f'{imu[0].strip()} through a {STALL_S:g} s stop')
    assert count > 2.0 * STALL_S * 100 and missing == 0, out
