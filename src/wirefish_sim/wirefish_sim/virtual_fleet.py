# SPDX-License-Identifier: Apache-2.0
"""
A school of virtual fish on one clock: each fish's firmware of its own, one physics for all.

``VirtualFleet.step(dt)`` advances every fish by the same simulated time in the same fixed
physics steps (``virtual_fish.swim``: the tail kinematics and the surge/yaw integration are
vectorised over the fish), so N fish cost one process and little more than one fish's
numpy calls. Each fish keeps everything that is its own: its firmware (``receive``,
failsafes, telemetry and heartbeats), its IMU noise Generator, its state. A fish of the fleet
swims as the same fish alone would, given the same inputs (to float rounding).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from wirefish_kinematics.geometry import FishGeometry
from wirefish_sim.servo_trim_store import Storage
from wirefish_sim.virtual_fish import physics_steps, SimConfig, swim, VirtualFish


class VirtualFleet:
    """``len(rngs)`` virtual fish of one config and geometry, advanced together."""

    def __init__(self, rngs: Sequence[np.random.Generator], config: SimConfig | None = None,
                 geometry: FishGeometry | None = None,
                 storages: Sequence[Storage | None] | None = None) -> None:
        """
        Build one fish at rest per Generator (its IMU biases and noise).

        ``storages``: each fish's calibration storage (None, or a None of it: in RAM).
        """
        if not rngs:
            raise ValueError('a fleet has at least one fish')
        if storages is not None and len(storages) != len(rngs):
            raise ValueError(f'{len(storages)} calibration storages for {len(rngs)} fish')
        config = config or SimConfig()
        geometry = geometry or FishGeometry()
        self.fish = tuple(VirtualFish(config, geometry, rng, storage)
                          for rng, storage in zip(rngs, storages or [None] * len(rngs)))
        self.config, self.geometry = config, geometry
        self._remainder = 0.0

    def __len__(self) -> int:
        """Return the number of fish."""
        return len(self.fish)

    def step(self, dt: float) -> None:
        """Advance every fish by ``dt`` s of simulated time (the part of a step is carried)."""
        count, self._remainder = physics_steps(self._remainder, dt, self.config.physics_dt_s)
        if count > 0:
            swim(self.fish, count)
