# SPDX-License-Identifier: Apache-2.0
"""
Forward speed -> gait: eq 18 inverted over a family of gaits (pure; no rclpy).

A gait family maps (tail-beat frequency f, amplitude scale s) to CPG parameters: Table 1 locked
at f with both R_i scaled by s (``Table1Family``, ``wirefish_cpg.table1_gait``), or the gait
library's fitted family of a reference wave, envelope scaled by s at frequency f, interpolated
between the fitted grid points (``LibraryFamily``, ``wirefish_cpg.gait_family``; only inside
its grid, which bounds the planner's f and s). Each gait is
judged on one locked period of its servo commands: the eq 18 speed (eqs 16-22, servos that
follow exactly), the peak servo rate and the peak servo angle.

Feasible: peak rate <= ``slew_margin`` x the servo's slew limit (the virtual fish's 9.1 rad/s,
``wirefish_analysis.servo_calibration``: a faster command is not followed, so eq 18 would
over-predict) and peak angle + the largest turning offset <= the servo range. In Table 1's
family both are linear in s (the locked phase difference does not depend on s), so the largest
feasible scale at a frequency is one division; a family that is not (``linear_in_scale``
False, e.g. fitted gaits) gets it by bisection.

Policy: the lowest frequency that reaches the target. Below the speed of the lowest frequency at
the largest feasible scale, the frequency stays at its minimum and the scale is solved; above,
the scale stays at its largest feasible value and the frequency is solved (fewer tail beats,
higher swimming number). Targets above the fastest feasible gait are clamped to it, and the
reason names the binding limit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
import functools
import math
from pathlib import Path
from typing import Protocol

import numpy as np
from scipy.optimize import brentq
from wirefish_cpg.gait_family import family_members, FamilyMember, interpolated_parameters
from wirefish_cpg.gait_library import load_library
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.table1_gait import one_locked_period, table1_locked_at
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import estimate_speed
from wirefish_kinematics.wave_spec import WaveSpec

FRONTIER_SAMPLES = 24  # frequencies scanned for the fastest feasible gait
SPEED_TOLERANCE_M_S = 1e-5


class GaitFamily(Protocol):
    """A family of gaits: CPG parameters for (tail-beat frequency Hz, amplitude scale)."""

    name: str
    linear_in_scale: bool  # servo angles and rates proportional to the amplitude scale
    frequency_range: tuple[float, float] | None  # where the family is defined (Hz)
    scale_range: tuple[float, float] | None

    def gait(self, frequency_hz: float, amplitude_scale: float) -> CpgParameters:
        """Return the CPG parameters of this gait."""


class Table1Family:
    """Table 1 locked at f with R_i scaled by s (the analytic family, no fit needed)."""

    name: str = 'table1'
    linear_in_scale: bool = True
    frequency_range: tuple[float, float] | None = None
    scale_range: tuple[float, float] | None = None

    def gait(self, frequency_hz: float, amplitude_scale: float) -> CpgParameters:
        """Return Table 1 locked at ``frequency_hz`` with R_i scaled by ``amplitude_scale``."""
        return table1_locked_at(frequency_hz, amplitude_scale)


class LibraryFamily:
    """The gait library's fitted gaits of a reference wave, blended inside their grid."""

    name: str = 'library'
    linear_in_scale: bool = False
    frequency_range: tuple[float, float] | None
    scale_range: tuple[float, float] | None

    def __init__(self, members: list[FamilyMember]) -> None:
        """Keep a grid of at least 2 x 2 members (ValueError otherwise)."""
        frequencies = sorted({m.frequency_hz for m in members})
        scales = sorted({m.scale for m in members})
        if len(frequencies) < 2 or len(scales) < 2:
            raise ValueError(f'the library family has {len(members)} gaits over '
                             f'{len(frequencies)} frequencies x {len(scales)} scales: a 2 x 2 '
                             'grid at least is needed (wirefish gaits build)')
        self.members = members
        self.frequency_range = (frequencies[0], frequencies[-1])
        self.scale_range = (scales[0], scales[-1])

        self._frequencies, self._scales = frequencies, scales

    def gait(self, frequency_hz: float, amplitude_scale: float) -> CpgParameters:
        """Return the gait blended from the four fitted members around (f, s)."""
        # wirefish_cpg.gait_family.interpolated_parameters gives amplitude 0 on a grid line
        # (its corner weights share dict keys there); the blend is continuous, so a query a
        # 1e-9 relative step inside the cell gives the value on the line.
        return interpolated_parameters(self.members, _off_grid(frequency_hz, self._frequencies),
                                       _off_grid(amplitude_scale, self._scales))


