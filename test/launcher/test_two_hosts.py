# SPDX-License-Identifier: Apache-2.0
"""
Acceptance across two hosts, a fish and a shore, over a radio that fails.

The fish role runs in one network namespace, the shore role in another, DDS over a veth pair
between them (multicast discovery, UDPv4 only: see netns.py).

One run, in phases (each needs the graph up, which takes most of the time): the fish swims
(servo_cmd >= 95 % of its default rate measured inside the fish's namespace) and the shore gets its
copies of imu/data and speed_estimate; a retune called on the shore applies on the fish; the link
is cut for 10 s while the shore drives: servo_cmd never pauses, the planner's cmd_vel timeout rests
the fish, nothing reaches the shore; the link returns: the shore sees the streams again within
RECOVERY_BOUND_S and a second retune applies; under a 100 kbit/s token bucket every relayed topic
arrives at its configured rate, with the bytes per second crossing each way printed (the
BENCHMARKS.md row). Wall time ~2.5 min. The run is made once per module (the ``run`` fixture:
what must hold for the next phase to mean anything is waited for there); each test judges one
of its claims.
"""

from dataclasses import dataclass
import re
import time

from link_hosts import wait_for
import numpy as np
import pytest
from wirefish_bringup.graph import Role
from wirefish_cpg.cpg_node_parameters import TABLE as CPG_TABLE
from wirefish_relay.crossing import default_crossing_file, load_crossing

pytestmark = pytest.mark.ros

FISH_TOPICS = ('servo_cmd:sensor_msgs/msg/JointState:sensor',
               'planner_state:wirefish_msgs/msg/PlannerState:reliable',
               'cpg_params:wirefish_msgs/msg/CpgParams:latched')
# The crossing topics the fish's probe hears at their source: published on change, not at a rate.
FISH_SOURCES = ('planner_state', 'cpg_params')
CROSSING = load_crossing(default_crossing_file())
SHORE_TOPICS = tuple(f'{row.shore_topic}:{row.type_name}:{row.qos}' for row in CROSSING)
UP_TIMEOUT_S = 90.0  # both graphs start on the loaded 2-core machine and discover each other
CUT_S = 10.0
# The link returns: Fast DDS's participant lease (20 s) outlasts a 10 s cut, so nothing has to
# be discovered again; data resumes with the next sample or resend.
RECOVERY_BOUND_S = 15.0
SERVO_GAP_BOUND_S = 0.25  # 25 periods at 100 Hz: a pause, not a scheduling hiccup
SERVO_MIN_HZ = 0.95 * CPG_TABLE.by_name['publish_rate_hz'].default
REST_WITHIN_S = 3.0  # cmd_vel_timeout_s 0.5 + a control period + the CPG's parameter call
RATE_WINDOW_S = 10.0
SERVO_WINDOW_S = 5.0  # of driving before the cut
RATE_FRACTION = 0.8  # of each relayed topic's configured rate, over RATE_WINDOW_S
RADIO_BYTES_PER_S = 100e3 / 8  # the 100 kbit/s of the shaped window, each way


def _count(probe, topic: str) -> int:
    reports = probe.reports()
    return reports[-1]['counts'][topic] if reports else 0


def _rate(probe, topic: str, start: float, end: float) -> float:
    inside = [r for r in probe.reports() if start <= r['t'] <= end]
    assert len(inside) >= 2, f'no reports of {topic} in [{start:.1f}, {end:.1f}]'
    first, last = inside[0], inside[-1]
    return (last['counts'][topic] - first['counts'][topic]) / (last['t'] - first['t'])


def _fewest_relay_ticks(times: list[float], period_s: float, phases: int = 50) -> int:
    """
    Return the fewest ticks of a relay every ``period_s`` that find news among ``times``.

    The relay forwards the newest message it holds at each tick, so changes that come in a
    burst within one period cross once; the relay's phase is unknown: the fewest over phases.
    """
    if not times:
        return 0
    t = np.asarray(times)
    return min(len(np.unique(np.floor((t - phase) / period_s)))
               for phase in np.linspace(0.0, period_s, phases, endpoint=False))


def _max_gap(probe, topic: str, start: float, end: float) -> float:
    return max(r['gap'][topic] for r in probe.reports() if start <= r['t'] <= end)


def _retune(hosts, frequency_hz: float) -> float:
    """Run `wirefish retune --apply` on the shore; return the frequency the fit applied."""
    done = hosts.run(Role.SHORE, ['wirefish', 'retune', '--apply', '--namespace',
                                  hosts.namespace, '--freq', str(frequency_hz), '--iterations',
                                  '30', '--swarm', '20', '--timeout', '60'], timeout_s=90.0)
    print(done.stdout[-1200:], done.stderr[-600:])
    assert done.returncode == 0, 'the retune called from shore failed'
    return float(re.search(r'^frequency_hz\s+([0-9.]+)', done.stdout, re.M).group(1))


