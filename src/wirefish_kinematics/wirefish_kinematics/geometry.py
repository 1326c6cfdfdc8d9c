# SPDX-License-Identifier: Apache-2.0
"""
The fish's dimensions (SI) used by every equation of paper section 3.

The paper gives no dimensions except the body length (530 mm, section 2.1). Every other default
is an ESTIMATE from the fish's size, not a measurement; the drag coefficient is the one constant
calibrated on the paper (``python -m wirefish_analysis.calibrate_drag``, see the README).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math

# Effective C_D of eq 17: eq 18 gives 0.39 m/s (section 5.3, Fig 8) at 3 Hz with the steady
# state of the Table 1 CPG. Printed by `python -m wirefish_analysis.calibrate_drag`; keep equal.
CALIBRATED_DRAG_COEFFICIENT = 0.999663194


@dataclass(frozen=True)
class FishGeometry:
    """
    Dimensions and fluid constants of the fish, validated on construction.

    Lengths in m, density in kg/m^3, areas in m^2, C_D dimensionless. Raises ``ValueError``
    (naming the field) unless every value is a finite number > 0.
    """

    l1: float = 0.080  # flexible link L1, oval plate I to III (m), estimate
    l2: float = 0.100  # flexible link L2, plate III to V (m), estimate
    l3: float = 0.060  # rigid caudal fin L3 (m), estimate
    r1: float = 0.020  # offset of wire pair 1 from the body axis (m), estimate
    r2: float = 0.012  # offset of wire pair 2 from the body axis (m), estimate
    rd1: float = 0.018  # radius R_D1 of reel 1 (m), estimate
    rd2: float = 0.018  # radius R_D2 of reel 2 (m), estimate
    body_length: float = 0.53  # L of Sw = U / (f L) (m), paper section 2.1
    water_density: float = 1000.0  # rho (kg/m^3)
    fin_span: float = 0.14  # caudal fin span (m), estimate; A(L_T) = pi span^2 / 4
    wetted_area: float = 0.14  # S_c of eq 17 (m^2), estimate
    drag_coefficient: float = CALIBRATED_DRAG_COEFFICIENT  # C_D of eq 17, calibrated

    def __post_init__(self) -> None:
        """Coerce every field to float and check it is finite and > 0."""
        for spec in fields(self):
            value = getattr(self, spec.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f'{spec.name} must be a number, got {value!r}')
            value = float(value)
            if not math.isfinite(value) or value <= 0.0:
                raise ValueError(f'{spec.name} must be finite and > 0, got {value}')
            object.__setattr__(self, spec.name, value)

    @property
    def tail_length(self) -> float:
        """Return L_T = l1 + l2 + l3 (m), the arc length from plate I to the tail tip."""
        return self.l1 + self.l2 + self.l3

    @property
    def link_end_stations(self) -> tuple[float, float]:
        """Return the stations q of O1 and O2 (m): l1 and l1 + l2."""
        return self.l1, self.l1 + self.l2

    @property
    def tip_cross_section_area(self) -> float:
        """Return A(L_T) = pi span^2 / 4 (m^2), the cross-section area of eqs 16 and 18."""
        return math.pi * self.fin_span ** 2 / 4.0


GEOMETRY_FIELDS = tuple(spec.name for spec in fields(FishGeometry))
