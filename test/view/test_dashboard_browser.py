# SPDX-License-Identifier: Apache-2.0
"""
The dashboard in a real browser: headless chromium (Debian's) driven by Selenium.

The page is that of a running `wirefish up --sim --view`.

One graph and one browser for the module. The claims: the plots update (values read back from
the page), their legends show values, the battery shows no NaN percentage, the top view has a
distance scale and /favicon.ico is served; a drive key raises planner_state's target speed; a
retune from the form shows its progress and applies, and the page then offers the hand-back
(named as `wirefish hand-back`) that gives the drive keys their effect again; the form refuses
what is not a number before sending, and shows the tuner's refusal of an unreachable wave at
once; the stop button brings cmd_vel to zero and the fish to rest; after it, the speed plot
shows no estimate newer than the last one published, and the body-wave axis stays the tail's
after a retune. The retune
test saves its screenshot to out/dashboard.png; with WIREFISH_UPDATE_DOCS=1 it also replaces
docs/dashboard.png, the picture the README shows (a plain run leaves the tree clean).
"""

import math
import os
from pathlib import Path
import shutil
import time
import urllib.request

from geometry_msgs.msg import Twist
from headless_chromium import headless_chromium
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from selenium.webdriver.common.by import By
from sensor_msgs.msg import JointState
from wirefish_common.qos import LATCHED, RELIABLE, SENSOR_DATA
from wirefish_msgs.msg import CpgParams, PlannerState, SpeedEstimate

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

ROOT = Path(__file__).resolve().parents[2]
SCREENSHOT = ROOT / 'out' / 'dashboard.png'
DOCS_SCREENSHOT = ROOT / 'docs' / 'dashboard.png'
REST_RAD = 0.05  # servo commands within this of neutral: the fish at rest
DONE = "window.wirefish.retune && window.wirefish.retune.state === 'done'"


@pytest.fixture(scope='module')
def browser(view_graph, tmp_path_factory):
    """Yield a headless chromium on the dashboard page; quit it (and its driver) afterwards."""
    with headless_chromium(view_graph.http_url, tmp_path_factory.mktemp('chromium')) as driver:
        yield driver


def _live(browser, expression: str):
    return browser.execute_script(f'return {expression};')