def _applied(fish, frequency_hz: float, after: float) -> bool:
    return any(e['t'] > after and abs(e['frequency_hz'] - frequency_hz) < 1e-3
               for e in fish.events('cpg_params'))


@dataclass(frozen=True)
class Run:
    """What the run measured (see the module's docstring)."""

    swim_hz: float
    servo_gap: float
    cut_hz: float
    rested_after: float | None
    imu_cut_start: int
    imu_cut: int
    figures: dict


@pytest.fixture(scope='module')
def run(module_hosts) -> Run:
    """Start both roles, drive, cut and restore the link, retune, shape it; return the figures."""
    hosts = module_hosts
    link = hosts.link
    hosts.up(Role.FISH, 'fish')
    hosts.up(Role.SHORE, 'shore')
    fish = hosts.probe(Role.FISH, *FISH_TOPICS)
    shore = hosts.probe(Role.SHORE, *SHORE_TOPICS)
    started = time.monotonic()
    wait_for(lambda: _count(shore, 'shore/imu/data') > 0
             and _count(shore, 'shore/speed_estimate') > 0, UP_TIMEOUT_S,
             'the shore receives imu/data and speed_estimate')
    print(f'shore streams after {time.monotonic() - started:.1f} s')

    # The fish swims (servo_cmd inside the fish's namespace: measured below, over the drive
    # and the cut, once start-up and discovery no longer share the 2 cores).
    time.sleep(2.0)
    now = time.monotonic()
    print(f'servo_cmd on the fish during start-up: {_rate(fish, "servo_cmd", now - 2, now):.1f} '
          'Hz')

    # A retune called from shore applies on the fish.
    asked = time.monotonic()
    frequency = _retune(hosts, 1.2)
    wait_for(lambda: _applied(fish, frequency, asked), 10.0, 'the fit in cpg_params on the fish')
    wait_for(lambda: any(abs(e['frequency_hz'] - frequency) < 1e-3
                         for e in shore.events('cpg_params')), 10.0,
             "the fit in the shore's copy of cpg_params")

    # The fit is a manual override (the planner does not drive it); the shore hands it back.
    # A new participant on the shore finds the fish's service across the link: on the loaded
    # machine that took longer than hand-back's default 10 s (seen once in a full run).
    handed = hosts.run(Role.SHORE, ['wirefish', 'hand-back', '--namespace', hosts.namespace,
                                    '--timeout', '30'], timeout_s=60.0)
    assert handed.returncode == 0, handed.stderr

    # The shore drives; the link is cut for 10 s.
    shore.send('go 0.2 0.0')
    wait_for(lambda: fish.events('planner_state')[-1]['mode'] != 'rest', 15.0,
             'the planner drives on cmd_vel from shore')
    drive_at = time.monotonic()
    time.sleep(SERVO_WINDOW_S)
    gap_before = _max_gap(fish, 'servo_cmd', time.monotonic() - 3.0, time.monotonic())
    cut_at = time.monotonic()
    link.cut()
    time.sleep(1.0)  # the probe's last report before the cut may still be on its way
    imu_cut_start = _count(shore, 'shore/imu/data')
    time.sleep(CUT_S - 1.0)
    imu_cut = _count(shore, 'shore/imu/data')
    restored_at = time.monotonic()
    link.restore()
    rested = [e for e in fish.events('planner_state') if cut_at < e['t'] and e['mode'] == 'rest']
    servo_gap = _max_gap(fish, 'servo_cmd', cut_at, restored_at)
    cut_hz = _rate(fish, 'servo_cmd', cut_at, restored_at)
    print(f'link cut {CUT_S:g} s: servo_cmd {cut_hz:.1f} Hz, longest gap {servo_gap * 1e3:.0f} '
          f'ms (before the cut {gap_before * 1e3:.0f} ms); planner at rest '
          f'{rested[0]["t"] - cut_at if rested else float("nan"):.2f} s after the cut; the '
          f'shore got {imu_cut - imu_cut_start} imu/data copies in its last {CUT_S - 1:g} s')
    swim_hz = _rate(fish, 'servo_cmd', drive_at, restored_at)
    print(f'servo_cmd on the fish over the drive and the cut: {swim_hz:.1f} Hz')
    rested_after = rested[0]['t'] - cut_at if rested else None

    back = wait_for(lambda: _count(shore, 'shore/imu/data') > imu_cut, RECOVERY_BOUND_S,
                    'the shore sees imu/data again after the link returns')
    print(f'streams back on the shore {back - restored_at:.2f} s after the link returned '
          f'(bound {RECOVERY_BOUND_S:g} s)')
    wait_for(lambda: fish.events('planner_state')[-1]['mode'] != 'rest', 10.0,
             'cmd_vel from shore reaches the planner again')

    # A retune from shore after the outage (the shore stops driving first, so the fish rests
    # before the fit takes over as a manual override).
    shore.send('halt')
    wait_for(lambda: fish.events('planner_state')[-1]['mode'] == 'rest', 10.0,
             'the fish rests when the shore stops driving')
    asked = time.monotonic()
    frequency = _retune(hosts, 1.5)
    wait_for(lambda: _applied(fish, frequency, asked), 10.0,
             'the second fit in cpg_params on the fish')

    # Bytes crossing, then the same under a 100 kbit/s token bucket, the shore driving.
    shore.send('go 0.2 0.0')
    figures = {}
    for shaped in (False, True):
        if shaped:
            link.shape('100kbit', '16kbit', '400ms')
            time.sleep(3.0)  # queues settle under the new limit
        tx0, t0 = (link.tx_bytes(Role.FISH), link.tx_bytes(Role.SHORE)), time.monotonic()
        time.sleep(RATE_WINDOW_S)
        tx1, t1 = (link.tx_bytes(Role.FISH), link.tx_bytes(Role.SHORE)), time.monotonic()
        rates = {row.topic: _rate(shore, row.shore_topic, t0, t1) for row in CROSSING}
        sources = {row.topic: _rate(fish, row.topic, t0, t1) for row in CROSSING
                   if row.topic in FISH_SOURCES}
        # What an on-change topic can cross at most: the relay ticks that find a change.
        news = {row.topic: _fewest_relay_ticks(
            [e['t'] for e in fish.events(row.topic) if t0 <= e['t'] < t1],
            1.0 / row.rate_hz) / (t1 - t0)
            for row in CROSSING if row.topic in FISH_SOURCES and row.rate_hz > 0}
        figures[shaped] = ((tx1[0] - tx0[0]) / (t1 - t0), (tx1[1] - tx0[1]) / (t1 - t0), rates,
                           sources, news)
        print(f'{"100 kbit/s tbf" if shaped else "unshaped":>15}: fish->shore '
              f'{figures[shaped][0]:.0f} B/s, shore->fish {figures[shaped][1]:.0f} B/s; '
              + ', '.join(f'{topic} {hz:.1f} Hz' for topic, hz in rates.items()))
    qdisc = link.qdisc(Role.FISH)
    print(qdisc)
    dropped = int(re.search(r'dropped (\d+)', qdisc).group(1))
    print(f'tbf on the fish side: {dropped} packets dropped in {RATE_WINDOW_S + 3:g} s')
    print('on the fish in the shaped window: ' + ', '.join(
        f'{topic} {hz:.2f} Hz ({figures[True][4][topic]:.2f} Hz of relay ticks with a change)'
        for topic, hz in figures[True][3].items()))
    return Run(swim_hz, servo_gap, cut_hz, rested_after, imu_cut_start, imu_cut, figures)


