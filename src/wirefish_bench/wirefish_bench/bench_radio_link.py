# SPDX-License-Identifier: Apache-2.0
"""
Benchmark: bytes per second crossing the fish-shore radio link, per discovery mode.

A fish host and a shore host in two network namespaces (``wirefish_launcher.netns``, root
only), ``wirefish up --role fish`` on one and ``wirefish up --role shore --duration`` on the
other (the shore records its copies of the crossing topics: config/crossing.yaml). Once the
shore records, the transmit counters of both veth ends are read over a window, first as is,
then under a 100 kbit/s token bucket (tc tbf) on each direction; the shore's bag gives the
rate at which each copy arrived in the shaped window. Both DDS discoveries are measured:
multicast (SUBNET) and static peers (LOCALHOST + ROS_STATIC_PEERS). No cmd_vel is sent (the
two-host test drives from shore: +4.6 kB/s shore -> fish at 20 Hz).

``python -m wirefish_bench.bench_radio_link`` prints the figures as JSON; ``row(result)`` is
the BENCHMARKS.md row.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time

NAMESPACE = '/bench_radio'
SETTLE_S = 8.0  # after the shore starts recording: discovery's burst is over
WINDOW_S = 10.0
LIMIT = '100kbit'
LIMIT_BYTES_S = 100_000 / 8


def _window(link, seconds: float) -> dict:
    from wirefish_bringup.graph import Role

    before, t0 = (link.tx_bytes(Role.FISH), link.tx_bytes(Role.SHORE)), time.monotonic()
    time.sleep(seconds)
    after, t1 = (link.tx_bytes(Role.FISH), link.tx_bytes(Role.SHORE)), time.monotonic()
    return {'fish_to_shore_B_s': (after[0] - before[0]) / (t1 - t0),
            'shore_to_fish_B_s': (after[1] - before[1]) / (t1 - t0), 'start': t0, 'end': t1}


def _wait_for_line(proc: subprocess.Popen, start: str, what: str) -> None:
    assert proc.stdout is not None  # started with stdout=PIPE
    for line in proc.stdout:
        if line.startswith(start):
            return
    raise RuntimeError(f'the {what} side ended before printing {start!r}')


def measure(discovery: str, domain_id: int, subnet: int) -> dict:
    """Return the bytes crossing each way, unshaped and under the limit, for one discovery."""
    from wirefish_bag.bagfile import read_bag
    from wirefish_bringup.graph import Role
    from wirefish_launcher.netns import TwoHosts

    link = TwoHosts(f'b{os.getpid() % 10**6:x}', subnet)
    out = Path(tempfile.mkdtemp(prefix='wirefish_bench_radio_'))
    duration = SETTLE_S + 2 * WINDOW_S + 6.0
    procs = []
    link.remove()
    link.create()
    try:
        def up(side: Role, *extra: str) -> subprocess.Popen:
            env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
                       **link.ros_environment(side, discovery))
            proc = subprocess.Popen(
                [*link.exec_prefix(side), sys.executable, '-m', 'wirefish_cli.cli', 'up',
                 '--role', side, '--namespace', NAMESPACE, '--no-status', '--out',
                 str(out / side), *extra], env=env, stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT, text=True, start_new_session=True)
            procs.append(proc)
            return proc

        fish = up(Role.FISH)
        _wait_for_line(fish, 'running:', Role.FISH)
        shore = up(Role.SHORE, '--duration', str(duration))
        _wait_for_line(shore, 'recording to', Role.SHORE)
        time.sleep(SETTLE_S)
        unshaped = _window(link, WINDOW_S)
        link.shape(LIMIT, '16kbit', '400ms')
        time.sleep(3.0)
        shaped = _window(link, WINDOW_S)
        drops = link.qdisc(Role.FISH)
        shore.wait(timeout=duration + 60)
        bag = next((out / Role.SHORE).glob('run_*/bag'))
        messages = read_bag(bag).messages
        start_ns, end_ns = shaped['start'], shaped['end']
        rates = {}
        for topic, stamped in messages.items():
            # receive times are the recorder's ROS clock (system time): map the window
            t_wall_end = time.time() - (time.monotonic() - end_ns)
            t_wall_start = t_wall_end - (end_ns - start_ns)
            inside = [t for t, _ in stamped if t_wall_start <= t <= t_wall_end]
            rates[topic.removeprefix(f'{NAMESPACE}/')] = len(inside) / (end_ns - start_ns)
        return {'discovery': discovery, 'unshaped': unshaped, 'shaped': shaped,
                'shaped_rates_hz': rates, 'tbf': ' '.join(drops.split())}
    finally:
        for proc in procs:
            if proc.poll() is None:
                os.killpg(proc.pid, 2)
        for proc in procs:
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, 9)
        link.remove()


def run(domain_id: int = 101, subnet: int = 250) -> dict:
    """Measure both discoveries; without root say why nothing was measured."""
    from wirefish_launcher.netns import Discovery, root_problem

    problem = root_problem()
    if problem is not None:
        return {'error': problem}
    return {mode: measure(mode, domain_id, subnet) for mode in Discovery}


def row(result: dict) -> tuple[str, str, str, str, str]:
    """Return the BENCHMARKS.md row: (figure, goal, measured, verdict, how)."""
    figure = 'Fish-shore radio link: bytes/s crossing (fish→shore / shore→fish)'
    goal = f'fits {LIMIT}/s ({LIMIT_BYTES_S:.0f} B/s each way)'
    if 'error' in result:
        return figure, goal, result['error'], 'not measured', ''
    parts, fits = [], {}
    for mode, r in result.items():
        u, s = r['unshaped'], r['shaped']
        parts.append(f'{mode}: {u["fish_to_shore_B_s"]:.0f} / {u["shore_to_fish_B_s"]:.0f} '
                     f'unshaped, {s["fish_to_shore_B_s"]:.0f} / {s["shore_to_fish_B_s"]:.0f} '
                     'under tbf')
        fits[mode] = u['fish_to_shore_B_s'] <= LIMIT_BYTES_S
    # Each discovery is a choice a user makes (README): each gets its own verdict.
    if all(fits.values()) or not any(fits.values()):
        verdict = 'met' if all(fits.values()) else 'missed'
    else:
        verdict = '; '.join(f'{mode}: {"met" if ok else "missed"}' for mode, ok in fits.items())
    return (figure, goal, '; '.join(parts), verdict,
            'two network namespaces, wirefish up --role fish / --role shore (recording), veth '
            'tx counters over 10 s; tc tbf 100kbit burst 16kbit latency 400ms')


if __name__ == '__main__':
    print(json.dumps(run(), indent=2))
