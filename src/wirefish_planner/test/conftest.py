# SPDX-License-Identifier: Apache-2.0
"""
Fixtures of the planner's pure tests: the planner, CPG and virtual fish in one process.

What the graph does, minus DDS: cmd_vel legs -> ``Planner`` -> CPG parameters -> servo commands
at 200 Hz -> ``VirtualFish`` -> IMU samples (its telemetry model, 100 Hz) -> ``Planner``. Runs
faster than real time; the pure tests and the gain tuning use it, the cross-process tests check
the same claims on the real graph.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
from types import SimpleNamespace

import numpy as np
import pytest
from wirefish_cpg.oscillator import CpgIntegrator, CpgParameters
from wirefish_planner.gait_choice import GaitLimits, GaitPlanner, Table1Family
from wirefish_planner.planner_config import planner_from
from wirefish_planner.planner_core import Planner
from wirefish_planner.planner_node_parameters import TABLE
from wirefish_sim.faults import disturb, Disturbance
from wirefish_sim.virtual_fish import SimConfig, VirtualFish

COMMAND_DT_S = 0.005  # cpg_node's servo_cmd period
IMU_EVERY = 2  # IMU samples every 2 command periods (100 Hz)
PLAN_EVERY = 10  # planner step every 10 command periods (20 Hz)


@dataclass(frozen=True)
class Leg:
    """One cmd_vel leg: forward speed (m/s) and yaw rate (rad/s) for ``duration_s``."""

    duration_s: float
    speed: float
    yaw_rate: float = 0.0


@dataclass
class Trace:
    """Ground truth and planner outputs sampled every command period."""

    t: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray
    yaw: np.ndarray
    x: np.ndarray
    y: np.ndarray
    offset: np.ndarray
    servo: np.ndarray  # (T, 2) servo commands (rad)
    modes: list[str]


def cpg_target(params: CpgParameters | None, offset: float,
               base: CpgParameters) -> CpgParameters:
    """Return the CPG parameters the planner sets: the gait (or rest) with b_1 = b_2 = offset."""
    if params is None:
        return replace(base, amplitude=(0.0, 0.0), offset=(0.0, 0.0))
    return replace(params, offset=(offset, offset))


def run_legs(planner: Planner, legs: list[Leg], disturbance: Disturbance | None = None,
             config: SimConfig | None = None, seed: int = 0) -> Trace:
    """Drive the virtual fish through ``legs`` (cmd_vel repeated at 20 Hz) and trace it."""
    config = config or SimConfig(command_timeout_s=None, heartbeat_timeout_s=None)
    fish = VirtualFish(config, rng=np.random.default_rng(seed))
    disturbance = disturbance or Disturbance()
    base = CpgParameters()
    rest = cpg_target(None, 0.0, base)
    cpg = CpgIntegrator(rest, step_s=0.001)
    applied = rest
    rows, servos, modes = [], [], []
    t = 0.0
    step = 0
    for leg in legs:
        for _ in range(int(round(leg.duration_s / COMMAND_DT_S))):
            if leg.speed >= 0.0 and step % PLAN_EVERY == 0:
                planner.command(t, leg.speed, leg.yaw_rate)
            if step % IMU_EVERY == 0:
                imu = fish.telemetry()
                planner.imu(t, t, imu.yaw, imu.gyro[2])
            if step % PLAN_EVERY == 0:
                out = planner.step(t)
                wanted = cpg_target(out.gait.point and out.gait.point.params, out.offset, base)
                if wanted != applied:
                    cpg.set_parameters(wanted)
                    applied = wanted
                modes.append(out.mode)
            cpg.advance(t)
            angles, _ = cpg.output(t)
            fish.command(float(angles[0]), float(angles[1]))
            fish.step(COMMAND_DT_S)
            if disturbance.active:
                disturb(fish.state, disturbance, COMMAND_DT_S, config.yaw_time_constant_s,
                        fish.total_mass)
            s = fish.state
            rows.append((t, s.speed, s.yaw_rate, s.yaw, s.x, s.y, applied.offset[0]))
            servos.append(angles)
            t += COMMAND_DT_S
            step += 1
    data = np.array(rows)
    return Trace(*(data[:, i] for i in range(7)), np.array(servos), modes)


def heading_rms_deg(yaw: np.ndarray, target: float) -> float:
    """Return the RMS of wrap(yaw - target) in degrees."""
    error = (yaw - target + math.pi) % (2.0 * math.pi) - math.pi
    return float(np.degrees(np.sqrt(np.mean(error ** 2))))


@pytest.fixture(scope='session')
def gait_planner() -> GaitPlanner:
    """Return the default gait planner (Table 1 family, default limits)."""
    return GaitPlanner(Table1Family(), GaitLimits())


@pytest.fixture
def make_planner():
    """Return ``make(**parameter overrides) -> Planner`` on the node's defaults."""
    def make(**overrides) -> Planner:
        return planner_from({**TABLE.defaults(), **overrides})
    return make


@pytest.fixture(scope='session')
def closed_loop() -> SimpleNamespace:
    """Return the in-process drive: ``Leg``, ``run_legs`` and ``heading_rms_deg``."""
    return SimpleNamespace(Leg=Leg, run_legs=run_legs, heading_rms_deg=heading_rms_deg)
