# SPDX-License-Identifier: Apache-2.0
"""
The live view's cost: CPU of the view server with one browser on the dashboard, and the rates.

One `wirefish up --sim --view` graph (the view on free ports); then a 10 s window with no
client (the view idle: it subscribes to nothing), and a 10 s window with Debian's headless
chromium on the dashboard (Selenium), which subscribes to the dashboard's topics, servo_cmd
among them. In each window: the view_node process's CPU, the rest of the graph's, the
browser's (chromium and its children), and the rates of servo_cmd and imu/data as a separate
ROS subscriber receives them (header stamps in the window); a third window without the
browser again says how much the machine's own noise moves them. ``python -m
wirefish_bench.bench_view`` prints the JSON.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from typing import Any

NAMESPACE = '/bench_view'
WINDOW_S = 10.0
WARM_UP_S = 5.0
STREAMS = {'servo_cmd': 'sensor_msgs.msg:JointState', 'imu/data': 'sensor_msgs.msg:Imu'}


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def _cpu_s(processes: list) -> float:
    import psutil

    total = 0.0
    for p in processes:
        try:
            t = p.cpu_times()
            total += t.user + t.system
        except psutil.NoSuchProcess:
            pass
    return total


def _start_graph(domain_id: int, out: Path, ws_port: int, http_port: int
                 ) -> subprocess.Popen:
    from wirefish_bringup.graph import default_params_file

    params = out / 'params.yaml'
    params.write_text(default_params_file().read_text() + (
        f'\n/**/view_node:\n  ros__parameters:\n    port: {ws_port}\n'
        f'    http_port: {http_port}\n'))
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    launcher = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--sim', '--view', '--no-status',
         '--namespace', NAMESPACE, '--out', str(out), '--params-file', str(params)],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    assert launcher.stdout is not None
    deadline = time.monotonic() + 90.0
    while time.monotonic() < deadline:
        line = launcher.stdout.readline()
        if not line or line.startswith('running:'):
            break
    return launcher


def _window(node, executor, processes: dict[str, list]) -> dict[str, Any]:
    """Measure one window: CPU % of a core per group, and each stream's rate (Hz)."""
    import importlib

    from wirefish_common.qos import SENSOR_DATA

    stamps: dict[str, list[float]] = {topic: [] for topic in STREAMS}
    subscriptions = []
    for topic, kind in STREAMS.items():
        module, name = kind.split(':')
        message = getattr(importlib.import_module(module), name)
        subscriptions.append(node.create_subscription(
            message, f'{NAMESPACE}/{topic}',
            lambda m, t=topic: stamps[t].append(
                m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec), SENSOR_DATA))
    end = time.monotonic() + WARM_UP_S
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)
    start_cpu = {group: _cpu_s(ps) for group, ps in processes.items()}
    start_wall, start_stamp = time.monotonic(), time.time()
    while time.monotonic() < start_wall + WINDOW_S:
        executor.spin_once(timeout_sec=0.05)
    wall = time.monotonic() - start_wall
    cpu = {group: 100.0 * (_cpu_s(ps) - start_cpu[group]) / wall
           for group, ps in processes.items()}
    rates = {topic: sum(start_stamp <= s < start_stamp + WINDOW_S for s in values) / WINDOW_S
             for topic, values in stamps.items()}
    for subscription in subscriptions:
        node.destroy_subscription(subscription)
    return {'cpu_percent': cpu, 'rates_hz': rates}


def _browser(url: str):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which('chromium') or 'chromium'
    for argument in ('--headless=new', '--no-sandbox', '--disable-gpu',
                     '--disable-dev-shm-usage', '--window-size=1400,1100'):
        options.add_argument(argument)
    driver = webdriver.Chrome(options=options,
                              service=Service(shutil.which('chromedriver') or 'chromedriver'))
    driver.get(url)
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline and not driver.execute_script(
            'return window.wirefish && window.wirefish.plots.servo'
            ' && window.wirefish.plots.servo.data[0].length > 50;'):
        time.sleep(0.2)
    return driver


