# SPDX-License-Identifier: Apache-2.0
"""The bridge's graph time: a simulated clock drives the gate and link health, never back."""

from wirefish_bridge.command_gate import CommandGate, NEUTRAL
from wirefish_bridge.graph_clock import GraphTime
from wirefish_bridge.link_health import Level, LinkHealth
from wirefish_bridge.protocol import Heartbeat, Role
from wirefish_bridge.transport import LinkState, LinkStats


class SimulatedClock:
    """A node clock the test steps: seconds of simulated time, read through ``GraphTime``."""

    def __init__(self, start_s: float) -> None:
        self.clock_s = start_s
        self.graph = GraphTime()

    def now(self) -> float:
        return self.graph(self.clock_s)


def test_graph_time_follows_the_clock_and_carries_on_over_a_jump_back():
    graph = GraphTime()
    assert [graph(t) for t in (5.0, 5.01, 5.02)] == [5.0, 5.01, 5.02]
    assert graph(0.0) == 5.02          # fish_sim restarted: a pause of no length
    assert graph(0.25) == 5.27         # then the clock's steps, one for one
    assert graph.jumps_back == 1


def test_a_100_hz_gate_passes_every_10_ms_step_of_simulated_time_however_long_in_wall_time():
    # The lockstep: one command per 10 ms step, each arriving whenever the loaded machine
    # delivers it; in simulated time the rate is exactly the limit, so none is held.
    clock = SimulatedClock(1000.0)
    gate = CommandGate(max_rate_hz=100.0, timeout_s=0.5, limit_rad=1.0)
    sent = []
    for step in range(300):
        clock.clock_s = 1000.0 + 0.01 * step
        sent.append(gate.on_command((0.1, -0.1), clock.now()))
        assert gate.on_tick(clock.now()) is None
    assert all(s == (0.1, -0.1) for s in sent)


def test_the_command_timeout_counts_simulated_time_not_the_wait_for_a_step():
    clock = SimulatedClock(50.0)
    gate = CommandGate(max_rate_hz=100.0, timeout_s=0.5, limit_rad=1.0)
    assert gate.on_command((0.2, 0.2), clock.now()) == (0.2, 0.2)
    for _ in range(1000):   # the clock waits for the next command: simulated time stands still
        assert gate.on_tick(clock.now()) is None
    assert not gate.failsafe
    clock.clock_s += 0.51
    assert gate.on_tick(clock.now()) == NEUTRAL and gate.failsafe


def test_a_jump_back_of_the_clock_still_times_out_a_silent_host():
    clock = SimulatedClock(300.0)
    gate = CommandGate(max_rate_hz=100.0, timeout_s=0.5, limit_rad=1.0)
    gate.on_command((0.2, 0.2), clock.now())
    clock.clock_s = 0.0        # fish_sim restarted from 0: without GraphTime the age is -300 s
    gate.on_tick(clock.now())
    clock.clock_s = 0.6
    assert gate.on_tick(clock.now()) == NEUTRAL


def test_the_heartbeat_age_counts_simulated_seconds():
    clock = SimulatedClock(20.0)
    health = LinkHealth(heartbeat_timeout_s=1.0, now=clock.now())
    health.on_heartbeat(Heartbeat(role=Role.FISH), clock.now())
    clock.clock_s = 20.9
    assert health.level(clock.now(), LinkState.CONNECTED, '/dev/fish', LinkStats(),
                        False)[0] is Level.OK
    clock.clock_s = 21.2
    level, message = health.level(clock.now(), LinkState.CONNECTED, '/dev/fish', LinkStats(),
                                  False)
    assert level is Level.WARN and 'heartbeat stale' in message
    assert abs(health.heartbeat_age(clock.now()) - 1.2) < 1e-9
