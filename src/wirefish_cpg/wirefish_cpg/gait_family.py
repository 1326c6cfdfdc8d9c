# SPDX-License-Identifier: Apache-2.0
"""
A family of gaits over (tail-beat frequency, amplitude scale) of a reference wave, for planners.

The family of a reference wave (c1, c2, k, f0) (eq 23) is every library gait of the same
geometry whose wave is (s c1, s c2, k, f): same wave number and envelope shape, envelope scaled
by s, any frequency f. ``nearest_gait`` picks the member closest to a query (relative distance
in f and in s); ``interpolated_parameters`` blends the four members around a query, bilinearly.

What is blended: at the locked state the fitted gait is (R1, R2, Delta*) only (the coupling's
(w, phi) are not identifiable: wirefish_cpg README), so the corners are reduced to that form
(signs folded so that R1, R2 >= 0: (R1, R2, D) ~ (-R1, -R2, D) ~ (R1, -R2, D + pi)), blended,
and given a canonical coupling that locks at exactly that Delta* without shifting the frequency:
phi12 = Delta*, phi21 = -Delta*, w12 = w21 = ``CANONICAL_COUPLING``, for which eq 1 gives
dDelta/dt = -(R1 w21 + R2 w12) sin(Delta - Delta*) (stable) and Omega = 2 pi v, so v = f.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from wirefish_cpg.gait_library import FitMode, Gait, GaitLibrary
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import stable_phase_difference
from wirefish_kinematics.wave_spec import WaveSpec

# Coupling (1/s) of interpolated gaits: half the paper's bound; locks at ~5 (R1 + R2) 1/s.
CANONICAL_COUPLING = 5.0
_SAME = 1e-9  # relative tolerance for "same shape" (k, c2/c1) of a member's wave


@dataclass(frozen=True)
class FamilyMember:
    """A gait of the family, at its frequency (Hz) and amplitude scale."""

    frequency_hz: float
    scale: float
    gait: Gait


def scaled_wave(reference: WaveSpec, frequency_hz: float, scale: float) -> WaveSpec:
    """Return the reference wave with its envelope scaled by ``scale`` at ``frequency_hz``."""
    return WaveSpec(reference.c1 * scale, reference.c2 * scale, reference.k, frequency_hz)


def scale_of(wave: WaveSpec, reference: WaveSpec) -> float | None:
    """Return s if ``wave`` is the reference's shape scaled by s (any frequency), else None."""
    if not math.isclose(wave.k, reference.k, rel_tol=_SAME):
        return None
    ref = np.array([reference.c1, reference.c2])
    own = np.array([wave.c1, wave.c2])
    norm = float(ref @ ref)
    if norm == 0.0:
        return None
    scale = float(own @ ref) / norm
    if not np.allclose(own, scale * ref, rtol=_SAME, atol=_SAME * math.sqrt(norm)):
        return None
    return scale


def family_members(library: GaitLibrary, reference: WaveSpec, geometry: dict[str, float],
                   mode: str = FitMode.PHASE_FREE) -> list[FamilyMember]:
    """Return the library's gaits of the reference's family on ``geometry``, by (f, s)."""
    members = []
    for gait in library.for_geometry(geometry):
        scale = scale_of(gait.wave, reference)
        if scale is not None and gait.mode == mode:
            members.append(FamilyMember(gait.wave.frequency_hz, scale, gait))
    return sorted(members, key=lambda m: (m.frequency_hz, m.scale))


def nearest_gait(members: list[FamilyMember], frequency_hz: float, scale: float
                 ) -> FamilyMember:
    """Return the member nearest to (frequency_hz, scale), distances relative to the query."""
    if not members:
        raise ValueError('the family is empty: build it first (wirefish gaits build)')
    if not (frequency_hz > 0.0 and scale > 0.0):
        raise ValueError(f'frequency and scale must be > 0, got {frequency_hz}, {scale}')
    return min(members, key=lambda m: math.hypot((m.frequency_hz - frequency_hz) / frequency_hz,
                                                 (m.scale - scale) / scale))


def locked_form(params: CpgParameters) -> tuple[float, float, float]:
    """Return a gait's (R1, R2, Delta*) with R1, R2 >= 0 (the same locked output)."""
    r1, r2 = params.amplitude
    delta = float(stable_phase_difference(r1, r2, params.w12, params.w21, params.phi12,
                                          params.phi21))
    if r1 < 0.0:
        r1, r2 = -r1, -r2
    if r2 < 0.0:
        r2, delta = -r2, delta + math.pi
    return r1, r2, math.remainder(delta, 2.0 * math.pi)


def canonical_parameters(frequency_hz: float, r1: float, r2: float, delta: float,
                         alpha: float) -> CpgParameters:
    """Return CPG parameters that lock to (R1, R2, Delta*) at ``frequency_hz`` (see above)."""
    delta = math.remainder(delta, 2.0 * math.pi)
    return CpgParameters(frequency_hz=frequency_hz, amplitude=(r1, r2), w12=CANONICAL_COUPLING,
                         w21=CANONICAL_COUPLING, phi12=delta, phi21=-delta, alpha=alpha)


def interpolated_parameters(members: list[FamilyMember], frequency_hz: float, scale: float
                            ) -> CpgParameters:
    """
    Return the gait at (frequency_hz, scale) blended from the four members around it.

    Raises ``ValueError`` when the query is outside the family's grid or a corner is missing.
    """
    frequencies = sorted({m.frequency_hz for m in members})
    scales = sorted({m.scale for m in members})
    f0, f1 = _bracket(frequencies, frequency_hz, 'frequency_hz')
    s0, s1 = _bracket(scales, scale, 'scale')
    corners = {}
    for f in (f0, f1):
        for s in (s0, s1):
            match = [m for m in members if m.frequency_hz == f and m.scale == s]
            if not match:
                raise ValueError(f'no gait at frequency {f:g} Hz, scale {s:g} to blend from')
            corners[f, s] = locked_form(match[0].gait.params)
    u = 0.0 if f1 == f0 else (frequency_hz - f0) / (f1 - f0)
    v = 0.0 if s1 == s0 else (scale - s0) / (s1 - s0)
    # Summed, not assigned: on a grid line two corners are one (f0 == f1 or s0 == s1), and
    # assigning the second weight would overwrite the first (a zero gait on every grid line).
    weights: dict[tuple[float, float], float] = {}
    for key, weight in (((f0, s0), (1 - u) * (1 - v)), ((f1, s0), u * (1 - v)),
                        ((f0, s1), (1 - u) * v), ((f1, s1), u * v)):
        weights[key] = weights.get(key, 0.0) + weight
    anchor = corners[f0, s0][2]
    r1 = r2 = delta = 0.0
    for key, weight in weights.items():
        c1, c2, d = corners[key]
        r1 += weight * c1
        r2 += weight * c2
        delta += weight * (anchor + math.remainder(d - anchor, 2.0 * math.pi))  # unwrapped
    alpha = members[0].gait.params.alpha
    return canonical_parameters(frequency_hz, r1, r2, delta, alpha)


def _bracket(values: list[float], x: float, name: str) -> tuple[float, float]:
    if not values or not values[0] <= x <= values[-1]:
        span = f'[{values[0]:g}, {values[-1]:g}]' if values else '(empty)'
        raise ValueError(f'{name} {x:g} is outside the family grid {span}')
    upper = next(v for v in values if v >= x)
    lower = max(v for v in values if v <= x)
    return lower, upper
