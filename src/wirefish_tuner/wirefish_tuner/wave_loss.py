# SPDX-License-Identifier: Apache-2.0
"""
The point-optimisation loss of paper eqs 24-25, evaluated exactly on the locked steady state.

The six tuned values form a position vector ``(w12, w21, phi12, phi21, R1, R2)`` (the order of
Fig 6(b)); a swarm is an array (P, 6). For each particle the stable phase difference and the
locked frequency come in closed form (``steady_state``), so the outputs over the stabilised
window [t_s, t_o] are known without integrating eq 1. Two decisions make the loss well posed:

* Frequency. Coupling shifts the locked frequency away from 2 pi v (eq 1). The tuner therefore
  chooses v so that the locked frequency equals the wave's (``intrinsic_frequency_for``; the
  paper says v "can be determined by swing period T"). The loss is then a function of the
  waveform only, and any window of whole periods gives the same loss per period. Particles whose
  required v falls outside (0, ``max_frequency_hz``] are penalised.
* Absolute phase. The CPG's phase after start-up is arbitrary, so the desired wave is referenced
  to oscillator 1: oscillator 1's phase is set to the phase of the desired wave's fundamental at
  q1 (shifted by pi when R1 < 0). y(q1) is an odd, increasing function of Theta_1 alone (eqs 3,
  7), so this is the best alignment for q1; the optimiser only places q2 through Delta* and R2.

The window is ``window_periods`` whole periods of the desired wave (default 1), sampled at
``samples_per_period`` instants; the rectangle rule is the natural quadrature of a periodic
integrand. The loss is in m*s.

Two fit modes (``FitMode``). ``'phase_free'`` (the default, above) is the engineering problem:
the robot's phase is arbitrary and v is whatever locks the network to the wave. ``'literal'`` is
the paper's own problem (sections 4.1 and 5.2): v = omega / 2 pi (the wave's frequency), eq 1
started from rest with alpha = 20 (``from_rest``, exact), the same clock t in y_body and in the
CPG, and eq 24 integrated over [t_s, t_o] = [``window_start_s``, ``window_end_s``] by the
trapezoid rule (the integrand is not periodic: a network locked off the wave's frequency
drifts). Default window [20 s, 25 s]: from rest, Table 1's phase difference is still 0.17 rad
from its lock at 5 s and within 3e-4 rad of it at 20 s (lock rate C = 0.43 1/s); five periods
show a 0.01 Hz frequency error as 0.3 rad of drift.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import enum
import math

import numpy as np
from wirefish_cpg.from_rest import outputs_from_rest
from wirefish_cpg.gait_library import FitMode
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import intrinsic_frequency_for, stable_phase_difference
from wirefish_kinematics.body_wave import body_positions, swing_angles
from wirefish_kinematics.desired_wave import (desired_lateral_position,
                                              desired_swing_angles as wave_swing_angles,
                                              WAVE_TIME_SIGN)
from wirefish_kinematics.geometry import FishGeometry
# The one wave type (eq 23), also this module's: callers name it with the loss it defines.
from wirefish_kinematics.wave_spec import WaveSpec as WaveSpec
from wirefish_kinematics.wire_coupling import bend_angles

PARAMETER_NAMES = ('w12', 'w21', 'phi12', 'phi21', 'amplitude_1', 'amplitude_2')
# Paper section 4.2: w_ij in [-10, 10], phi_ij in [-pi, pi] rad, R_i in [-pi/2, pi/2] rad.
PAPER_LOWER = np.array([-10.0, -10.0, -np.pi, -np.pi, -np.pi / 2, -np.pi / 2])
PAPER_UPPER = -PAPER_LOWER
# Loss added (m*s) when the locked frequency cannot be reached with an admissible v: far above
# any real fit (a perfect miss of the section 5.2 wave costs about 0.08 m*s per period).
FREQUENCY_PENALTY = 10.0


class ThetaBar(enum.StrEnum):
    """
    Where the expected swing angle theta-bar_i of section 5.2 puts the wave (unstated there).

    AXIAL: at x = q_i (atan2(y_body, q_i), the project's); CHORD: at distance q_i from O0
    (x = sqrt(q_i^2 - y_body^2), i.e. asin(y_body / q_i)).
    """

    AXIAL = 'axial'
    CHORD = 'chord'


@dataclass(frozen=True)
class WaveFitProblem:
    """
    Everything the loss needs besides the swarm: the wave, the fish, and the quadrature.

    ``reverse_wave`` flips the sign of omega t in eq 23, i.e. the wave travels the other way
    than the project's convention (used only to compare the two readings of eq 23).
    """

    wave: WaveSpec = field(default_factory=WaveSpec)
    geometry: FishGeometry = field(default_factory=FishGeometry)
    samples_per_period: int = 48
    window_periods: int = 1
    max_frequency_hz: float = 10.0
    reverse_wave: bool = False
    window_start_s: float = 20.0  # t_s of eq 24 in the literal mode (module docstring)
    window_end_s: float = 25.0  # t_o

    def __post_init__(self) -> None:
        """Check the literal window: 0 <= t_s < t_o <= t_s + 1000 s (ValueError)."""
        start, end = float(self.window_start_s), float(self.window_end_s)
        if not (math.isfinite(start) and math.isfinite(end) and 0.0 <= start < end
                and end - start <= 1000.0):
            raise ValueError(f'window [{start}, {end}] s must satisfy 0 <= t_s < t_o '
                             '<= t_s + 1000 s')

    def stations(self) -> np.ndarray:
        """Return q1 = l1 and q2 = l1 + l2 (m), the link ends O1 and O2 of eq 25, (2,)."""
        return np.array(self.geometry.link_end_stations)

    def times(self) -> np.ndarray:
        """Return the sample instants of one period, (N,) s, starting at 0."""
        n = self.samples_per_period
        return np.arange(n) / (n * self.wave.frequency_hz)

    def time_sign(self) -> float:
        """Return the sign of omega t in eq 23 used here (the project's, or the reverse)."""
        return -WAVE_TIME_SIGN if self.reverse_wave else WAVE_TIME_SIGN

    def desired(self, times: np.ndarray | None = None) -> np.ndarray:
        """Return y_body(q_i, t_n) of eq 23 at the stations, (N, 2) m (default: ``times()``)."""
        w = self.wave
        times = self.times() if times is None else times
        return np.asarray(desired_lateral_position(
            self.stations()[None, :], times[:, None], w.c1, w.c2, w.k, w.frequency_hz,
            time_sign=self.time_sign()))

    def window_times(self) -> np.ndarray:
        """Return the literal mode's instants on [t_s, t_o], both ends, (N,) s."""
        span = self.window_end_s - self.window_start_s
        count = max(int(round(self.samples_per_period * self.wave.frequency_hz * span)), 2)
        return np.linspace(self.window_start_s, self.window_end_s, count + 1)


@dataclass(frozen=True)
class SwarmWaveforms:
    """Locked outputs of a swarm: angles (P, N, 2) rad, Delta* (P,) rad, v (P,) Hz."""

    angles: np.ndarray
    delta: np.ndarray
    intrinsic_hz: np.ndarray


def swarm_waveforms(positions: np.ndarray, problem: WaveFitProblem,
                    desired: np.ndarray | None = None) -> SwarmWaveforms:
    """
    Return the steady-state servo angles of every particle over one period (eq 1 locked).

    ``positions`` (P, 6) in ``PARAMETER_NAMES`` order; the phase is referenced to oscillator 1
    as described in the module docstring; offsets are 0 (paper section 4.1, straight motion).
    """
    w12, w21, phi12, phi21, r1, r2 = np.moveaxis(np.atleast_2d(positions), -1, 0)
    delta = stable_phase_difference(r1, r2, w12, w21, phi12, phi21)
    intrinsic = intrinsic_frequency_for(problem.wave.frequency_hz, r2, w12, phi12, delta)
    omega_t = 2.0 * np.pi * problem.wave.frequency_hz * problem.times()
    phase1 = oscillator1_phase(problem, desired) + np.where(r1 < 0.0, np.pi, 0.0)
    xi1 = omega_t[None, :] + phase1[:, None]
    angles = np.stack([r1[:, None] * np.cos(xi1),
                       r2[:, None] * np.cos(xi1 + delta[:, None])], axis=-1)
    return SwarmWaveforms(angles=angles, delta=delta, intrinsic_hz=intrinsic)


def oscillator1_phase(problem: WaveFitProblem, desired: np.ndarray | None = None) -> float:
    """
    Return the phase (rad) oscillator 1 is given at t = 0 when R_1 > 0.

    It is the phase of the fundamental of y_body(q1, t), so that
    Theta_1 = R_1 cos(omega t + phase) peaks together with the desired wave at q1.
    """
    desired = problem.desired() if desired is None else desired
    omega_t = 2.0 * np.pi * problem.wave.frequency_hz * problem.times()
    return float(np.angle(np.sum(desired[:, 0] * np.exp(-1j * omega_t))))


def lateral_positions(angles: np.ndarray, problem: WaveFitProblem) -> np.ndarray:
    """Return y(q_i, t) at the two link ends from servo angles (..., 2) (eqs 3-4, 7-11), m."""
    beta1, beta2 = bend_angles(angles[..., 0], angles[..., 1], problem.geometry)
    _, y = body_positions(problem.stations(), beta1, beta2, problem.geometry)
    return np.asarray(y)


def waveform_loss(angles: np.ndarray, problem: WaveFitProblem,
                  desired: np.ndarray | None = None) -> np.ndarray:
    """
    Return eq 24's integral of eq 25's error for servo angles (P, N, 2) over one period, (P,).

    e(t) = sum_i |y_body(q_i, t) - y(q_i, t)| at the sample instants ``problem.times()``,
    integrated by the rectangle rule over ``window_periods`` periods, m*s.
    """
    desired = problem.desired() if desired is None else desired
    error = np.abs(desired[None] - lateral_positions(angles, problem)).sum(axis=-1)
    period = 1.0 / problem.wave.frequency_hz
    loss: np.ndarray = error.mean(axis=-1) * period * problem.window_periods
    return loss


def body_wave_loss(positions: np.ndarray, problem: WaveFitProblem) -> np.ndarray:
    """
    Return the loss of eqs 24-25 for every particle (P, 6) on its locked steady state, (P,).

    Adds ``FREQUENCY_PENALTY`` where no admissible v locks the network to the wave.
    """
    desired = problem.desired()
    forms = swarm_waveforms(positions, problem, desired)
    loss = waveform_loss(forms.angles, problem, desired)
    return np.where(admissible_frequency(forms.intrinsic_hz, problem), loss,
                    loss + FREQUENCY_PENALTY)


def admissible_frequency(intrinsic_hz: np.ndarray, problem: WaveFitProblem) -> np.ndarray:
    """Return whether the intrinsic frequencies (Hz) are in (0, max_frequency_hz], bool."""
    return (intrinsic_hz > 0.0) & (intrinsic_hz <= problem.max_frequency_hz)


def desired_swing_angles(problem: WaveFitProblem, theta_bar: str = ThetaBar.AXIAL,
                         times: np.ndarray | None = None) -> np.ndarray:
    """
    Return the expected swing angles theta-bar_i (N, 2) rad of section 5.2, from eq 23.

    'axial': theta-bar_i = atan2(y_body(q_i, t), q_i) (``wirefish_kinematics.desired_wave``);
    'chord': asin(y_body / q_i) (``ThetaBar``). Default times: ``times()``.
    """
    w = problem.wave
    times = problem.times() if times is None else times
    if theta_bar == ThetaBar.AXIAL:
        return np.stack(wave_swing_angles(times, w.c1, w.c2, w.k, w.frequency_hz,
                                          problem.geometry, time_sign=problem.time_sign()),
                        axis=-1)
    if theta_bar == ThetaBar.CHORD:
        ratio = problem.desired(times) / problem.stations()[None, :]
        chord: np.ndarray = np.arcsin(np.clip(ratio, -1.0, 1.0))
        return chord
    raise ValueError(f'theta_bar must be one of {tuple(d.value for d in ThetaBar)}, '
                     f'got {theta_bar!r}')


def swing_angle_rmse_deg(positions: np.ndarray, problem: WaveFitProblem,
                         theta_bar: str = ThetaBar.AXIAL) -> np.ndarray:
    """Return the RMSE of theta_1, theta_2 against theta-bar over one period, (P, 2) degrees."""
    return waveform_swing_rmse_deg(swarm_waveforms(positions, problem).angles, problem,
                                   theta_bar)


def waveform_swing_rmse_deg(angles: np.ndarray, problem: WaveFitProblem,
                            theta_bar: str = ThetaBar.AXIAL) -> np.ndarray:
    """Return the swing-angle RMSE (P, 2) degrees of servo angles (P, N, 2) (section 5.2)."""
    error = _swing_angles_of(angles, problem) - desired_swing_angles(problem, theta_bar)[None]
    rmse: np.ndarray = np.degrees(np.sqrt(np.mean(error ** 2, axis=-2)))
    return rmse


def _swing_angles_of(angles: np.ndarray, problem: WaveFitProblem) -> np.ndarray:
    """Return theta_1, theta_2 (..., 2) rad of servo angles (..., 2) (eqs 3-15, section 5.2)."""
    beta1, beta2 = bend_angles(angles[..., 0], angles[..., 1], problem.geometry)
    return np.stack(swing_angles(beta1, beta2, problem.geometry), axis=-1)


def literal_waveforms(positions: np.ndarray, problem: WaveFitProblem, alpha: float = 20.0
                      ) -> np.ndarray:
    """
    Return the servo angles (P, N, 2) rad on ``window_times()`` of the literal mode.

    eq 1 from rest (``from_rest``) with v = the wave's frequency, alpha, b = 0; t is the same
    clock as eq 23's (module docstring).
    """
    w12, w21, phi12, phi21, r1, r2 = (v[:, None] for v in
                                      np.moveaxis(np.atleast_2d(positions), -1, 0))
    return outputs_from_rest(problem.window_times()[None, :], problem.wave.frequency_hz,
                             r1, r2, w12, w21, phi12, phi21, alpha)


def literal_waveform_loss(angles: np.ndarray, problem: WaveFitProblem) -> np.ndarray:
    """
    Return eq 24 over [t_s, t_o] (m*s) for servo angles (P, N, 2) on ``window_times()``, (P,).

    e(t) of eq 25 against y_body at the same instants; trapezoid rule.
    """
    times = problem.window_times()
    error = np.abs(problem.desired(times)[None] - lateral_positions(angles, problem))
    return _trapezoid(error.sum(axis=-1), times)


def literal_body_wave_loss(positions: np.ndarray, problem: WaveFitProblem,
                           alpha: float = 20.0) -> np.ndarray:
    """Return the paper-literal loss of eqs 24-25 (m*s) of every particle (P, 6), (P,)."""
    return literal_waveform_loss(literal_waveforms(positions, problem, alpha), problem)


def literal_swing_rmse_deg(positions: np.ndarray, problem: WaveFitProblem,
                           theta_bar: str = ThetaBar.AXIAL, alpha: float = 20.0) -> np.ndarray:
    """Return the theta_1, theta_2 RMSE (P, 2) degrees over [t_s, t_o] in the literal mode."""
    return literal_waveform_swing_rmse_deg(literal_waveforms(positions, problem, alpha),
                                           problem, theta_bar)


def literal_waveform_swing_rmse_deg(angles: np.ndarray, problem: WaveFitProblem,
                                    theta_bar: str = ThetaBar.AXIAL) -> np.ndarray:
    """Return the swing RMSE (P, 2) degrees of servo angles (P, N, 2) on ``window_times()``."""
    times = problem.window_times()
    expected = desired_swing_angles(problem, theta_bar, times)
    error = _swing_angles_of(angles, problem) - expected[None]
    mean_square = _trapezoid(np.moveaxis(error ** 2, -2, -1), times) / (times[-1] - times[0])
    rmse: np.ndarray = np.degrees(np.sqrt(mean_square))
    return rmse


def _trapezoid(values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Return the trapezoid rule over the last axis of ``values`` sampled at ``times``."""
    step = np.diff(times)
    integral: np.ndarray = np.sum(0.5 * (values[..., 1:] + values[..., :-1]) * step, axis=-1)
    return integral


def check_mode(mode: str) -> FitMode:
    """Return ``mode`` as a ``FitMode``; raise ``ValueError`` if it is none."""
    try:
        return FitMode(mode)
    except ValueError:
        raise ValueError(f'mode must be one of {tuple(m.value for m in FitMode)}, '
                         f'got {mode!r}') from None


def swarm_loss(positions: np.ndarray, problem: WaveFitProblem, mode: str = FitMode.PHASE_FREE,
               alpha: float = 20.0) -> np.ndarray:
    """Return the loss (P,) m*s of every particle (P, 6) in fit ``mode`` (``FitMode``)."""
    if check_mode(mode) == FitMode.LITERAL:
        return literal_body_wave_loss(positions, problem, alpha)
    return body_wave_loss(positions, problem)


def swarm_swing_rmse_deg(positions: np.ndarray, problem: WaveFitProblem,
                         mode: str = FitMode.PHASE_FREE, theta_bar: str = ThetaBar.AXIAL,
                         alpha: float = 20.0) -> np.ndarray:
    """Return the swing-angle RMSE (P, 2) degrees of every particle in fit ``mode``."""
    if check_mode(mode) == FitMode.LITERAL:
        return literal_swing_rmse_deg(positions, problem, theta_bar, alpha)
    return swing_angle_rmse_deg(positions, problem, theta_bar)


def position_of(params: CpgParameters) -> np.ndarray:
    """Return the six tuned values of ``params`` as a position (6,)."""
    return np.array([params.w12, params.w21, params.phi12, params.phi21, *params.amplitude])


def parameters_at(position: np.ndarray, problem: WaveFitProblem, alpha: float = 20.0,
                  offset: tuple[float, float] = (0.0, 0.0),
                  mode: str = FitMode.PHASE_FREE) -> CpgParameters:
    """
    Return the CPG parameters of a position in fit ``mode``.

    'phase_free': v chosen to lock to the wave's frequency; 'literal': v = the wave's frequency.
    """
    if check_mode(mode) == FitMode.LITERAL:
        frequency = problem.wave.frequency_hz
    else:
        frequency = float(swarm_waveforms(np.asarray(position)[None, :],
                                          problem).intrinsic_hz[0])
    w12, w21, phi12, phi21, r1, r2 = (float(v) for v in position)
    return CpgParameters(frequency_hz=frequency, amplitude=(r1, r2),
                         offset=offset, w12=w12, w21=w21, phi12=phi12, phi21=phi21,
                         alpha=alpha)
