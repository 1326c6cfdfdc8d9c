# SPDX-License-Identifier: Apache-2.0
"""Fit the CPG to a desired body wave: PSO (eqs 26-27) on the exact loss of eqs 24-25."""

from __future__ import annotations

from dataclasses import dataclass
import time

import numpy as np
from wirefish_cpg.gait_library import FitMode
from wirefish_cpg.oscillator import CpgParameters
from wirefish_tuner.pso import minimise, ProgressCallback, PsoOptions, PsoResult
from wirefish_tuner.wave_loss import (check_mode, PAPER_LOWER, PAPER_UPPER, parameters_at,
                                      swarm_loss, swarm_swing_rmse_deg, WaveFitProblem)


@dataclass(frozen=True)
class FitResult:
    """
    A fitted gait and how it was found.

    The CPG parameters (v locked to the wave), loss (m*s), swing-angle RMSE (2,) degrees,
    PSO iterations, wall time (s) and the optimiser's full history.
    """

    params: CpgParameters
    loss: float
    rmse_theta_deg: np.ndarray
    iterations: int
    elapsed_s: float
    pso: PsoResult


def fit_gait(problem: WaveFitProblem, rng: np.random.Generator,
             options: PsoOptions = PsoOptions(), lower: np.ndarray = PAPER_LOWER,
             upper: np.ndarray = PAPER_UPPER, alpha: float = 20.0,
             callback: ProgressCallback | None = None, mode: str = FitMode.PHASE_FREE
             ) -> FitResult:
    """
    Return the CPG parameters whose output best follows ``problem``'s wave.

    Searches (w12, w21, phi12, phi21, R1, R2) in [lower, upper] (6,) (default: the paper's
    bounds) with alpha fixed and offsets 0, as in paper section 4.1. ``mode`` (a
    ``FitMode``): 'phase_free' scores the locked output with v chosen to lock at the wave's
    frequency; 'literal' is the paper's problem (v = the wave's frequency, eq 1 from rest,
    eq 24 over [t_s, t_o]). Raises ``ValueError`` for an unknown mode.
    """
    check_mode(mode)
    start = time.perf_counter()
    result = minimise(lambda x: swarm_loss(x, problem, mode, alpha), lower, upper, rng,
                      options, callback)
    elapsed = time.perf_counter() - start
    best = result.best_position
    return FitResult(params=parameters_at(best, problem, alpha=alpha, mode=mode),
                     loss=float(result.best_loss),
                     rmse_theta_deg=swarm_swing_rmse_deg(best[None, :], problem, mode,
                                                         alpha=alpha)[0],
                     iterations=result.iterations, elapsed_s=elapsed, pso=result)
