"""
With the graph's transports, a subscriber SIGKILLed and restarted never stalls its publisher.

The check of wirefish_bringup.dds_profile's choice, by ``tools/kill_stall_probe.py``: a 100 Hz
publisher whose subscriber is killed and started again. Over Fast DDS's shared memory its
publish waited out the dead port's 1 s health check in about one kill in six; a CPG stalled as
long starves the bridge past its command timeout, so that timeout is the bound here.
"""

import json
import os
from pathlib import Path
import sys

import pytest
from wirefish_bringup.dds_profile import TRANSPORTS_VARIABLE, with_profile

pytestmark = pytest.mark.ros

PROBE = Path(__file__).resolve().parents[2] / 'tools' / 'kill_stall_probe.py'
KILLS = 8
COMMAND_TIMEOUT_S = 0.5  # the bridge's default command_timeout_s (config/wirefish.yaml)


def test_a_killed_subscriber_never_stalls_a_publisher_of_the_graph(spawn, ros_env):
    env = with_profile({k: v for k, v in ros_env.items() if k != TRANSPORTS_VARIABLE})
    probe = spawn([sys.executable, str(PROBE), '--kills', str(KILLS)], env=env)
    out, _ = probe.communicate(timeout=120.0)
    print(out)
    assert probe.returncode == 0, out
    account = json.loads(out.strip().splitlines()[-1])
    assert account['sent'] > 100 * KILLS * 2
    assert account['longest_publish_ms'] < COMMAND_TIMEOUT_S * 1e3, account['stalls']


def test_the_graph_environment_keeps_the_users_transports():
    env = with_profile({**os.environ, TRANSPORTS_VARIABLE: 'DEFAULT'})
    assert env[TRANSPORTS_VARIABLE] == 'DEFAULT'