def test_the_fish_swims_through_the_drive_and_the_cut(run):
    assert run.swim_hz >= SERVO_MIN_HZ


def test_servo_cmd_never_pauses_while_the_link_is_cut(run):
    assert run.servo_gap < SERVO_GAP_BOUND_S and run.cut_hz >= SERVO_MIN_HZ


def test_the_planner_rests_the_fish_soon_after_the_cut(run):
    assert run.rested_after is not None and run.rested_after < REST_WITHIN_S


def test_nothing_reaches_the_shore_while_the_link_is_cut(run):
    assert run.imu_cut == run.imu_cut_start  # the cut cuts (no shared-memory path past the veth)


@pytest.mark.parametrize('row', [row for row in CROSSING if row.rate_hz > 0],
                         ids=lambda row: row.topic)
def test_every_relayed_topic_crosses_a_100_kbit_radio_at_its_rate(run, row):
    figures = run.figures
    # An on-change topic (cpg_params, planner_state) crosses at most once per relay tick
    # that finds a change on the fish (changes come in bursts: 16 in one window were
    # seen to cross as 5). Every topic has one message of slack for the window's ends: at
    # 0.5 Hz a span of 9.5 s holds 4 or 5 messages by phase alone, so without it battery had
    # no sample to lose (best effort through the bucket) where the fraction leaves a fifth.
    wanted = min(row.rate_hz, figures[True][4].get(row.topic, row.rate_hz))
    slack = 1.0 / RATE_WINDOW_S
    assert figures[True][2][row.topic] >= RATE_FRACTION * wanted - slack, row.topic


def test_the_speed_estimate_crosses_the_shaped_radio(run):
    assert run.figures[True][2]['speed_estimate'] > 0.0


def test_what_the_fish_sends_unshaped_fits_the_radio(run):
    # Discovery announces every 10 s (dds_profile). The bucket's drops are printed, not
    # judged: with the demand under the rate they come from bursts of a relay that a loaded
    # machine held back (0-9 of ~360 packets in clean-clone runs on two workers, 18 on three),
    # not from the demand.
    assert run.figures[False][0] < RADIO_BYTES_PER_S