def run(domain_id: int) -> dict[str, Any]:
    """Return the figures of the view idle and with one browser (see the module docstring)."""
    import psutil
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    out = Path(tempfile.mkdtemp(prefix='bench_view_'))
    ws_port, http_port = _free_port(), _free_port()
    launcher = _start_graph(domain_id, out, ws_port, http_port)
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    node = rclpy.create_node('bench_view_probe', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    driver = None
    try:
        graph = psutil.Process(launcher.pid).children(recursive=True)
        view = [p for p in graph if any('view_node' in a for a in p.cmdline())]
        if not view:
            raise RuntimeError('no view_node process in the graph')
        rest = [p for p in graph if p not in view]
        idle = _window(node, executor, {'view_node': view, 'graph': rest})
        driver = _browser(f'http://127.0.0.1:{http_port}/')
        browser = psutil.Process(driver.service.process.pid).children(recursive=True)
        with_browser = _window(node, executor, {'view_node': view, 'graph': rest,
                                                'browser': browser})
        driver.quit()
        driver = None
        # The same again without the browser: how much of a change is the machine's own noise.
        after = _window(node, executor, {'view_node': view, 'graph': rest})
        return {'idle': idle, 'one_browser': with_browser, 'after': after,
                'window_s': WINDOW_S, 'load_average': os.getloadavg()}
    finally:
        if driver is not None:
            driver.quit()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        _stop(launcher)


def _stop(launcher: subprocess.Popen) -> None:
    """SIGINT the graph's process group (as Ctrl-C does), SIGKILL it if it lingers."""
    import signal

    try:
        os.killpg(launcher.pid, signal.SIGINT)
        launcher.wait(timeout=20.0)
    except subprocess.TimeoutExpired:
        os.killpg(launcher.pid, signal.SIGKILL)
        launcher.wait()
    except ProcessLookupError:
        pass
    if launcher.stdout is not None:
        launcher.stdout.close()


def row(result: dict) -> tuple[str, str, str, str, str]:
    """Return the BENCHMARKS.md row: (figure, goal, measured, verdict, how)."""
    figure = 'View server (wirefish up --view) with one browser on the dashboard: CPU, rates'
    goal = 'servo_cmd, imu/data at their rates with the view on'
    if 'error' in result:
        return figure, goal, result['error'], 'not measured', ''
    idle, one = result['idle'], result['one_browser']

    def rates(w: dict) -> str:
        return ', '.join(f'{t} {hz:.1f} Hz' for t, hz in w['rates_hz'].items())
    after = result.get('after')
    measured = (f'view_node {one["cpu_percent"]["view_node"]:.1f} % of a core with the browser '
                f'({idle["cpu_percent"]["view_node"]:.1f} % idle); the rest of the graph '
                f'{one["cpu_percent"]["graph"]:.1f} % ({idle["cpu_percent"]["graph"]:.1f} %); '
                f'chromium {one["cpu_percent"]["browser"]:.1f} %; {rates(one)} '
                f'(without a client before: {rates(idle)}'
                + (f'; after: {rates(after)}' if after else '') + ')'
                + (f'; load average {result["load_average"][0]:.1f}'
                   if 'load_average' in result else ''))
    met = all(one['rates_hz'][t] >= 0.95 * idle['rates_hz'][t] for t in STREAMS)
    return (figure, goal, measured, 'met' if met else 'missed',
            f'wirefish up --sim --view, {result["window_s"]:g} s windows after '
            f'{WARM_UP_S:g} s, idle then Debian headless chromium via Selenium on the '
            'dashboard; psutil CPU; rates from header stamps at a separate subscriber; '
            'goal: each ≥ 95 % of its rate without a client (bench_view.py)')


def main() -> int:
    """Print the JSON of ``run`` on domain WIREFISH_BENCH_DOMAIN (101)."""
    print(json.dumps(run(int(os.environ.get('WIREFISH_BENCH_DOMAIN', '101'))), indent=2))
    return 0


if __name__ == '__main__':
    sys.exit(main())
