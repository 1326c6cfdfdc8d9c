# SPDX-License-Identifier: Apache-2.0
"""
Whether the tail can follow a desired wave, and a fit is good enough to run (eqs 2-4, 23).

Two gates around the PSO fit, both pure:

* ``wave_infeasibility`` before fitting. The desired swing angles theta-bar_i of section 5.2
  (from eq 23) are inverted through the tail's geometry into the servo angles that would
  produce them exactly: link L1 is one circular arc, so theta_1 = beta_1 / 2; beta_2 is found
  by a dense search along link L2; eqs 3-4 (``servo_angles_for``) then give the servo angles.
  The wave is refused when those servo amplitudes exceed the servo range, when their peak rate
  exceeds the servo's rate limit, when a swing angle lies beyond what any bend can reach, when
  a flexible link would have to hold more than half a wavelength (each link bends as one
  constant-curvature arc, so k * max(l1, l2) <= pi), or when the beat is slower than a swimming
  fish's (``min_frequency_hz``).
* ``fit_rejection`` after fitting: a loss that is not finite, a loss that carries the
  inadmissible-frequency penalty, or a swing-angle RMSE above ``max_rmse_deg`` is refused.

Default limits and why:
``max_rmse_deg = 5``: about three times the paper's own fit (1.72 / 1.28 deg, section 5.2); a
reachable wave fits well inside it even in a short run (5 iterations of 40 particles: <= 3.5
deg), while waves at the edge of the servo range fit visibly wrong (twice the section 5.2
envelope: 6.5 deg, servo amplitudes > 1 rad). ``min_frequency_hz = 0.1``: a 10 s beat; slower
is holding still, and the coupling shift then drives the intrinsic frequency towards 0 (a
1e-300 Hz wave is "fitted" with v = 0.155 Hz at a locked frequency of 0). ``servo_range_rad =
pi/2``: the paper's amplitude bound (section 4.2), equal to cpg_node's default servo limit.
``servo_rate_limit_rad_s = 9.1``: the servo slew the virtual fish is calibrated with (the
paper's 3 Hz cap).
"""

from __future__ import annotations

from dataclasses import dataclass
import functools
import math

import numpy as np
from wirefish_kinematics.body_wave import swing_angles
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.wire_coupling import servo_angles_for
from wirefish_tuner.wave_loss import desired_swing_angles, FREQUENCY_PENALTY, WaveFitProblem

# Bends searched for beta_2 (rad) and the residual above which a swing angle counts as
# unreachable: 0.05 deg (Newton's steps land within ~1e-9 rad of a reachable angle).
_BEND_SEARCH = np.linspace(-math.pi, math.pi, 73)  # 5 deg: the start of Newton's steps
_NEWTON_STEPS = 6
_SLOPE_STEP = 1e-6
_REACH_TOLERANCE_RAD = math.radians(0.05)


@dataclass(frozen=True)
class FitLimits:
    """What the tail and its servos can do, and how well a fit must follow the wave."""

    servo_range_rad: float = math.pi / 2
    servo_rate_limit_rad_s: float = 9.1
    min_frequency_hz: float = 0.1
    max_rmse_deg: float = 5.0

    def __post_init__(self) -> None:
        for name in ('servo_range_rad', 'servo_rate_limit_rad_s', 'min_frequency_hz',
                     'max_rmse_deg'):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value > 0.0 and not math.isnan(value)):
                raise ValueError(f'{name} must be > 0, got {value!r}')


@dataclass(frozen=True)
class WaveDemand:
    """
    What a wave asks of the servos over one period.

    ``servo_angles`` (N, 2) rad at ``problem.times()``, NaN where a swing angle is beyond
    reach; ``amplitude_rad`` (2,) and ``peak_rate_rad_s`` (2,) their peaks; ``reachable``
    whether every sample could be inverted.
    """

    servo_angles: np.ndarray
    amplitude_rad: np.ndarray
    peak_rate_rad_s: np.ndarray
    reachable: bool
    worst_swing_deg: np.ndarray