def _wait_page(browser, expression: str, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if _live(browser, expression):
            return True
        time.sleep(0.2)
    return bool(_live(browser, expression))


@pytest.fixture
def probe(graph_context, view_graph):
    """Yield a ROS listener of the graph: its latest planner_state, cmd_vel, servo_cmd."""
    namespace = view_graph.graph.namespace
    node = rclpy.create_node('dashboard_probe', context=graph_context)
    executor = SingleThreadedExecutor(context=graph_context)
    executor.add_node(node)
    heard = {'planner_state': [], 'cmd_vel': [], 'servo_cmd': [], 'cpg_params': []}
    for topic, kind, qos in (('planner_state', PlannerState, RELIABLE),
                             ('cmd_vel', Twist, RELIABLE), ('servo_cmd', JointState, SENSOR_DATA),
                             ('cpg_params', CpgParams, LATCHED)):
        node.create_subscription(kind, f'{namespace}/{topic}', heard[topic].append, qos)
    yield heard, executor
    executor.shutdown()
    node.destroy_node()


def test_the_plots_update_with_the_graphs_values(browser):
    assert _wait_page(browser, 'window.wirefish.connected', 20.0)
    assert _wait_page(browser, 'window.wirefish.plots.servo.data[0].length > 100', 30.0)
    assert _wait_page(browser, 'window.wirefish.plots.wave.data[0].length > 0', 30.0)
    before = _live(browser, 'window.wirefish.plots.servo.data[0].slice(-1)[0]')
    time.sleep(1.5)
    servo = _live(browser, 'window.wirefish.plots.servo.data')
    assert servo[0][-1] > before  # new samples were plotted
    commanded = [v for v in servo[1] if v is not None]
    assert max(commanded) - min(commanded) > 0.1  # the tail beats on the page
    assert all(abs(v) <= math.pi / 2 for v in commanded)
    assert _wait_page(browser, 'window.wirefish.plots.speed.data[0].length > 10', 10.0)
    assert _wait_page(browser, 'window.wirefish.latest.odom !== undefined', 10.0)  # from /tf
    assert _wait_page(browser, "document.getElementById('v-mode').textContent !== '-'", 10.0)
    battery = browser.find_element(By.ID, 'v-battery').text
    assert 'V' in battery and 'NaN' not in battery and '-' not in battery, battery
    # Legends show values (uPlot's own legend shows '--' without a cursor over the plot).
    legends = _live(browser, "Array.from(document.querySelectorAll('#plot-servo .u-legend "
                    ".u-value, #plot-heading .u-legend .u-value')).map(e => e.textContent)")
    assert legends and '--' not in legends, legends
    scale = _live(browser, 'window.wirefish.topdown')
    assert scale['bar_m'] > 0 and scale['bar_px'] > 20, scale
    with urllib.request.urlopen(browser.current_url + 'favicon.ico', timeout=10) as icon:
        assert icon.status == 200 and icon.headers['Content-Type'] == 'image/svg+xml'


def test_a_drive_key_raises_the_planners_target_speed(browser, probe):
    heard, executor = probe
    body = browser.find_element(By.TAG_NAME, 'body')
    body.send_keys('w')
    body.send_keys('w')
    assert _live(browser, 'window.wirefish.drive.speed') == pytest.approx(0.1)
    assert spin_until(executor, lambda: bool(heard['planner_state']) and math.isclose(
        heard['planner_state'][-1].target_speed, 0.1, abs_tol=1e-9), timeout_s=20.0)
    assert _wait_page(browser, "document.getElementById('v-target-speed').textContent"
                      " === '0.10'", 10.0)


def test_a_retune_from_the_form_shows_progress_and_applies(browser, probe):
    heard, executor = probe
    spin_until(executor, lambda: bool(heard['cpg_params']), timeout_s=10.0)
    form = browser.find_element(By.ID, 'retune-form')
    iterations = form.find_element(By.NAME, 'max_iterations')
    iterations.clear()
    iterations.send_keys('12')
    form.find_element(By.NAME, 'k').clear()
    form.find_element(By.NAME, 'k').send_keys('6.0')
    browser.find_element(By.ID, 'retune-submit').click()
    assert _wait_page(browser, "window.wirefish.retuneLog.some(m => m.state === 'done')",
                      120.0), _live(browser, 'window.wirefish.retuneLog')
    log = _live(browser, 'window.wirefish.retuneLog')
    running = [m for m in log if m['state'] == 'running']
    assert running and running[-1]['max_iterations'] == 12
    done = next(m for m in log if m['state'] == 'done')
    assert done['success'] and done['applied'], done
    assert 'done' in browser.find_element(By.ID, 'v-retune').text
    assert _live(browser, "document.getElementById('retune-progress').value") > 0
    SCREENSHOT.parent.mkdir(exist_ok=True)
    assert browser.save_screenshot(str(SCREENSHOT))
    if os.environ.get('WIREFISH_UPDATE_DOCS') == '1':
        shutil.copyfile(SCREENSHOT, DOCS_SCREENSHOT)


def test_after_an_applied_retune_the_page_hands_the_gait_back_to_the_planner(browser, probe):
    heard, executor = probe
    assert spin_until(executor, lambda: bool(heard['planner_state']) and (
        heard['planner_state'][-1].mode == 'manual'), timeout_s=20.0)
    assert _wait_page(browser, "!document.getElementById('hand-back').hidden", 10.0)
    assert 'wirefish hand-back' in browser.find_element(By.ID, 'v-note').text
    browser.find_element(By.ID, 'hand-back').click()
    assert spin_until(executor, lambda: heard['planner_state'][-1].mode != 'manual',
                      timeout_s=20.0)
    assert _wait_page(browser, "document.getElementById('hand-back').hidden", 10.0)


def test_the_stop_button_zeroes_cmd_vel_and_rests_the_fish(browser, probe):
    heard, executor = probe
    browser.find_element(By.ID, 'stop').click()
    assert spin_until(executor, lambda: bool(heard['cmd_vel']) and (
        heard['cmd_vel'][-1].linear.x == 0.0 and heard['cmd_vel'][-1].angular.z == 0.0),
        timeout_s=10.0)
    assert spin_until(executor, lambda: bool(heard['planner_state']) and (
        heard['planner_state'][-1].target_speed == 0.0), timeout_s=10.0)

    def at_rest() -> bool:
        recent = heard['servo_cmd'][-100:]
        return len(recent) == 100 and all(abs(p) < REST_RAD for m in recent
                                          for p in m.position)

    assert spin_until(executor, at_rest, timeout_s=30.0)
    assert _live(browser, 'window.wirefish.drive.speed') == 0.0


def _retune_from_form(browser, **fields: str) -> None:
    form = browser.find_element(By.ID, 'retune-form')
    for name, value in fields.items():
        form.find_element(By.NAME, name).clear()
        form.find_element(By.NAME, name).send_keys(value)
    browser.find_element(By.ID, 'retune-submit').click()


def test_the_retune_form_refuses_what_the_tuner_would_at_once(browser):
    _retune_from_form(browser, c1='abc', max_iterations='0')
    assert _live(browser, 'window.wirefish.retune.state') == 'invalid'  # nothing was sent
    assert "c1 must be a number, got 'abc'" in browser.find_element(By.ID, 'v-retune').text
    # An amplitude the servos cannot reach: the tuner's refusal, shown as such, no full bar.
    sent = time.monotonic()
    _retune_from_form(browser, c1='5', max_iterations='0')
    assert _wait_page(browser, DONE + ' && !window.wirefish.retune.success', 30.0), (
        _live(browser, 'window.wirefish.retune'), browser.find_element(By.ID, 'v-retune').text)
    print(f'c1 = 5 refused in {time.monotonic() - sent:.2f} s: '
          f'{browser.find_element(By.ID, "v-retune").text}')
    assert browser.find_element(By.ID, 'v-retune').text.startswith('refused: rejected:')
    assert _live(browser, "document.getElementById('retune-progress').value") == 0
    _retune_from_form(browser, c1='0.15')


def test_after_stop_the_speed_plot_shows_no_estimate_newer_than_the_last_published(
        browser, probe, view_graph):
    heard, executor = probe
    browser.find_element(By.ID, 'stop').click()
    node = executor.get_nodes()[0]
    published: list[float] = []
    node.create_subscription(
        SpeedEstimate, f'{view_graph.graph.namespace}/speed_estimate',
        lambda m: published.append(m.header.stamp.sec + m.header.stamp.nanosec * 1e-9),
        RELIABLE)
    spin_until(executor, lambda: False, timeout_s=8.0)  # the fish comes to rest, then on
    assert published, 'no speed estimate was published'
    data = _live(browser, 'window.wirefish.plots.speed.data')
    plotted = [t for t, v in zip(data[0], data[1]) if v is not None and t >= published[0]]
    truths = [t for t, v in zip(data[0], data[2]) if v is not None]
    print(f'estimates published {len(published)}, last at {published[-1]:.3f}; plotted '
          f'since the first: {len(plotted)}, last at {max(plotted, default=0):.3f}; ground '
          f'truth up to {max(truths):.3f}')
    assert max(plotted, default=-math.inf) <= published[-1] + 1e-6
    assert all(min(abs(t - p) for p in published) < 1e-6 for t in plotted)  # at their stamps


def test_after_stop_and_a_retune_the_body_wave_axis_is_the_tails(browser):
    _retune_from_form(browser, c1='0.15', k='8.0', max_iterations='5')
    assert _wait_page(browser, DONE, 120.0), _live(browser, 'window.wirefish.retune')
    time.sleep(2.0)
    scale = _live(browser, 'window.wirefish.plots.wave.scales.x')
    assert scale['min'] == 0 and 0.1 < scale['max'] < 1.0, scale  # the tail: 0.24 m
