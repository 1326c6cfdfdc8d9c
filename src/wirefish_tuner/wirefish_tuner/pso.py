# SPDX-License-Identifier: Apache-2.0
"""
Global-best particle swarm optimisation, paper eqs 26-27, over a box.

Per particle i and dimension d, with fresh uniform random numbers r1, r2 in [0, 1)::

    v_id = c_w v_id + c_f1 r1 (p_id - x_id) + c_f2 r2 (p_gd - x_id)      (eq 26)
    x_id = x_id + v_id                                                  (eq 27)

The paper gives no rule for the box walls; here a particle that leaves the box is put back on
the wall and loses that velocity component (absorbing walls), and velocities are clamped to a
fraction of the box so that no particle crosses it in one jump. The whole swarm is evaluated in
one call of the loss (shape (P, D) -> (P,)), so the loss can be vectorised over particles.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import math

import numpy as np

SwarmLoss = Callable[[np.ndarray], np.ndarray]
# (iteration, best loss, best position) after each iteration; iteration 0 = initial swarm.
ProgressCallback = Callable[[int, float, np.ndarray], None]


@dataclass(frozen=True)
class PsoOptions:
    """
    Settings of the swarm (eq 26's c_w, c_f1, c_f2) and its stopping rules.

    Defaults: Clerc's constriction-equivalent weights (c_w = 0.7298, c_f = 1.49618), a common
    choice that converges without velocity explosion. The run stops after ``max_iterations``, or
    when the best loss improved by less than ``stall_tolerance`` (relative) for
    ``stall_iterations`` iterations in a row. ``velocity_limit`` is the largest step per
    iteration as a fraction of each dimension's range.
    """

    swarm_size: int = 40
    max_iterations: int = 100
    inertia: float = 0.7298
    cognitive: float = 1.49618
    social: float = 1.49618
    velocity_limit: float = 0.5
    stall_iterations: int = 20
    stall_tolerance: float = 1e-6

    def __post_init__(self) -> None:
        if not 1 <= self.swarm_size <= 100_000:
            raise ValueError(f'swarm_size must be in [1, 100000], got {self.swarm_size}')
        if not 1 <= self.max_iterations <= 100_000:
            raise ValueError(f'max_iterations must be in [1, 100000], got {self.max_iterations}')
        if self.stall_iterations < 1:
            raise ValueError(f'stall_iterations must be >= 1, got {self.stall_iterations}')
        for name in ('inertia', 'cognitive', 'social', 'velocity_limit', 'stall_tolerance'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f'{name} must be finite and >= 0, got {value}')


@dataclass(frozen=True)
class PsoResult:
    """
    Outcome of a run: best position (D,) and loss, iteration count and the history.

    ``loss_history`` (iterations + 1,) and ``position_history`` (iterations + 1, D) hold the
    global best after the initial evaluation (index 0) and after every iteration.
    """

    best_position: np.ndarray
    best_loss: float
    iterations: int
    loss_history: np.ndarray
    position_history: np.ndarray
    stalled: bool


def minimise(loss: SwarmLoss, lower: np.ndarray, upper: np.ndarray,
             rng: np.random.Generator, options: PsoOptions = PsoOptions(),
             callback: ProgressCallback | None = None) -> PsoResult:
    """
    Minimise ``loss`` over the box [lower, upper] (D,) with PSO, eqs 26-27.

    ``loss`` maps positions (P, D) to losses (P,); non-finite losses count as +inf. All
    randomness comes from ``rng``, so the same seed gives the same result.
    """
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    if (lower.shape != upper.shape or lower.ndim != 1 or not np.all(np.isfinite(lower))
            or not np.all(np.isfinite(upper)) or np.any(upper < lower)):
        raise ValueError('lower and upper must be finite equal-length vectors, lower <= upper')
    span = upper - lower
    v_max = options.velocity_limit * span
    shape = (options.swarm_size, lower.size)

    x = lower + rng.random(shape) * span
    v = (2.0 * rng.random(shape) - 1.0) * 0.1 * span
    f = _evaluate(loss, x)
    p_best, p_loss = x.copy(), f.copy()
    g = int(np.argmin(p_loss))
    g_best, g_loss = p_best[g].copy(), float(p_loss[g])
    losses, positions = [g_loss], [g_best.copy()]
    if callback is not None:
        callback(0, g_loss, g_best.copy())

    stall = 0
    iteration = 0
    for iteration in range(1, options.max_iterations + 1):
        r1 = rng.random(shape)
        r2 = rng.random(shape)
        v = (options.inertia * v + options.cognitive * r1 * (p_best - x)
             + options.social * r2 * (g_best - x))                        # eq 26
        v = np.clip(v, -v_max, v_max)
        x = x + v                                                         # eq 27
        outside = (x < lower) | (x > upper)
        x = np.clip(x, lower, upper)
        v[outside] = 0.0
        f = _evaluate(loss, x)
        better = f < p_loss
        p_best[better], p_loss[better] = x[better], f[better]
        g = int(np.argmin(p_loss))
        previous = g_loss
        if p_loss[g] < g_loss:
            g_best, g_loss = p_best[g].copy(), float(p_loss[g])
        losses.append(g_loss)
        positions.append(g_best.copy())
        if callback is not None:
            callback(iteration, g_loss, g_best.copy())
        improved = previous - g_loss > options.stall_tolerance * max(abs(previous), 1e-300)
        stall = 0 if improved else stall + 1
        if stall >= options.stall_iterations:
            break
    return PsoResult(best_position=g_best, best_loss=g_loss, iterations=iteration,
                     loss_history=np.array(losses), position_history=np.array(positions),
                     stalled=stall >= options.stall_iterations)


def _evaluate(loss: SwarmLoss, x: np.ndarray) -> np.ndarray:
    f = np.asarray(loss(x), dtype=float).reshape(x.shape[0])
    return np.where(np.isfinite(f), f, np.inf)
