# SPDX-License-Identifier: Apache-2.0
"""The virtual fish's disturbances (wirefish_sim.faults, fish_sim flags) for the planner."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from wirefish_kinematics.lighthill import drag_force
from wirefish_sim.faults import disturb, Disturbance
from wirefish_sim.fish_sim import build_parser, flags_problem
from wirefish_sim.virtual_fish import SimConfig, VirtualFish


def _drift(disturbance: Disturbance, seconds: float) -> VirtualFish:
    """Return a fish with a straight, still tail after ``seconds`` in ``disturbance``."""
    config = SimConfig(command_timeout_s=None, heartbeat_timeout_s=None)
    fish = VirtualFish(config, rng=np.random.default_rng(0))
    for _ in range(int(seconds / 0.01)):
        fish.step(0.01)
        disturb(fish.state, disturbance, 0.01, config.yaw_time_constant_s, fish.total_mass)
    return fish


def test_a_yaw_disturbance_turns_a_straight_fish_at_its_rate():
    fish = _drift(Disturbance(yaw_rate_rad_s=0.05), 3.0)
    assert fish.state.yaw_rate == pytest.approx(0.05, rel=0.02)
    assert fish.state.yaw > 0.0  # + turns left (REP-103)


def test_a_surge_force_settles_where_drag_balances_it():
    fish = _drift(Disturbance(surge_force_n=0.5), 20.0)
    expected = brentq(lambda u: float(drag_force(u, fish.geometry)) - 0.5, 1e-6, 2.0)
    assert fish.state.speed == pytest.approx(expected, rel=0.02)


def test_no_disturbance_is_inactive():
    assert not Disturbance().active and Disturbance(0.0, -1.0).active


@pytest.mark.parametrize('value', [math.nan, math.inf])
def test_non_finite_disturbances_are_refused(value):
    with pytest.raises(ValueError):
        Disturbance(yaw_rate_rad_s=value)
    args = build_parser().parse_args(['--surge-disturbance', str(value)])
    assert '--surge-disturbance must be finite' in flags_problem(args)


def test_fish_sim_takes_the_disturbance_flags():
    args = build_parser().parse_args(['--yaw-disturbance', '0.05', '--surge-disturbance',
                                      '-0.2'])
    assert (args.yaw_disturbance, args.surge_disturbance) == (0.05, -0.2)
    assert flags_problem(args) is None
