# SPDX-License-Identifier: Apache-2.0
"""
The two-host pair itself: DDS crosses the veth, before and after the link is cut.

Fast DDS sends its discovery announcements to multicast groups; a namespace with nothing but
the veth's subnet route cannot send them (ENETUNREACH), and then no participant on one host
ever finds one on the other, with static peers too. These tests caught that.
"""

from pathlib import Path
import subprocess
import sys

import pytest
from wirefish_bringup.graph import Role
from wirefish_launcher.netns import Discovery, MULTICAST_ROUTE

pytestmark = pytest.mark.ros

CHAT = str(Path(__file__).resolve().parents[1] / 'support' / 'chat.py')
HEAR_WITHIN_S = 20.0


def _multicast_routes(link, side: Role) -> str:
    return subprocess.run(link.exec_prefix(side) + ['ip', 'route', 'show', MULTICAST_ROUTE],
                          capture_output=True, text=True, check=True).stdout


def _shore_hears_the_fish(hosts) -> subprocess.CompletedProcess:
    talker = hosts.start(Role.FISH, [sys.executable, CHAT, 'talk', str(HEAR_WITHIN_S + 5)])
    try:
        return hosts.run(Role.SHORE, [sys.executable, CHAT, 'listen', str(HEAR_WITHIN_S)],
                         timeout_s=HEAR_WITHIN_S + 15)
    finally:
        talker.kill()
        talker.wait()


@pytest.mark.parametrize('side', [Role.FISH, Role.SHORE])
def test_each_host_routes_multicast_over_its_veth_after_the_link_returns(hosts, side):
    assert hosts.link.device(side) in _multicast_routes(hosts.link, side)
    hosts.link.cut()
    hosts.link.restore()
    assert hosts.link.device(side) in _multicast_routes(hosts.link, side)


@pytest.mark.parametrize('hosts', [Discovery.MULTICAST, Discovery.STATIC], indirect=True)
def test_a_topic_published_on_the_fish_host_is_heard_on_the_shore_host(hosts):
    done = _shore_hears_the_fish(hosts)
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_shore_hears_the_fish_again_after_a_cut_link_returns(hosts):
    hosts.link.cut()
    hosts.link.restore()
    done = _shore_hears_the_fish(hosts)
    assert done.returncode == 0, done.stdout + done.stderr
