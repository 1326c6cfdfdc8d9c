# SPDX-License-Identifier: Apache-2.0
"""
Ijspeert's coupled phase oscillators (paper eq 1), integrated with a fixed-step RK4.

Per oscillator i the state is the phase xi_i, the amplitude r_i and its rate, and the offset
b_i and its rate::

    d xi_i / dt = 2 pi v_i + sum_j r_j w_ij sin(xi_j - xi_i - phi_ij)
    r_i''      = alpha (alpha / 4 (R_i - r_i) - r_i')
    b_i''      = alpha (alpha / 4 (B_i - b_i) - b_i')      (offset: same law as r, see below)
    Theta_i    = r_i cos(xi_i) + b_i

The paper sets the offset b_i directly; here it converges to its target B_i by the same
critically damped law as the amplitude, so a turning command is as smooth as a change of
amplitude. The state persists across parameter changes, so no change produces a step in the
output angle or its rate (only its second derivative jumps).

Everything is vectorised: arrays of shape (..., N) hold one network per leading index, so the
same code integrates one network or a whole PSO swarm (``NetworkArrays`` with shape (P, N)).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import math

import numpy as np

# Layout of the state array (..., 5, N): one row per state variable.
PHASE, AMPLITUDE, AMPLITUDE_RATE, OFFSET, OFFSET_RATE = range(5)
STATE_ROWS = 5
NUM_SERVOS = 2


def _finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f'{name} must be finite, got {value}')
    return value


@dataclass(frozen=True)
class CpgParameters:
    """
    Parameters of the fish's two-oscillator network (eq 1); SI units and radians.

    ``amplitude`` = (R_1, R_2) rad, ``offset`` = (B_1, B_2) rad (targets of r_i and b_i),
    ``w12``/``w21`` the coupling weights omega_12 (of oscillator 2 on 1) and omega_21 (1/s),
    ``phi12``/``phi21`` the phase biases (rad), ``alpha`` the convergence gain (1/s), and
    ``frequency_hz`` the intrinsic frequency v shared by both oscillators (Hz). Defaults are
    Table 1 of the paper with v = 1 Hz, alpha = 20, b = 0. Raises ``ValueError`` if invalid.
    """

    frequency_hz: float = 1.0
    amplitude: tuple[float, float] = (0.38, 0.47)
    offset: tuple[float, float] = (0.0, 0.0)
    w12: float = -0.41
    w21: float = 0.64
    phi12: float = 1.76
    phi21: float = 1.06
    alpha: float = 20.0

    def __post_init__(self) -> None:
        for name in ('frequency_hz', 'w12', 'w21', 'phi12', 'phi21', 'alpha'):
            object.__setattr__(self, name, _finite(name, getattr(self, name)))
        for name in ('amplitude', 'offset'):
            values = tuple(_finite(name, v) for v in np.ravel(getattr(self, name)))
            if len(values) != NUM_SERVOS:
                raise ValueError(f'{name} needs {NUM_SERVOS} values, got {len(values)}')
            object.__setattr__(self, name, values)
        if self.frequency_hz <= 0.0:
            raise ValueError(f'frequency_hz must be > 0, got {self.frequency_hz}')
        if self.alpha <= 0.0:
            raise ValueError(f'alpha must be > 0, got {self.alpha}')

    def coupling_weights(self) -> np.ndarray:
        """Return W (2, 2) with W[i, j] = omega_ij (1/s) and a zero diagonal."""
        return np.array([[0.0, self.w12], [self.w21, 0.0]])

    def phase_biases(self) -> np.ndarray:
        """Return Phi (2, 2) with Phi[i, j] = phi_ij (rad) and a zero diagonal."""
        return np.array([[0.0, self.phi12], [self.phi21, 0.0]])


def at_rest(params: CpgParameters) -> CpgParameters:
    """Return ``params`` with amplitude and offset targets 0: what eq 1 converges to on stop."""
    return replace(params, amplitude=(0.0, 0.0), offset=(0.0, 0.0))


@dataclass(frozen=True)
class NetworkArrays:
    """
    Eq 1's parameters as arrays for vectorised integration of many networks at once.

    Shapes: ``frequency_hz``, ``amplitude``, ``offset``, ``alpha`` (..., N);
    ``weights`` and ``biases`` (..., N, N) with [i, j] the influence of j on i.
    """

    frequency_hz: np.ndarray
    amplitude: np.ndarray
    offset: np.ndarray
    weights: np.ndarray
    biases: np.ndarray
    alpha: np.ndarray = field(default_factory=lambda: np.array(20.0))

    @classmethod
    def from_parameters(cls, params: CpgParameters) -> NetworkArrays:
        """Return the arrays (shape (2,) and (2, 2)) of one fish network."""
        return cls(frequency_hz=np.full(NUM_SERVOS, params.frequency_hz),
                   amplitude=np.asarray(params.amplitude),
                   offset=np.asarray(params.offset),
                   weights=params.coupling_weights(),
                   biases=params.phase_biases(),
                   alpha=np.full(NUM_SERVOS, params.alpha))

    @classmethod
    def stack(cls, params: list[CpgParameters]) -> NetworkArrays:
        """Return the arrays of P fish networks, shapes (P, 2) and (P, 2, 2)."""
        singles = [cls.from_parameters(p) for p in params]
        return cls(**{name: np.stack([getattr(s, name) for s in singles])
                      for name in ('frequency_hz', 'amplitude', 'offset', 'weights',
                                   'biases', 'alpha')})


def initial_state(shape: tuple[int, ...] = (), oscillators: int = NUM_SERVOS) -> np.ndarray:
    """Return the state at rest (all phases, amplitudes, offsets and rates 0), (*shape, 5, N)."""
    return np.zeros(shape + (STATE_ROWS, oscillators))


def eq1_derivative(state: np.ndarray, net: NetworkArrays) -> np.ndarray:
    """
    Return d(state)/dt of the oscillator network, eq 1 (plus the offset law), (..., 5, N).

    ``state`` (..., 5, N) rows: phase (rad), amplitude (rad), amplitude rate (rad/s),
    offset (rad), offset rate (rad/s).
    """
    xi = state[..., PHASE, :]
    r = state[..., AMPLITUDE, :]
    alpha = net.alpha
    # sin(xi_j - xi_i - phi_ij): rows i, columns j.
    pair = np.sin(xi[..., None, :] - xi[..., :, None] - net.biases)
    d = np.empty_like(state)
    d[..., PHASE, :] = 2.0 * np.pi * net.frequency_hz + np.sum(
        net.weights * r[..., None, :] * pair, axis=-1)
    d[..., AMPLITUDE, :] = state[..., AMPLITUDE_RATE, :]
    d[..., AMPLITUDE_RATE, :] = alpha * (
        0.25 * alpha * (net.amplitude - r) - state[..., AMPLITUDE_RATE, :])
    d[..., OFFSET, :] = state[..., OFFSET_RATE, :]
    d[..., OFFSET_RATE, :] = alpha * (
        0.25 * alpha * (net.offset - state[..., OFFSET, :]) - state[..., OFFSET_RATE, :])
    return d


def rk4_step(state: np.ndarray, step_s: float, net: NetworkArrays) -> np.ndarray:
    """Return the state one classical Runge-Kutta step of ``step_s`` seconds later."""
    k1 = eq1_derivative(state, net)
    k2 = eq1_derivative(state + 0.5 * step_s * k1, net)
    k3 = eq1_derivative(state + 0.5 * step_s * k2, net)
    k4 = eq1_derivative(state + step_s * k3, net)
    later: np.ndarray = state + (step_s / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return later


def output_angles(state: np.ndarray, net: NetworkArrays) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the outputs Theta_i = r_i cos(xi_i) + b_i (rad) and their rates (rad/s), eq 1.

    Both (..., N). The rate is the exact time derivative of the output along the flow.
    """
    xi = state[..., PHASE, :]
    r = state[..., AMPLITUDE, :]
    xi_rate = eq1_derivative(state, net)[..., PHASE, :]
    angle = r * np.cos(xi) + state[..., OFFSET, :]
    rate = (state[..., AMPLITUDE_RATE, :] * np.cos(xi) - r * xi_rate * np.sin(xi)
            + state[..., OFFSET_RATE, :])
    return angle, rate


