# SPDX-License-Identifier: Apache-2.0
"""
Fresh clients against restarted servers with the workspace's Fast DDS profile: every call answered.

The reduced form of ``tools/probes/reply_probe.py`` (which also runs a second graph for load and
shows the loss without the profile): a new participant, node and client per call, wait_for_service,
one request, no retry, the server restarted before every tenth call. And every reply writer the
profile names is one of a service the servers offer (a misspelt name would wait for nothing).
"""

import importlib.util
from pathlib import Path
import sys

from cpg_probe import CPG_NODE, TUNER_NODE
import pytest
from ros_utils import spin_until
from wirefish_bringup.dds_profile import reply_writer_names

# It mostly waits (0.09 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

PROBE = Path(__file__).resolve().parents[2] / 'tools' / 'probes' / 'reply_probe.py'


def _probe():
    spec = importlib.util.spec_from_file_location('reply_probe', PROBE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize('server, call', [('tuner_node', 'tuner_call'),
                                          ('cpg_node', 'cpg_call')])
def test_fresh_clients_of_a_restarted_server_are_all_answered(ros_env, monkeypatch, tmp_path,
                                                              server, call):
    probe = _probe()
    for name in ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE'):
        monkeypatch.setenv(name, ros_env[name])  # the probe's clients, as its servers
    env = probe.server_environment(profile=True, domain=int(ros_env['ROS_DOMAIN_ID']))
    batch = probe.Batch(calls=20, restart_every=10, deadline_s=10.0, find_s=30.0)
    with open(tmp_path / 'server.log', 'w') as log:
        tally = probe.run_batch(probe.server_command(server),
                                (probe.fresh_call, getattr(probe, call)), batch, env, log)
    assert tally.no_service == 0
    assert tally.unanswered == 0
    assert tally.answered == 20


def test_every_reply_writer_of_the_profile_names_a_service_the_servers_offer(spawn, probe):
    for node in (CPG_NODE, TUNER_NODE):
        spawn([node, '--ros-args', '-r', '__ns:=/profile_check'])
    wanted = {name[len('rr'):-len('Reply')] for name in reply_writer_names('/profile_check')}

    def offered() -> set[str]:
        return {name for name, _ in probe.node.get_service_names_and_types()}

    spin_until(probe.executor, lambda: wanted <= offered(), 30.0)
    assert sorted(wanted - offered()) == []
