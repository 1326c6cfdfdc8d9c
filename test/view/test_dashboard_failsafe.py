# SPDX-License-Identifier: Apache-2.0
"""
The dashboard's stream-mode failsafe in a real browser (headless chromium, Selenium).

The page is that of a running `wirefish up --sim --view` in stream mode (the bridge forwards
servo_cmd) with bridge_node's heartbeats at 0.5 Hz: the virtual fish's heartbeat timeout
(1.5 s) passes before each next one, and for that while the fish moves its servo targets to
neutral at its bounded failsafe slew (2 rad/s), whatever the commands, and flags
FAILSAFE_HEARTBEAT. The claims: the badge says stream mode, then the failsafe in words with its
cause, each as the bridge's status word says; while it lasts the panel shows the slew observed
on servo_state, a finite rate, or that the tail holds neutral; no NaN on the page.
"""

import math
import re
import time

from diagnostic_msgs.msg import DiagnosticArray
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from selenium.webdriver.common.by import By
from wirefish_bridge.protocol import Status
from wirefish_common.qos import RELIABLE

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

GRAPH_PARAMS = {'bridge_node': {'heartbeat_rate_hz': 0.5, 'diagnostics_rate_hz': 10.0}}
FAILSAFE_WORDS = 'failsafe: no host heartbeat, tail slewing to neutral'
# The badge's state and words and the failsafe row, in one read: the page updates them together.
READ_BADGE_AND_ROW = ("[document.getElementById('v-link-badge').dataset.state, "
                      "document.getElementById('v-link-badge').textContent, "
                      "document.getElementById('v-failsafe').textContent]")
SLEWING = re.compile(r'slewing to neutral, (\d+\.\d\d) rad/s observed|holding neutral')


FAILSAFES = Status.FAILSAFE_HEARTBEAT | Status.FAILSAFE_COMMAND


def _both_heard(words: set[int]) -> bool:
    """Return whether the bridge's status words heard hold a heartbeat failsafe and no failsafe."""
    return (any(w & Status.FAILSAFE_HEARTBEAT for w in words)
            and any(not w & FAILSAFES for w in words))


def test_the_panel_shows_the_stream_failsafe_and_its_slew(dashboard, graph_context, view_graph):
    node = rclpy.create_node('failsafe_probe', context=graph_context)
    executor = SingleThreadedExecutor(context=graph_context)
    executor.add_node(node)
    name = f'{view_graph.graph.namespace}/bridge_node:'
    words: set[int] = set()

    def on_diagnostics(array: DiagnosticArray) -> None:
        for status in array.status:
            if status.name.startswith(name):
                value = next(kv.value for kv in status.values if kv.key == 'fish_status')
                words.add(int(re.match(r'0x([0-9a-f]+)', value).group(1), 16))

    node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, RELIABLE)
    try:
        assert dashboard.wait(
            "window.wirefish.board && window.wirefish.board.drive_mode === 'stream'", 30.0)
        seen: dict[str, set[str]] = {}   # state -> the badge's words
        slews: list[str] = []            # the failsafe row while the badge says failsafe
        deadline = time.monotonic() + 30.0
        # Until the page and the probe have both seen both: the probe's subscription is new,
        # and the page can show everything before the probe hears its first status.
        while time.monotonic() < deadline and not (
                FAILSAFE_WORDS in seen.get('failsafe', ()) and 'stream' in seen
                and len(slews) >= 3 and _both_heard(words)):
            state, badge, row = dashboard.live(READ_BADGE_AND_ROW)
            seen.setdefault(state, set()).add(badge)
            if state == 'failsafe':
                slews.append(row)
            executor.spin_once(timeout_sec=0.02)
    finally:
        executor.shutdown()
        node.destroy_node()
    assert {'stream', 'failsafe'} <= set(seen), seen
    # 'no command' too at times: the fish's command timeout passed (as before the first one,
    # or when the loaded machine holds servo_cmd back).
    assert FAILSAFE_WORDS in seen['failsafe'], seen
    assert all(re.fullmatch(r'failsafe: (no host heartbeat|no command|no host heartbeat, no '
                            r'command), tail slewing to neutral', words)
               for words in seen['failsafe']), seen
    assert seen['stream'] == {'stream: the host commands the servos'}, seen
    assert any(w & Status.FAILSAFE_HEARTBEAT for w in words), sorted(words)
    assert any(not w & FAILSAFES for w in words), sorted(words)
    # While the badge says failsafe the row says the slew observed, or that the tail holds.
    matches = [SLEWING.fullmatch(s) for s in slews]
    assert all(matches), slews
    rates = [float(m.group(1)) for m in matches if m.group(1)]
    assert all(math.isfinite(r) for r in rates)
    print(f'failsafe rows {slews}')
    assert 'NaN' not in dashboard.driver.find_element(By.TAG_NAME, 'body').text
    assert dashboard.live('window.wirefish.boardLog.length') <= 100   # bounded