def simulate(net: NetworkArrays, duration_s: float, step_s: float,
             state: np.ndarray | None = None, record_every: int = 1
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Integrate eq 1 from ``state`` (default: at rest) for ``duration_s`` in fixed RK4 steps.

    Works for one network (arrays (N,)) or a batch (arrays (P, N)). Returns
    ``(t (T,), angles (T, ..., N), rates (T, ..., N), final_state (..., 5, N))`` sampled every
    ``record_every`` steps, starting with the initial state at t = 0.
    """
    steps = int(round(duration_s / step_s))
    if state is None:
        batch_shape = np.broadcast_shapes(np.shape(net.amplitude), np.shape(net.frequency_hz))
        state = initial_state(batch_shape[:-1], batch_shape[-1])
    times, angles, rates = [], [], []
    for n in range(steps + 1):
        if n % record_every == 0:
            angle, rate = output_angles(state, net)
            times.append(n * step_s)
            angles.append(angle)
            rates.append(rate)
        if n < steps:
            state = rk4_step(state, step_s, net)
    return np.array(times), np.array(angles), np.array(rates), state


def _pair_derivative(s: tuple[float, ...], c: tuple[float, ...]) -> tuple[float, ...]:
    """
    Return eq 1's derivative for two oscillators on plain floats (the node's hot path).

    State ``s`` = (xi1, xi2, r1, r2, r1', r2', b1, b2, b1', b2'); constants ``c`` =
    (2 pi v, R1, R2, B1, B2, w12, w21, phi12, phi21, alpha). Same equations as
    ``eq1_derivative``, without numpy's per-call overhead on (5, 2) arrays.
    """
    xi1, xi2, r1, r2, dr1, dr2, b1, b2, db1, db2 = s
    omega, big_r1, big_r2, big_b1, big_b2, w12, w21, phi12, phi21, alpha = c
    gain = 0.25 * alpha
    return (omega + r2 * w12 * math.sin(xi2 - xi1 - phi12),
            omega + r1 * w21 * math.sin(xi1 - xi2 - phi21),
            dr1, dr2,
            alpha * (gain * (big_r1 - r1) - dr1), alpha * (gain * (big_r2 - r2) - dr2),
            db1, db2,
            alpha * (gain * (big_b1 - b1) - db1), alpha * (gain * (big_b2 - b2) - db2))


def _pair_rk4(s: tuple[float, ...], h: float, c: tuple[float, ...]) -> tuple[float, ...]:
    """Return the two-oscillator state one classical RK4 step of ``h`` seconds later."""
    k1 = _pair_derivative(s, c)
    k2 = _pair_derivative(tuple(x + 0.5 * h * k for x, k in zip(s, k1)), c)
    k3 = _pair_derivative(tuple(x + 0.5 * h * k for x, k in zip(s, k2)), c)
    k4 = _pair_derivative(tuple(x + h * k for x, k in zip(s, k3)), c)
    return tuple(x + h / 6.0 * (a + 2.0 * b + 2.0 * cc + d)
                 for x, a, b, cc, d in zip(s, k1, k2, k3, k4))


# Order of the rows of the (5, 2) state in the flat two-oscillator tuple.
_PAIR_ROWS = (PHASE, AMPLITUDE, AMPLITUDE_RATE, OFFSET, OFFSET_RATE)


class CpgIntegrator:
    """
    A running fish CPG: fixed-step RK4 on an internal clock, independent of the output rate.

    ``advance(t)`` integrates whole steps up to time ``t``; ``output(t)`` evaluates the outputs
    exactly at ``t`` by a partial step that is not committed, so the publish rate never changes
    the trajectory. ``set_parameters`` commits the last output's partial step, then swaps the
    targets and keeps the state: the trajectory goes on from exactly what was output.
    Integrates the same equations as ``rk4_step`` on plain floats (two oscillators only),
    because a node stepping at 1 kHz spends most of its time in numpy call overhead otherwise.
    """

    _params: CpgParameters
    _c: tuple[float, ...]  # the constants of eq 1 that _pair_rk4 takes

    def __init__(self, params: CpgParameters, step_s: float = 1e-3, time_s: float = 0.0,
                 state: np.ndarray | None = None) -> None:
        """Start at rest (or at ``state`` (5, 2)) at time ``time_s`` with RK4 step ``step_s``."""
        self.step_s = float(step_s)
        self.time_s = float(time_s)
        self._shown_s = -math.inf  # time of the last output (its partial step not committed)
        self.state = initial_state() if state is None else state
        self.set_parameters(params)

    @property
    def state(self) -> np.ndarray:
        """Return the state as a (5, 2) array (rows as in ``eq1_derivative``)."""
        return np.array(self._s).reshape(STATE_ROWS, NUM_SERVOS)

    @state.setter
    def state(self, value: np.ndarray) -> None:
        value = np.asarray(value, dtype=float).reshape(STATE_ROWS, NUM_SERVOS)
        if not np.all(np.isfinite(value)):
            raise ValueError(f'state must be finite, got {value.tolist()}')
        self._s = tuple(float(v) for row in _PAIR_ROWS for v in value[row])

    @property
    def parameters(self) -> CpgParameters:
        """Return the parameters currently driving the network."""
        return self._params

    def set_parameters(self, params: CpgParameters) -> None:
        """
        Change the targets; state and time persist, so outputs stay continuous.

        An output already given past the last whole step is committed first, with the old
        parameters: the trajectory goes on from exactly the state last output. (Re-integrating
        that partial step with the new parameters moved the output by up to r * 2 pi df *
        step_s: 0.68 mrad for a +0.77 Hz change from Table 1 over 300 switch times, a small
        servo step at each of the planner's frequency changes.)
        """
        if self._shown_s > self.time_s:
            self._s = _pair_rk4(self._s, self._shown_s - self.time_s, self._c)
            self.time_s = self._shown_s
        self._params = params
        self._c = (2.0 * math.pi * params.frequency_hz, *params.amplitude, *params.offset,
                   params.w12, params.w21, params.phi12, params.phi21, params.alpha)

    def advance(self, time_s: float, max_steps: int = 100_000) -> None:
        """
        Integrate whole steps while they end at or before ``time_s`` (s).

        A clock that jumps backwards or far ahead (more than ``max_steps`` steps) re-bases the
        internal clock instead of integrating, keeping the state: outputs stay continuous.
        """
        steps = math.floor((time_s - self.time_s) / self.step_s + 1e-9)
        if steps < 0 or steps > max_steps:
            self.time_s = float(time_s)
            self._shown_s = -math.inf
            return
        for _ in range(steps):
            self._s = _pair_rk4(self._s, self.step_s, self._c)
        self.time_s += steps * self.step_s

    def output(self, time_s: float) -> tuple[tuple[float, float], tuple[float, float]]:
        """
        Return (angles rad, rates rad/s) of the two servos at ``time_s`` (within a step of now).

        Plain floats, not arrays: the node calls this at every tick (up to 1 kHz).
        """
        _finite('time_s', time_s)
        lead = min(max(time_s - self.time_s, 0.0), self.step_s)
        s = self._s if lead == 0.0 else _pair_rk4(self._s, lead, self._c)
        self._shown_s = self.time_s + lead
        d = _pair_derivative(s, self._c)
        xi1, xi2, r1, r2, dr1, dr2, b1, b2, db1, db2 = s
        angles = (r1 * math.cos(xi1) + b1, r2 * math.cos(xi2) + b2)
        rates = (dr1 * math.cos(xi1) - r1 * d[0] * math.sin(xi1) + db1,
                 dr2 * math.cos(xi2) - r2 * d[1] * math.sin(xi2) + db2)
        return angles, rates
