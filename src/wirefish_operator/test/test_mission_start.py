# SPDX-License-Identifier: Apache-2.0
"""When `wirefish mission` takes the fish for driven: what the bridge's /diagnostics say."""

import pytest
from wirefish_operator.verb.mission import fish_hears_host


@pytest.mark.parametrize('values', [
    {'link_state': 'connected', 'fish_status': '0x0000 (ok)'},
    {'link_state': 'connected', 'fish_status': '0x0001 (FAILSAFE_COMMAND)'},  # before commands
    {'link_state': 'connected', 'fish_status': '0x0100 (GAIT_MODE)'},
])
def test_a_connected_fish_that_hears_the_host_is_driven(values):
    assert fish_hears_host(values)


@pytest.mark.parametrize('values', [
    {'link_state': 'connected', 'fish_status': '0x0002 (FAILSAFE_HEARTBEAT)'},
    {'link_state': 'connected',
     'fish_status': '0x0003 (FAILSAFE_COMMAND, FAILSAFE_HEARTBEAT)'},
    {'link_state': 'identifying', 'fish_status': '0x0000 (ok)'},
    {'link_state': 'connected'},  # no status word yet
    {},
])
def test_a_fish_deaf_to_the_host_or_a_link_not_up_is_not_driven(values):
    assert not fish_hears_host(values)
