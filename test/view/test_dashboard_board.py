# SPDX-License-Identifier: Apache-2.0
"""
The dashboard's link, gait and health panels in a real browser (headless chromium, Selenium).

The page is that of a running `wirefish up --sim --view --drive-mode gait`: the virtual fish
runs the gait itself (GAIT frames from cpg_params) and sends HEALTH at boot and every 2 s. The
host's frames are made sparse: bridge_node's heartbeats at 0.5 Hz, the fish's link timeout
0.3 s and coast time 0.6 s (its LINK_CONFIG). So between two host frames the fish loses the
link, coasts on its last gait, then rests, and says so in its telemetry's status bits; the
bridge's /diagnostics (at 10 Hz here) carries them to the page. Each host frame ends it.

The claims: the health panel shows the reset cause and the clock source the bridge reports
(the virtual fish's POWER_ON and EMULATED), the uptime, the stack high-water and the drop
counters, and no NaN; the badge shows gait mode with the board's gait id, then coasting and
resting each in its own words and colour, coasting before resting, and the gait again once a
host frame arrives; each state the page showed is one the bridge's status word gave. A FAULT
reset shows its PC and a crystal failure the fallback clock, unknown values are blank (the
page's own functions on the key-values link_health and diagnostic_status make of such a
HEALTH: the virtual fish does not fault). A screenshot of both panels goes to
out/dashboard_board.png.
"""

import json
import math
from pathlib import Path
import re
import time

from diagnostic_msgs.msg import DiagnosticArray
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from selenium.webdriver.common.by import By
from wirefish_bridge.link_health import health_values
from wirefish_bridge.protocol import ClockSource, Health, HealthFlags, ResetCause, Status
from wirefish_bridge.ros_messages import diagnostic_status
from wirefish_bridge.transport import LinkState
from wirefish_common.qos import RELIABLE

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

GRAPH_OPTIONS = ('--drive-mode', 'gait')
GRAPH_PARAMS = {'bridge_node': {'heartbeat_rate_hz': 0.5, 'link_timeout_s': 0.3,
                                'coast_s': 0.6, 'diagnostics_rate_hz': 10.0}}
COASTING_WORDS = 'coasting: link lost, swimming the last gait'
RESTING_WORDS = 'resting: link lost, tail brought to rest'
SCREENSHOT = Path(__file__).resolve().parents[2] / 'out' / 'dashboard_board.png'


@pytest.fixture
def bridge_reports(graph_context, view_graph):
    """Yield the bridge's /diagnostics values heard on the graph (a list of dicts) and a spin."""
    node = rclpy.create_node('board_probe', context=graph_context)
    executor = SingleThreadedExecutor(context=graph_context)
    executor.add_node(node)
    heard: list[dict[str, str]] = []
    name = f'{view_graph.graph.namespace}/bridge_node:'

    def on_diagnostics(array: DiagnosticArray) -> None:
        for status in array.status:
            if status.name.startswith(name):
                heard.append({kv.key: kv.value for kv in status.values})

    node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, RELIABLE)
    yield heard, executor
    executor.shutdown()
    node.destroy_node()


def _state_of(values: dict[str, str]) -> str:
    """Return the page's state name for the bridge's status word (as board.js's linkState)."""
    status = int(re.match(r'0x([0-9a-f]+)', values['fish_status']).group(1), 16)
    if status & Status.RESTING:
        return 'resting'
    if status & Status.COASTING:
        return 'coasting'
    return 'gait' if status & Status.GAIT_MODE else 'stream'