def _off_grid(x: float, grid: list[float]) -> float:
    """Return ``x``, moved a 1e-9 relative step towards the grid's inside if it is on a line."""
    if not any(math.isclose(x, g, rel_tol=1e-12, abs_tol=0.0) for g in grid):
        return x
    step = 1e-9 * (grid[-1] - grid[0])
    return x - step if x >= grid[-1] else x + step


def library_family(path: Path, reference: WaveSpec, geometry: dict[str, float]
                   ) -> LibraryFamily:
    """Return the library file's family of ``reference`` on ``geometry`` (ValueError: none)."""
    try:
        library = load_library(path)
    except OSError as error:
        raise ValueError(f'gait library {path}: {error}') from error
    return LibraryFamily(family_members(library, reference, geometry))


@dataclass(frozen=True)
class GaitLimits:
    """What a gait may ask of the servos; SI units, radians."""

    min_frequency_hz: float = 0.5
    max_frequency_hz: float = 4.0
    max_amplitude_scale: float = 1.0  # Table 1's R_i: tail tip ~8.8 cm, the paper's largest
    servo_rate_limit_rad_s: float = 9.1
    slew_margin: float = 0.95
    servo_limit_rad: float = math.pi / 2
    max_offset_rad: float = 0.3

    def __post_init__(self) -> None:
        """Check every value is finite and the ranges are ordered."""
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f'{name} must be finite and > 0, got {value}')
        if self.min_frequency_hz >= self.max_frequency_hz:
            raise ValueError(f'min_frequency_hz ({self.min_frequency_hz:g}) must be below '
                             f'max_frequency_hz ({self.max_frequency_hz:g})')
        if self.slew_margin > 1.0:
            raise ValueError(f'slew_margin must be <= 1, got {self.slew_margin:g}')
        if self.max_offset_rad >= self.servo_limit_rad:
            raise ValueError(f'max_offset_rad ({self.max_offset_rad:g}) leaves no servo range '
                             f'below servo_limit_rad ({self.servo_limit_rad:g})')


@dataclass(frozen=True)
class GaitPoint:
    """One gait judged on a locked period: eq 18 speed (m/s), peak rate and angle (rad/s, rad)."""

    frequency_hz: float
    amplitude_scale: float
    params: CpgParameters
    speed: float
    peak_rate: float
    peak_angle: float


@dataclass(frozen=True)
class GaitChoice:
    """The planner's gait for a target speed; ``clamp_reason`` is '' unless it was clamped."""

    target_speed: float
    point: GaitPoint | None  # None: rest (speed 0)
    clamp_reason: str = ''

    @property
    def predicted_speed(self) -> float:
        """Return the eq 18 speed of the chosen gait (0 at rest)."""
        return 0.0 if self.point is None else self.point.speed


def evaluate_gait(family: GaitFamily, frequency_hz: float, amplitude_scale: float,
                  geometry: FishGeometry) -> GaitPoint:
    """Return the gait (f, s) of ``family`` with its eq 18 speed, peak rate and peak angle."""
    params = family.gait(frequency_hz, amplitude_scale)
    angles, rates, dt = one_locked_period(params)
    speed = estimate_speed(angles, rates, dt, geometry).speed
    return GaitPoint(frequency_hz, amplitude_scale, params, float(speed),
                     float(np.abs(rates).max()), float(np.abs(angles).max()))


