# SPDX-License-Identifier: Apache-2.0
"""
The fleet's acceptance: `wirefish up --fleet 3` on one machine, recorded in one bag.

Three virtual fish, each its whole graph in <base>/fish_<i>, one recorder of the base
namespace. While they swim, one fish is retuned (`wirefish retune --apply --namespace
<base>/fish_2`). The bag then holds every fish's streams, with frame ids under fish_<i>/, and
only fish_2's cpg_params changed. The fleet runs on its virtual fish's clock (`wirefish up
--sim` at --speed 1: one fish_sim, one clock for the three graphs). Wall time ~1.5 min (18 node
processes on 2 cores).
"""

import re
import subprocess
import sys
import time

from bag_utils import assert_bag_readable
from e2e_utils import OWN_NAMESPACE
import pytest
from wirefish_bag.bagfile import read_bag

pytestmark = pytest.mark.ros

BASE = '/h201_fleet'
FISH = ('fish_1', 'fish_2', 'fish_3')
RETUNED = 'fish_2'
DURATION_S = 30.0
UP_TIMEOUT_S = 150.0  # 18 processes start on the loaded 2-core machine
# topic -> the frame ids its messages carry, under the fish's prefix
FRAMES = {'imu/data': ('imu_link',), 'battery': ('base_link',), 'body_wave': ('tail_base',),
          'speed_estimate': ('tail_base',), 'sim/ground_truth': ('odom', 'base_link')}
STREAMS = ('servo_cmd', 'imu/data', 'servo_state', 'body_wave', 'speed_estimate',
           'sim/ground_truth', 'planner_state')


def _frames(msg) -> tuple[str, ...]:
    child = getattr(msg, 'child_frame_id', None)
    return (msg.header.frame_id,) + ((child,) if child is not None else ())


def _wait_for_action_server(context, name: str, timeout_s: float) -> None:
    """Wait on the ROS graph until action server ``name`` is discovered (or fail, naming it)."""
    import rclpy
    from rclpy.action import ActionClient
    from rclpy.executors import SingleThreadedExecutor
    from ros_utils import spin_until
    from wirefish_msgs.action import RetuneGait

    node = rclpy.create_node('fleet_probe', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    client = ActionClient(node, RetuneGait, name)
    try:
        assert spin_until(executor, client.server_is_ready, timeout_s), \
            f'no {name} action server discovered within {timeout_s:g} s'
    finally:
        client.destroy()
        executor.shutdown()
        node.destroy_node()


def test_a_fleet_of_three_streams_apart_and_one_bag_holds_them_all(spawn, ros_env, ros_context,
                                                                   tmp_path):
    up = spawn([sys.executable, '-m', 'wirefish_cli.cli', 'up', '--fleet', '3', *OWN_NAMESPACE,
                '--start-swimming', '--namespace', BASE, '--duration', str(DURATION_S),
                '--no-status', '--out', str(tmp_path)])
    deadline = time.monotonic() + UP_TIMEOUT_S
    lines = []
    for line in up.stdout:
        lines.append(line)
        if line.startswith('recording to'):
            break
        assert time.monotonic() < deadline, 'the fleet did not come up:\n' + ''.join(lines)
    else:
        pytest.fail('wirefish up ended before recording:\n' + ''.join(lines))
    # The retune's own process finds the action again; here the wait is on the graph itself:
    # 18 processes starting on two cores were seen to have it undiscovered after 3 s.
    _wait_for_action_server(ros_context, f'{BASE}/{RETUNED}/retune_gait', UP_TIMEOUT_S)
    retune = subprocess.run(
        [sys.executable, '-m', 'wirefish_cli.cli', 'retune', '--apply', '--namespace',
         f'{BASE}/{RETUNED}', '--freq', '1.3', '--iterations', '20', '--swarm', '20',
         '--timeout', '60'], env=ros_env, capture_output=True, text=True, timeout=90)
    print(retune.stdout[-800:], retune.stderr[-400:])
    assert retune.returncode == 0
    applied = float(re.search(r'^frequency_hz\s+([0-9.]+)', retune.stdout, re.M).group(1))
    rest, _ = up.communicate(timeout=DURATION_S + 120)
    print(''.join(lines) + rest[-2000:])
    assert up.returncode == 0
    # Off a terminal the timed run says how far it is in simulated seconds, with the time left.
    timed = [line for line in rest.splitlines()
             if line.startswith('recording, simulated seconds: ')]
    assert any(' left' in line for line in timed), rest[-2000:]
    # Its last line says what the recording lost, whatever it was (three fish on two cores).
    assert re.match(r'recording: (0 lost on \d+ topics|LOST \d+ messages: )',
                    rest.splitlines()[-1]), rest[-2000:]
    bag = next(tmp_path.glob('run_*/bag'))
    counts = assert_bag_readable(bag)
    for name in FISH:
        for topic in STREAMS:
            assert counts.get(f'{BASE}/{name}/{topic}', 0) > 0, f'{name} {topic} not recorded'
    print({t: c for t, c in counts.items() if t.endswith('servo_cmd')})

    wanted = [f'{BASE}/{n}/{t}' for n in FISH for t in (*FRAMES, 'cpg_params')]
    messages = read_bag(bag, wanted).messages
    frames_of = {name: set() for name in FISH}
    for name in FISH:
        for topic, frames in FRAMES.items():
            found = {_frames(msg) for _, msg in messages[f'{BASE}/{name}/{topic}']}
            assert found == {tuple(f'{name}/{frame}' for frame in frames)}, (name, topic)
            frames_of[name] |= {frame for pair in found for frame in pair}
    print('frames:', frames_of)
    all_frames = [frame for frames in frames_of.values() for frame in frames]
    assert len(all_frames) == len(set(all_frames))  # no frame shared: one TF tree holds all

    frequencies = {name: [round(msg.frequency_hz, 4)
                          for _, msg in messages[f'{BASE}/{name}/cpg_params']]
                   for name in FISH}
    print('cpg_params frequencies in the bag:', frequencies, 'applied', applied)
    assert abs(frequencies[RETUNED][-1] - applied) < 1e-3
    for name in FISH:
        if name != RETUNED:
            assert len(set(frequencies[name])) == 1 and frequencies[name][0] != applied, name
