# SPDX-License-Identifier: Apache-2.0
"""
The one fitting core behind the ``retune_gait`` service and the ``retune_gait`` action.

A retune order (the wave and fit options of a request or goal) goes through the same steps,
whoever asked (paper section 4, eqs 23-27):

1. ``order_problem``: the order's values are valid (finite, in range);
2. ``feasibility.wave_infeasibility``: the tail can follow the wave at all;
3. the gait library, when asked (``use_library``): the same wave on the same geometry is
   answered from it without fitting (``gait_library``; the caller stores new fits with
   ``gait_of``);
4. ``tuning.fit_gait``, with a per-iteration callback that may stop the fit (cancel);
5. ``feasibility.fit_rejection``: the fit is good enough to run.

No rclpy here: the nodes translate messages to ``RetuneOrder`` and ``RetuneOutcome`` back.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
import math
import time

import numpy as np
from wirefish_cpg.gait_library import FitMode, Gait, GaitLibrary
from wirefish_cpg.oscillator import CpgParameters
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.geometry_parameters import BODY_WAVE_GEOMETRY_FIELDS
from wirefish_tuner.feasibility import fit_rejection, FitLimits, wave_infeasibility
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.tuning import fit_gait
from wirefish_tuner.wave_loss import (PAPER_UPPER, swarm_swing_rmse_deg, WaveFitProblem,
                                      WaveSpec)

MAX_SWARM_SIZE = 2000
MAX_ITERATIONS = 5000
# (iteration, best loss (m*s), swing-angle RMSE (2,) deg of the best so far); may raise
# FitCancelled to stop the fit before the next iteration.
RetuneProgress = Callable[[int, float, np.ndarray], None]


class FitCancelled(Exception):
    """Raised by a progress callback to stop a fit; nothing is returned or applied."""


@dataclass(frozen=True)
class RetuneOrder:
    """What a request or goal asks: the wave (eq 23) as given, the fit options (0 = default)."""

    c1: float
    c2: float
    k: float
    frequency_hz: float
    seed: int = 0
    max_iterations: int = 0
    swarm_size: int = 0
    use_library: bool = True
    mode: str = ''  # a FitMode's value; '' = phase_free

    def fit_mode(self) -> str:
        """Return the fit mode the order asks for (FitMode.PHASE_FREE when not given)."""
        return self.mode or FitMode.PHASE_FREE

    def wave_values(self) -> dict[str, float]:
        """Return the wave's four numbers by their message field names."""
        return {'c1': self.c1, 'c2': self.c2, 'k': self.k, 'frequency_hz': self.frequency_hz}


@dataclass(frozen=True)
class RetuneSettings:
    """The tuner's side of a fit: defaults, PSO weights, search box, geometry and limits."""

    geometry: FishGeometry = field(default_factory=FishGeometry)
    limits: FitLimits = field(default_factory=FitLimits)
    pso: PsoOptions = field(default_factory=PsoOptions)
    upper: tuple[float, ...] = tuple(PAPER_UPPER)
    alpha: float = 20.0
    samples_per_period: int = 48

    def geometry_fields(self) -> dict[str, float]:
        """Return the geometry values the fit depends on (the library's geometry key), m."""
        return {name: getattr(self.geometry, name) for name in BODY_WAVE_GEOMETRY_FIELDS}

    def options_for(self, order: RetuneOrder) -> PsoOptions:
        """Return the PSO options of an order: its counts where given, else the defaults."""
        base = self.pso
        return PsoOptions(swarm_size=order.swarm_size or base.swarm_size,
                          max_iterations=order.max_iterations or base.max_iterations,
                          inertia=base.inertia, cognitive=base.cognitive, social=base.social,
                          velocity_limit=base.velocity_limit,
                          stall_iterations=base.stall_iterations,
                          stall_tolerance=base.stall_tolerance)

    def problem_for(self, order: RetuneOrder) -> WaveFitProblem:
        """Return the fit problem of an order (raises ValueError if its wave is invalid)."""
        wave = WaveSpec(order.c1, order.c2, order.k, order.frequency_hz)
        return WaveFitProblem(wave=wave, geometry=self.geometry,
                              samples_per_period=self.samples_per_period)


@dataclass(frozen=True)
class RetuneOutcome:
    """
    The answer to an order.

    ``success`` is whether the gait may be run; ``message`` the human-readable outcome (the
    reason, starting with 'rejected:' or 'fit refused:', when not). ``params``, ``loss``
    (m*s), ``rmse_theta_deg`` (2,), ``iterations`` and ``elapsed_s`` are the fit's figures
    (None/0 when nothing was fitted); ``from_library`` when the gait was not fitted but found.
    """

    success: bool
    message: str
    params: CpgParameters | None = None
    loss: float = math.nan
    rmse_theta_deg: tuple[float, float] = (math.nan, math.nan)
    iterations: int = 0
    elapsed_s: float = 0.0
    from_library: bool = False

    def summary(self) -> str:
        """Return the figures in one phrase (loss, iterations, RMSE)."""
        return figures_phrase(self.loss, self.iterations, self.rmse_theta_deg)


