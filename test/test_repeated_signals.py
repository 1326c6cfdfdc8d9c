# SPDX-License-Identifier: Apache-2.0
"""
A burst of SIGINT/SIGTERM a few ms apart stops every process with exit code 0 and no trace.

What a terminal's Ctrl-C does under a launcher (one signal from the terminal, one from the
launcher), or an impatient user: each process must stop as cleanly after the second, third...
signal as after the first, however the signals fall against its shutdown.
"""

import os
from pathlib import Path
import signal
import time

from ament_index_python.packages import get_package_prefix
import numpy as np
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until

pytestmark = pytest.mark.ros
RUNS = 3  # bursts per process, each with its own number and spacing of signals
GAP_S = (0.001, 0.050)
SIGNALS = (signal.SIGINT, signal.SIGTERM)


def executable(package: str, name: str) -> str:
    return os.path.join(get_package_prefix(package), 'lib', package, name)


def command(name: str, tmp_path: Path) -> list[str]:
    """Return the command line of process ``name`` (node name = ``name``)."""
    if name == 'cpg_node':  # busy: 1 kHz of callbacks while the signals arrive
        return [executable('wirefish_cpg', name), '--ros-args', '-p', 'publish_rate_hz:=1000.0']
    if name == 'tuner_node':
        return [executable('wirefish_tuner', name)]
    if name == 'kinematics_node':
        return [executable('wirefish_kinematics', name)]
    if name == 'bridge_node':  # no device: the bridge keeps retrying, which is enough here
        return [executable('wirefish_bridge', name), '--ros-args',
                '-p', f'port:={tmp_path / "no-such-device"}']
    if name == 'planner_node':
        return [executable('wirefish_planner', name)]
    if name == 'fish_sim':
        return [executable('wirefish_sim', name), '--ros', '--link', str(tmp_path / 'tty')]
    if name == 'wirefish_recorder':
        return [executable('wirefish_bag', 'recorder'),
                '-o', str(tmp_path / 'bag'), '--namespace', '/h61_signals']
    raise ValueError(name)


def burst(rng: np.random.Generator) -> list[tuple[float, int]]:
    """Return 2 to 6 (delay before it in s, signal) pairs: SIGINT first, then SIGINT/SIGTERM."""
    count = int(rng.integers(2, 7))
    delays = [0.0, *rng.uniform(*GAP_S, size=count - 1)]
    kinds = [signal.SIGINT, *rng.choice(SIGNALS, size=count - 1)]
    return [(float(d), int(k)) for d, k in zip(delays, kinds)]


@pytest.mark.parametrize('run', range(RUNS))
@pytest.mark.parametrize('name', ['cpg_node', 'tuner_node', 'kinematics_node', 'bridge_node',
                                  'planner_node', 'fish_sim', 'wirefish_recorder'])
def test_a_burst_of_signals_stops_the_process_cleanly(spawn, ros_context, tmp_path, name, run):
    rng = np.random.default_rng([61, run, *name.encode()])
    proc = spawn(command(name, tmp_path))
    probe = rclpy.create_node('signal_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)
    try:
        up = spin_until(executor, lambda: name in probe.get_node_names(), timeout_s=30.0)
    finally:
        executor.shutdown()
        probe.destroy_node()
    assert up, f'{name} never appeared'
    signals = burst(rng)
    for delay, signum in signals:
        time.sleep(delay)
        try:
            os.kill(proc.pid, signum)
        except ProcessLookupError:  # it already stopped: the remaining signals find nobody
            break
    code = proc.wait(timeout=20.0)
    output = proc.stdout.read()
    assert (code, 'Traceback' in output, 'Exception' in output) == (0, False, False), \
        f'{signals}: exit {code}\n{output}'
