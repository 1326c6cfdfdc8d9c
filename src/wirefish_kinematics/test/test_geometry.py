# SPDX-License-Identifier: Apache-2.0
"""FishGeometry: SI defaults and validation."""

import math

import pytest
from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS


def test_defaults_are_the_geometry_estimates_in_si_units():
    g = FishGeometry()
    assert (g.l1, g.l2, g.l3, g.r1, g.r2, g.rd1, g.rd2) == (
        0.080, 0.100, 0.060, 0.020, 0.012, 0.018, 0.018)
    assert (g.body_length, g.water_density, g.fin_span, g.wetted_area) == (
        0.53, 1000.0, 0.14, 0.14)


def test_tail_length_and_tip_cross_section():
    g = FishGeometry()
    assert g.tail_length == pytest.approx(0.24, rel=1e-15)
    assert g.tip_cross_section_area == pytest.approx(math.pi * 0.14 ** 2 / 4, rel=1e-15)
    assert g.link_end_stations == (0.08, 0.08 + 0.1)


@pytest.mark.parametrize('name', GEOMETRY_FIELDS)
@pytest.mark.parametrize('value', [0.0, -0.01, math.nan, math.inf, 'a', True])
def test_each_field_rejects_non_positive_or_non_finite_values_naming_itself(name, value):
    with pytest.raises(ValueError, match=name):
        FishGeometry(**{name: value})


def test_integers_are_accepted_as_floats():
    assert FishGeometry(water_density=1025).water_density == 1025.0