def figures_phrase(loss: float, iterations: int, rmse_theta_deg: Sequence[float] | np.ndarray
                   ) -> str:
    """Return a fit's figures in one phrase: loss (m*s), iterations, swing-angle RMSE (deg)."""
    return (f'loss {loss:.6g} m*s after {iterations} iterations, RMSE theta '
            f'{rmse_theta_deg[0]:.3f}/{rmse_theta_deg[1]:.3f} deg')


def order_problem(order: RetuneOrder) -> str | None:
    """Return why an order's values are invalid (the service's documented rules), or None."""
    for name, value in order.wave_values().items():
        if not math.isfinite(value):
            return f'wave.{name} must be finite, got {value}'
    if not 0.0 < order.frequency_hz <= 10.0:
        return f'wave.frequency_hz must be in (0, 10] Hz, got {order.frequency_hz:g}'
    if order.k <= 0.0:
        return f'wave.k must be > 0, got {order.k:g}'
    if order.swarm_size != 0 and not 2 <= order.swarm_size <= MAX_SWARM_SIZE:
        return (f'swarm_size must be 0 (default) or in [2, {MAX_SWARM_SIZE}], '
                f'got {order.swarm_size}')
    if order.mode and order.mode not in tuple(FitMode):
        return f'mode must be empty or one of {", ".join(FitMode)}, got {order.mode!r}'
    if order.max_iterations != 0 and not 1 <= order.max_iterations <= MAX_ITERATIONS:
        return (f'max_iterations must be 0 (default) or in [1, {MAX_ITERATIONS}], '
                f'got {order.max_iterations}')
    return None


def retune(order: RetuneOrder, settings: RetuneSettings,
           progress: RetuneProgress | None = None, library: GaitLibrary | None = None
           ) -> RetuneOutcome:
    """
    Validate, judge feasible, look up or fit, and judge the fit of one order (steps 1-5).

    ``progress`` is called after the initial swarm and after every PSO iteration; a
    ``FitCancelled`` it raises propagates (the caller reports the cancel). The library is
    consulted only when ``order.use_library``; a gait found there is given the current alpha.
    """
    start = time.perf_counter()
    reason = order_problem(order)
    if reason is not None:
        return RetuneOutcome(False, f'rejected: {reason}')
    try:
        problem = settings.problem_for(order)
    except ValueError as error:
        return RetuneOutcome(False, f'rejected: {error}')
    reason = wave_infeasibility(problem, settings.limits)
    if reason is not None:
        return RetuneOutcome(False, f'rejected: {reason}')
    if order.use_library and library is not None:
        gait = library.find(problem.wave, settings.geometry_fields(), order.fit_mode())
        if gait is not None:
            return RetuneOutcome(
                True, f'from the gait library (fitted {gait.fitted_at}): '
                      f'{figures_phrase(gait.loss, 0, gait.rmse_theta_deg)}',
                params=replace(gait.params, alpha=settings.alpha), loss=gait.loss,
                rmse_theta_deg=gait.rmse_theta_deg, iterations=0,
                elapsed_s=time.perf_counter() - start, from_library=True)
    return fit_order(order, problem, settings, progress)


def gait_of(order: RetuneOrder, outcome: RetuneOutcome, settings: RetuneSettings) -> Gait:
    """Return the library entry of a successful fit of ``order``."""
    if not outcome.success or outcome.params is None:
        raise ValueError('only a successful fit is a gait')
    wave = settings.problem_for(order).wave
    return Gait(wave=wave, geometry=tuple(sorted(settings.geometry_fields().items())),
                params=outcome.params, loss=outcome.loss,
                rmse_theta_deg=outcome.rmse_theta_deg, mode=order.fit_mode())


def fit_order(order: RetuneOrder, problem: WaveFitProblem, settings: RetuneSettings,
              progress: RetuneProgress | None = None) -> RetuneOutcome:
    """Fit a feasible order's problem and judge the fit (steps 4 and 5)."""
    options = settings.options_for(order)
    upper = np.asarray(settings.upper, dtype=float)

    mode = order.fit_mode()

    def on_iteration(iteration: int, best_loss: float, best: np.ndarray) -> None:
        if progress is not None:
            progress(iteration, best_loss, swarm_swing_rmse_deg(
                best[None, :], problem, mode, alpha=settings.alpha)[0])

    start = time.perf_counter()
    fit = fit_gait(problem, np.random.default_rng(order.seed), options, -upper, upper,
                   alpha=settings.alpha, callback=on_iteration, mode=mode)
    rmse_1, rmse_2 = (float(v) for v in fit.rmse_theta_deg)  # (2,): theta1, theta2
    elapsed_s = time.perf_counter() - start

    def outcome(success: bool, message: str) -> RetuneOutcome:
        return RetuneOutcome(success, message, params=fit.params, loss=fit.loss,
                             rmse_theta_deg=(rmse_1, rmse_2), iterations=fit.iterations,
                             elapsed_s=elapsed_s)

    phrase = figures_phrase(fit.loss, fit.iterations, fit.rmse_theta_deg)
    reason = fit_rejection(fit.loss, fit.rmse_theta_deg, settings.limits)
    if reason is not None:
        return outcome(False, f'fit refused, not applied: {reason} ({phrase})')
    return outcome(True, f'fitted: {phrase}')