def test_the_health_panel_shows_what_the_bridge_reports(dashboard, bridge_reports):
    heard, executor = bridge_reports
    assert dashboard.wait('window.wirefish.connected', 20.0)
    assert spin_until(executor, lambda: bool(heard) and heard[-1].get(
        'fish_reset_cause', 'none yet') != 'none yet', timeout_s=30.0)
    report = heard[-1]
    assert (report['fish_reset_cause'], report['fish_clock']) == ('POWER_ON', 'EMULATED')
    assert dashboard.wait(
        "document.getElementById('v-reset-cause').textContent === 'POWER_ON'", 10.0), (
        dashboard.text('v-reset-cause'))
    assert dashboard.text('v-clock') == 'EMULATED'   # not the fallback: no flag
    assert 'fallback' not in dashboard.driver.find_element(By.ID, 'v-clock').get_attribute('class')
    assert re.fullmatch(r'\d+(\.\d)? s|\d+ min \d\d s', dashboard.text('v-uptime'))
    # A stack size of 0: the board does not measure it (the virtual fish): blank, not '0 of 0'.
    free, size = re.fullmatch(r'(\d+) of (\d+) bytes', report['fish_stack_free_min']).groups()
    assert dashboard.text('v-stack') == (f'{free} of {size} bytes never used' if int(size)
                                         else '')
    counters = {key: dashboard.text(f'v-{key}') for key in (
        'fish_uart_rx_overruns', 'fish_tx_bytes_dropped', 'fish_rx_crc', 'fish_rx_frame',
        'fish_rx_invalid', 'fish_imu_faults')}
    assert all(value.isdigit() for value in counters.values()), counters
    page = dashboard.driver.find_element(By.TAG_NAME, 'body').text
    assert 'NaN' not in page and 'nan' not in page.split()


def test_the_badge_tells_coasting_from_resting_as_the_bridge_reports_them(
        dashboard, bridge_reports):
    heard, executor = bridge_reports
    assert dashboard.wait(
        "window.wirefish.board && window.wirefish.board.drive_mode === 'gait'", 30.0)
    assert dashboard.text('v-drive-mode') == 'gait'
    # The states the page shows from when the probe hears the bridge too (the page's log from
    # then on), through a whole quiet spell.
    assert spin_until(executor, lambda: bool(heard), timeout_s=10.0)
    spin_until(executor, lambda: False, timeout_s=0.3)   # a report on its way to the page
    start = dashboard.live('Date.now()')   # the page's clock: its log is bounded, not indexed
    seen: dict[str, tuple[str, str, str]] = {}   # state -> badge words, class, colour

    def log() -> list[str]:
        return [entry['state'] for entry in dashboard.live('window.wirefish.boardLog')
                if entry['at'] >= start]

    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline and not (
            'coasting,resting,gait' in ','.join(log())
            and {'gait', 'coasting', 'resting'} <= set(seen)):
        # One read of the page: the badge may change between two separate reads.
        state, words, classes, colour = dashboard.live(
            '(b => [b.dataset.state, b.innerText, b.className, getComputedStyle(b)'
            '.backgroundColor])(document.getElementById("v-link-badge"))')
        seen.setdefault(state, (words, classes, colour))
        executor.spin_once(timeout_sec=0.02)
    states = log()
    # Within a quiet spell the fish coasts, then rests; a host frame brings the gait back.
    assert 'coasting,resting,gait' in ','.join(states), states
    assert all(states[i - 1] == 'coasting' for i, s in enumerate(states) if s == 'resting'
               and i), states
    assert {'gait', 'coasting', 'resting'} <= set(seen), seen
    assert seen['coasting'][0] == COASTING_WORDS and seen['resting'][0] == RESTING_WORDS
    assert seen['coasting'][2] != seen['resting'][2]   # two colours, not one
    assert re.fullmatch(r'gait: the board swims gait [1-9]\d*', seen['gait'][0]), seen['gait']
    host, board = dashboard.text('v-gait-id').split(' / ')
    assert int(board) >= 1 and int(host) >= int(board)
    spin_until(executor, lambda: False, timeout_s=0.5)
    bridge_states = {_state_of(values) for values in heard}
    assert set(states) <= bridge_states, (states, bridge_states)
    print(f'page states {states}; the bridge reported {sorted(bridge_states)} in '
          f'{len(heard)} reports')
    dashboard.driver.execute_script("document.getElementById('link-panel').scrollIntoView()")
    SCREENSHOT.parent.mkdir(exist_ok=True)
    assert dashboard.driver.save_screenshot(str(SCREENSHOT))


