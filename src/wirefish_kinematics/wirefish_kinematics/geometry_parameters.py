# SPDX-License-Identifier: Apache-2.0
"""
The fish's geometry as ROS parameters: the graph's one geometry block (no rclpy import).

``GEOMETRY_PARAMETERS`` is the one declaration of the ``FishGeometry`` fields as ROS
parameters: every node that needs geometry (kinematics, planner, tuner, tf, view, the virtual
fish) declares its fields from it (``geometry_parameters``), so names, ranges and descriptions
cannot drift apart, and ``config/wirefish.yaml`` sets them once under ``/**``. Defaults are
``FishGeometry()``'s.
"""

from __future__ import annotations

from typing import Any, Mapping

from wirefish_common.parameter_table import ParameterSpec
from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS

_DEFAULT = FishGeometry()
_GEOMETRY_DOC = {
    'l1': ('Length of flexible link L1, plate I to III (m); estimate', 1.0),
    'l2': ('Length of flexible link L2, plate III to V (m); estimate', 1.0),
    'l3': ('Length of the rigid caudal fin L3 (m); estimate', 1.0),
    'r1': ('Offset r1 of wire pair 1 from the body axis (m), eq 3; estimate', 1.0),
    'r2': ('Offset r2 of wire pair 2 from the body axis (m), eq 4; estimate', 1.0),
    'rd1': ('Radius R_D1 of reel 1 (m), eq 3; estimate', 1.0),
    'rd2': ('Radius R_D2 of reel 2 (m), eq 4; estimate', 1.0),
    'body_length': ('Body length L of Sw = U / (f L) (m); paper: 0.53', 10.0),
    'water_density': ('Water density rho (kg/m^3), eqs 16-18', 2000.0),
    'fin_span': ('Caudal fin span (m); A(L_T) = pi span^2 / 4, eq 16; estimate', 1.0),
    'wetted_area': ('Wetted surface area S_c (m^2), eq 17; estimate', 10.0),
    'drag_coefficient': ('Effective drag coefficient C_D, eq 17; calibrated '
                         '(python -m wirefish_analysis.calibrate_drag)', 10.0),
}
GEOMETRY_PARAMETERS = tuple(
    ParameterSpec(name, getattr(_DEFAULT, name), _GEOMETRY_DOC[name][0], 0.0,
                  _GEOMETRY_DOC[name][1], low_exclusive=True)
    for name in GEOMETRY_FIELDS)
# The fields the body wave (eqs 2-15) needs: enough for a node that only fits or draws it.
BODY_WAVE_GEOMETRY_FIELDS = ('l1', 'l2', 'l3', 'r1', 'r2', 'rd1', 'rd2')


def geometry_parameters(names: tuple[str, ...] = GEOMETRY_FIELDS) -> tuple[ParameterSpec, ...]:
    """Return the specs of the geometry fields ``names`` (all by default), in that order."""
    unknown = set(names) - set(GEOMETRY_FIELDS)
    if unknown:
        raise ValueError(f'not FishGeometry fields: {sorted(unknown)}')
    by_name = {spec.name: spec for spec in GEOMETRY_PARAMETERS}
    return tuple(by_name[name] for name in names)


def geometry_from(values: Mapping[str, Any], names: tuple[str, ...] = GEOMETRY_FIELDS
                  ) -> FishGeometry:
    """
    Return the FishGeometry of the fields ``names`` in a name -> value mapping.

    Fields outside ``names`` keep FishGeometry's defaults: a node declaring only
    ``BODY_WAVE_GEOMETRY_FIELDS`` never reads the others. Raises ``KeyError`` if a name is
    missing from ``values`` and ``ValueError`` if a value is invalid.
    """
    return FishGeometry(**{name: values[name] for name in names})