def bends_for_swing_angles(theta: np.ndarray, geometry: FishGeometry
                           ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the bends (beta1, beta2) (N,) rad giving swing angles theta (N, 2) (section 5.2).

    theta_1 = beta_1 / 2 (chord of a circular arc); beta_2 starts at the best of a coarse grid
    of bends in [-pi, pi] and is refined by Newton's method on theta_2. Where no bend reaches
    theta_2 within 0.05 deg, beta_2 is NaN.
    """
    beta1 = 2.0 * np.asarray(theta[:, 0], dtype=float)
    # A coarse search over every bend for the start, then Newton steps on theta_2(beta_2).
    beta2, _ = _closest_bend(beta1, theta[:, 1], np.broadcast_to(
        _BEND_SEARCH, (beta1.size, _BEND_SEARCH.size)), geometry)
    for _ in range(_NEWTON_STEPS):
        miss = _theta2(beta1, beta2, geometry) - theta[:, 1]
        slope = (_theta2(beta1, beta2 + _SLOPE_STEP, geometry)
                 - _theta2(beta1, beta2 - _SLOPE_STEP, geometry)) / (2.0 * _SLOPE_STEP)
        with np.errstate(divide='ignore', invalid='ignore'):
            step = np.where(np.abs(slope) > 1e-9, miss / slope, 0.0)
        beta2 = np.clip(beta2 - step, -math.pi, math.pi)
    error = np.abs(_theta2(beta1, beta2, geometry) - theta[:, 1])
    reached = error <= _REACH_TOLERANCE_RAD
    reached &= np.abs(beta1) <= math.pi
    return beta1, np.where(reached, beta2, np.nan)


def _theta2(beta1: np.ndarray, beta2: np.ndarray, geometry: FishGeometry) -> np.ndarray:
    return swing_angles(beta1, beta2, geometry)[1]


def _closest_bend(beta1: np.ndarray, theta2: np.ndarray, candidates: np.ndarray,
                  geometry: FishGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Return, per row, the candidate beta_2 (N, M) whose theta_2 is closest, and the miss."""
    _, reached = swing_angles(np.broadcast_to(beta1[:, None], candidates.shape), candidates,
                              geometry)
    misses = np.abs(reached - theta2[:, None])
    best = np.argmin(misses, axis=1)
    rows = np.arange(best.size)
    return candidates[rows, best], misses[rows, best]


def wave_demand(problem: WaveFitProblem) -> WaveDemand:
    """Return the servo angles, amplitudes and peak rates that ``problem``'s wave asks for."""
    theta = desired_swing_angles(problem)
    beta1, beta2 = bends_for_swing_angles(theta, problem.geometry)
    servo = np.stack(servo_angles_for(beta1, beta2, problem.geometry), axis=-1)
    reachable = bool(np.all(np.isfinite(servo)))
    dt = 1.0 / (problem.samples_per_period * problem.wave.frequency_hz)
    # Central difference over the periodic samples: the rate the servos would have to run at.
    rate = (np.roll(servo, -1, axis=0) - np.roll(servo, 1, axis=0)) / (2.0 * dt)
    worst = np.degrees(np.abs(theta).max(axis=0))
    return WaveDemand(servo_angles=servo, amplitude_rad=np.abs(servo).max(axis=0),
                      peak_rate_rad_s=np.abs(rate).max(axis=0), reachable=reachable,
                      worst_swing_deg=worst)


@functools.lru_cache(maxsize=256)
def wave_infeasibility(problem: WaveFitProblem, limits: FitLimits = FitLimits()
                       ) -> str | None:
    """
    Return why the tail cannot follow ``problem``'s wave (eqs 2-4, 23), or None if it can.

    The reason names what the wave asks for against what the geometry and servos reach.
    Pure and deterministic, so the answers of recent (frozen, hashable) arguments are kept:
    a wave asked again, e.g. one the gait library answers, is judged in microseconds.
    """
    wave, geometry = problem.wave, problem.geometry
    if wave.frequency_hz < limits.min_frequency_hz:
        return (f'wave.frequency_hz {wave.frequency_hz:g} Hz is below the slowest beat, '
                f'{limits.min_frequency_hz:g} Hz (min_frequency_hz)')
    longest = max(geometry.l1, geometry.l2)
    if wave.k * longest > math.pi:
        return (f'wave.k {wave.k:g} rad/m puts {wave.k * longest / math.pi:.3g} half '
                f'wavelengths on a {longest:g} m link, which bends as one arc: k must be '
                f'<= pi / {longest:g} = {math.pi / longest:.4g} rad/m')
    with np.errstate(all='ignore'):  # absurd envelopes overflow to inf: judged below
        demand = wave_demand(problem)
    if not demand.reachable:
        return (f'the wave asks for swing angles up to {demand.worst_swing_deg[0]:.3g}/'
                f'{demand.worst_swing_deg[1]:.3g} deg, beyond any bend of the tail')
    amplitude = demand.amplitude_rad
    if np.any(amplitude > limits.servo_range_rad):
        return (f'the wave asks for servo amplitudes {amplitude[0]:.3g}/{amplitude[1]:.3g} '
                f'rad; the servo range is +-{limits.servo_range_rad:.4g} rad')
    rate = demand.peak_rate_rad_s
    if np.any(rate > limits.servo_rate_limit_rad_s):
        return (f'the wave asks for servo rates up to {rate[0]:.3g}/{rate[1]:.3g} rad/s; '
                f'the servos reach {limits.servo_rate_limit_rad_s:.4g} rad/s')
    return None


def fit_rejection(loss: float, rmse_theta_deg: np.ndarray, limits: FitLimits = FitLimits()
                  ) -> str | None:
    """Return why a fit (loss of eq 24, m*s; RMSE (2,) deg) must not be used, or None."""
    rmse = np.asarray(rmse_theta_deg, dtype=float)
    if not math.isfinite(loss):
        return f'the fit loss is not finite ({loss})'
    if loss >= FREQUENCY_PENALTY:
        return (f'the fit loss {loss:.6g} m*s carries the penalty of a CPG frequency outside '
                '(0, 10] Hz')
    if not np.all(np.isfinite(rmse)) or np.any(rmse > limits.max_rmse_deg):
        return (f'the fit misses the wave: RMSE theta {rmse[0]:.3f}/{rmse[1]:.3f} deg exceeds '
                f'{limits.max_rmse_deg:g} deg (max_rmse_deg)')
    return None
