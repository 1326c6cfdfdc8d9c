# SPDX-License-Identifier: Apache-2.0
"""Gait families over (frequency, amplitude scale): membership, nearest, interpolation."""

import numpy as np
import pytest
from wirefish_cpg.gait_family import (family_members, interpolated_parameters, locked_form,
                                      nearest_gait, scaled_wave)
from wirefish_cpg.gait_library import Gait, GaitLibrary
from wirefish_cpg.steady_state import stable_phase_difference
from wirefish_kinematics.geometry import FishGeometry
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.tuning import fit_gait
from wirefish_tuner.wave_loss import position_of, swing_angle_rmse_deg, WaveFitProblem, WaveSpec

REFERENCE = WaveSpec()
GEOMETRY = FishGeometry()
FIELDS = {name: getattr(GEOMETRY, name)
          for name in ('l1', 'l2', 'l3', 'r1', 'r2', 'rd1', 'rd2')}


def fitted(wave: WaveSpec, seed: int = 0) -> Gait:
    fit = fit_gait(WaveFitProblem(wave=wave, geometry=GEOMETRY), np.random.default_rng(seed),
                   PsoOptions())
    return Gait(wave=wave, geometry=tuple(sorted(FIELDS.items())), params=fit.params,
                loss=fit.loss, rmse_theta_deg=tuple(fit.rmse_theta_deg))


@pytest.fixture(scope='module')
def grid_library() -> GaitLibrary:
    library = GaitLibrary()
    for f in (1.0, 1.5):
        for s in (0.8, 1.2):
            library = library.with_gait(fitted(scaled_wave(REFERENCE, f, s)))
    return library


def test_the_family_holds_scaled_waves_of_the_reference_on_its_geometry(grid_library):
    other_shape = fitted(WaveSpec(c1=0.15, c2=2.0))
    other_fish = Gait(wave=REFERENCE, geometry=tuple(sorted({**FIELDS, 'l2': 0.12}.items())),
                      params=other_shape.params, loss=1.0, rmse_theta_deg=(1.0, 1.0))
    library = grid_library.with_gait(other_shape).with_gait(other_fish)
    members = family_members(library, REFERENCE, FIELDS)
    assert [(m.frequency_hz, m.scale) for m in members] == [
        (1.0, 0.8), (1.0, 1.2), (1.5, 0.8), (1.5, 1.2)]


def test_the_nearest_gait_is_the_closest_grid_point(grid_library):
    members = family_members(grid_library, REFERENCE, FIELDS)
    best = nearest_gait(members, 1.4, 0.85)
    assert (best.frequency_hz, best.scale) == (1.5, 0.8)
    with pytest.raises(ValueError, match='empty'):
        nearest_gait([], 1.0, 1.0)


def test_canonical_coupling_locks_at_the_blended_phase_difference(grid_library):
    members = family_members(grid_library, REFERENCE, FIELDS)
    params = interpolated_parameters(members, 1.25, 1.0)
    r1, r2 = params.amplitude
    delta = stable_phase_difference(r1, r2, params.w12, params.w21, params.phi12,
                                    params.phi21)
    assert delta == pytest.approx(params.phi12, abs=1e-9)
    assert params.frequency_hz == 1.25  # no coupling shift to compensate


def test_an_interpolated_gait_follows_the_wave_about_as_well_as_a_direct_fit(grid_library):
    members = family_members(grid_library, REFERENCE, FIELDS)
    target = scaled_wave(REFERENCE, 1.25, 1.0)
    problem = WaveFitProblem(wave=target, geometry=GEOMETRY)
    blended = swing_angle_rmse_deg(
        position_of(interpolated_parameters(members, 1.25, 1.0))[None], problem)[0]
    direct = fitted(target).rmse_theta_deg
    assert np.all(blended <= np.asarray(direct) + 0.5), (blended, direct)


def test_the_locked_form_folds_signs_without_changing_the_gait(grid_library):
    gait = grid_library.gaits[0]
    r1, r2, delta = locked_form(gait.params)
    assert r1 >= 0.0 and r2 >= 0.0 and -np.pi <= delta <= np.pi


@pytest.mark.parametrize('frequency, scale', [(0.9, 1.0), (1.2, 1.3)])
def test_interpolation_outside_the_grid_is_refused(grid_library, frequency, scale):
    with pytest.raises(ValueError, match='outside the family grid'):
        interpolated_parameters(family_members(grid_library, REFERENCE, FIELDS), frequency, scale)


@pytest.mark.parametrize('frequency, scale', [(1.0, 0.8), (1.5, 1.2), (1.25, 0.8), (1.0, 1.0)])
def test_a_query_on_a_grid_line_blends_within_the_family(grid_library, frequency, scale):
    members = family_members(grid_library, REFERENCE, FIELDS)
    r1, r2, _ = locked_form(interpolated_parameters(members, frequency, scale))
    corners = np.array([locked_form(m.gait.params)[:2] for m in members])
    # A blend is a convex combination: each amplitude within the corners' (never a zero gait).
    assert corners[:, 0].min() - 1e-12 <= r1 <= corners[:, 0].max() + 1e-12
    assert corners[:, 1].min() - 1e-12 <= r2 <= corners[:, 1].max() + 1e-12