class GaitPlanner:
    """Chooses gaits by the policy above; caches gait evaluations (they are deterministic)."""

    def __init__(self, family: GaitFamily, limits: GaitLimits,
                 geometry: FishGeometry | None = None, family_note: str = '') -> None:
        """Scan the feasible frontier once (FRONTIER_SAMPLES gaits) for the fastest gait."""
        self.family = family
        self.family_note = family_note  # why this family (e.g. the library was not usable)
        self.limits = limits = _within_family(limits, family)
        self._min_scale = family.scale_range[0] if family.scale_range else 0.0
        self.geometry = geometry or FishGeometry()
        self._point = functools.lru_cache(maxsize=4096)(self._evaluate)
        frequencies = np.linspace(limits.min_frequency_hz, limits.max_frequency_hz,
                                  FRONTIER_SAMPLES)
        frontier = [self.frontier_point(float(f)) for f in frequencies]
        self._fastest = max(frontier, key=lambda p: p.speed)

    def _evaluate(self, frequency_hz: float, amplitude_scale: float) -> GaitPoint:
        return evaluate_gait(self.family, frequency_hz, amplitude_scale, self.geometry)

    def feasible_scale(self, frequency_hz: float) -> tuple[float, str]:
        """Return the largest feasible amplitude scale at ``frequency_hz`` and what binds it."""
        lim = self.limits
        rate_limit = lim.slew_margin * lim.servo_rate_limit_rad_s
        angle_limit = lim.servo_limit_rad - lim.max_offset_rad
        if self.family.linear_in_scale:
            unit = self._point(frequency_hz, 1.0)
            by_rate = rate_limit / unit.peak_rate
            by_range = angle_limit / unit.peak_angle
        else:
            by_rate = self._largest_scale(frequency_hz, lambda p: p.peak_rate <= rate_limit)
            by_range = self._largest_scale(frequency_hz, lambda p: p.peak_angle <= angle_limit)
        candidates = ((lim.max_amplitude_scale, 'the largest amplitude scale '
                       f'{lim.max_amplitude_scale:g}'),
                      (by_rate, f'the servo slew limit {lim.servo_rate_limit_rad_s:g} rad/s x '
                       f'{lim.slew_margin:g}'),
                      (by_range, f'the servo range {lim.servo_limit_rad:.3g} rad less the '
                       f'turning offset {lim.max_offset_rad:g} rad'))
        return min(candidates, key=lambda c: c[0])

    def _largest_scale(self, frequency_hz: float, ok: Callable[[GaitPoint], bool],
                       iterations: int = 30) -> float:
        """Return the largest s in (0, max scale] with ``ok(gait)``, by bisection (monotone)."""
        high = self.limits.max_amplitude_scale
        if ok(self._point(frequency_hz, high)):
            return high
        low = self._min_scale  # below it a library family has no gait (taken even if not ok)
        for _ in range(iterations):
            middle = 0.5 * (low + high)
            if ok(self._point(frequency_hz, middle)):
                low = middle
            else:
                high = middle
        return low

    def frontier_point(self, frequency_hz: float) -> GaitPoint:
        """Return the gait at ``frequency_hz`` with its largest feasible amplitude scale."""
        scale, _ = self.feasible_scale(frequency_hz)
        return self._point(frequency_hz, scale)

    @property
    def fastest(self) -> GaitPoint:
        """Return the fastest feasible gait found on the frontier scan."""
        return self._fastest

    def choose(self, target_speed: float) -> GaitChoice:
        """Return the gait for ``target_speed`` (m/s, >= 0) by the documented policy."""
        if not (math.isfinite(target_speed) and target_speed >= 0.0):
            raise ValueError(f'target speed must be finite and >= 0, got {target_speed}')
        if target_speed == 0.0:
            return GaitChoice(0.0, None)
        lim = self.limits
        fastest = self._fastest
        if target_speed >= fastest.speed:
            _, binding = self.feasible_scale(fastest.frequency_hz)
            reason = (f'{target_speed:.3f} m/s is above the fastest feasible gait '
                      f'({fastest.speed:.3f} m/s at {fastest.frequency_hz:.2f} Hz, scale '
                      f'{fastest.amplitude_scale:.2f}, bound by {binding})')
            return GaitChoice(target_speed, fastest, '' if target_speed == fastest.speed
                              else reason)
        slowest = self.frontier_point(lim.min_frequency_hz)
        if target_speed <= slowest.speed:
            top = slowest.amplitude_scale
            bottom = max(1e-6 * top, self._min_scale)
            least = self._point(lim.min_frequency_hz, bottom)
            if target_speed <= least.speed:  # only a library family has a smallest gait
                return GaitChoice(target_speed, least, f'{target_speed:.3f} m/s is below the '
                                  f"family's slowest gait ({least.speed:.3f} m/s)")
            scale = brentq(lambda s: self._point(lim.min_frequency_hz, s).speed - target_speed,
                           bottom, top, xtol=1e-9 * top)
            return GaitChoice(target_speed, self._point(lim.min_frequency_hz, float(scale)))
        frequency = brentq(lambda f: self.frontier_point(f).speed - target_speed,
                           lim.min_frequency_hz, fastest.frequency_hz, xtol=1e-6,
                           rtol=SPEED_TOLERANCE_M_S)
        return GaitChoice(target_speed, self.frontier_point(float(frequency)))


def _within_family(limits: GaitLimits, family: GaitFamily) -> GaitLimits:
    """Return ``limits`` narrowed to where ``family`` is defined (ValueError if disjoint)."""
    changes: dict[str, float] = {}
    if family.frequency_range is not None:
        low, high = family.frequency_range
        changes['min_frequency_hz'] = max(limits.min_frequency_hz, low)
        changes['max_frequency_hz'] = min(limits.max_frequency_hz, high)
    if family.scale_range is not None:
        changes['max_amplitude_scale'] = min(limits.max_amplitude_scale, family.scale_range[1])
    return replace(limits, **changes)