def _as_published(values: dict[str, object]) -> dict[str, str]:
    """Return ``values`` as the bridge puts them in /diagnostics (its KeyValue texts)."""
    status = diagnostic_status('bridge_node: serial link test', 'test', 0, 'test', values)
    return {kv.key: kv.value for kv in status.values}


def test_a_fault_reset_shows_its_pc_and_a_dead_crystal_the_fallback_clock(dashboard):
    # The bridge's own key-values of such a HEALTH (the page's functions: the virtual fish
    # does not fault).
    health = Health(ResetCause.FAULT, ClockSource.HSI_PLL, HealthFlags.FAULT_RECORD,
                    fault_pc=0x08001234, fault_lr=0x08000ABD, fault_cfsr=0x8200,
                    fault_hfsr=0x40000000, uptime_ms=1500, stack_free_min=312,
                    stack_size=4096, rx_crc=3)
    values = _as_published(health_values(health))
    shown = dashboard.live(f'window.wirefish.boardView.health({json.dumps(values)})')
    assert shown['reset_cause'] == ('FAULT at PC 0x08001234 (LR 0x08000abd, CFSR 0x00008200, '
                                    'HFSR 0x40000000)')
    assert shown['clock'] == {'source': 'HSI_PLL', 'fallback': True,
                              'words': 'HSI_PLL: fallback, the crystal failed'}
    assert shown['uptime'] == '1.5 s'
    assert shown['stack'] == '312 of 4096 bytes never used'
    assert shown['flags'] == 'FAULT_RECORD'
    counters = {c['key']: c['value'] for c in shown['counters']}
    assert counters['fish_rx_crc'] == '3' and counters['fish_rx_frame'] == '0'
    assert counters['drops'] == ''   # not in these values: blank
    # Before the first HEALTH, and values the bridge does not know (nan, inf): blank.
    unknown = _as_published({**health_values(None), 'fish_uptime_s': math.nan})
    none_yet = dashboard.live(f'window.wirefish.boardView.health({json.dumps(unknown)})')
    assert none_yet['reset_cause'] == '' and none_yet['uptime'] == ''
    assert none_yet['clock']['words'] == ''
    # A board that cannot tell its reset cause (QEMU's has no reset flags) says UNKNOWN: shown.
    told = _as_published(health_values(Health(ResetCause.UNKNOWN, ClockSource.EMULATED)))
    assert dashboard.live(f'window.wirefish.boardView.health({json.dumps(told)})')[
        'reset_cause'] == 'UNKNOWN'
    # The link silent (a cut radio): the bridge's last status bits no longer say the state.
    silent = _as_published({'link_state': 'connected', 'drive_mode': 'gait',
                            'last_telemetry_age_s': 4.2, 'fish_status': '0x0100 (GAIT_MODE)'})
    assert dashboard.live(f'window.wirefish.boardView.linkState({json.dumps(silent)})') == {
        'state': 'silent', 'level': 'bad',
        'words': 'no telemetry for 4.2 s: link lost (the fish coasts, then rests)'}
    never = _as_published({'link_state': 'connected', 'drive_mode': 'stream',
                           'last_telemetry_age_s': math.inf, 'fish_status': '0x0000 (ok)'})
    assert dashboard.live(f'window.wirefish.boardView.linkState({json.dumps(never)})') == {
        'state': 'silent', 'level': 'bad', 'words': 'no telemetry yet: link lost'}
    opened = _as_published({'link_state': LinkState.IDENTIFYING, 'drive_mode': 'gait',
                            'last_telemetry_age_s': math.inf, 'fish_status': '0x0000 (ok)'})
    assert dashboard.live(f'window.wirefish.boardView.linkState({json.dumps(opened)})') == {
        'state': 'down', 'level': 'bad',
        'words': 'link identifying: the port is open, no fish heartbeat yet'}
