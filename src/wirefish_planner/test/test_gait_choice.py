# SPDX-License-Identifier: Apache-2.0
"""The speed -> gait inversion (eq 18 over the Table 1 family) and its policy."""

import math

import pytest
from wirefish_cpg.table1_gait import locked_speed_estimate, table1_locked_at
from wirefish_kinematics.geometry import FishGeometry
from wirefish_planner.gait_choice import GaitLimits, GaitPlanner, Table1Family


@pytest.mark.parametrize('target', [0.02, 0.05, 0.10, 0.20, 0.30, 0.35])
def test_chosen_gait_predicts_the_target_speed(gait_planner, target):
    choice = gait_planner.choose(target)
    assert choice.clamp_reason == ''
    # Checked against the table1_gait core directly, not the planner's own evaluation.
    params = table1_locked_at(choice.point.frequency_hz, choice.point.amplitude_scale)
    assert locked_speed_estimate(params, FishGeometry()).speed == pytest.approx(target,
                                                                                rel=1e-3)


@pytest.mark.parametrize('target', [0.10, 0.20, 0.30])
def test_above_the_slowest_gait_the_largest_scale_and_lowest_frequency_is_used(
        gait_planner, target):
    choice = gait_planner.choose(target)
    scale, _ = gait_planner.feasible_scale(choice.point.frequency_hz)
    assert choice.point.amplitude_scale == pytest.approx(scale)
    lower = gait_planner.frontier_point(0.98 * choice.point.frequency_hz)
    assert lower.speed < target  # a lower frequency does not reach the target


def test_below_the_slowest_frontier_gait_the_frequency_stays_at_its_minimum(gait_planner):
    choice = gait_planner.choose(0.02)
    assert choice.point.frequency_hz == GaitLimits().min_frequency_hz
    assert choice.point.amplitude_scale < gait_planner.feasible_scale(
        GaitLimits().min_frequency_hz)[0]


def test_every_chosen_gait_respects_the_slew_limit_and_range(gait_planner):
    limits = GaitLimits()
    for target in (0.05, 0.15, 0.25, 0.35, 1.0):
        point = gait_planner.choose(target).point
        assert point.peak_rate <= limits.slew_margin * limits.servo_rate_limit_rad_s + 1e-9
        assert point.peak_angle + limits.max_offset_rad <= limits.servo_limit_rad


def test_a_target_above_the_fastest_gait_is_clamped_with_the_reason(gait_planner):
    choice = gait_planner.choose(1.0)
    assert choice.predicted_speed == pytest.approx(gait_planner.fastest.speed)
    assert choice.predicted_speed < 1.0
    assert 'above the fastest feasible gait' in choice.clamp_reason
    assert 'slew limit' in choice.clamp_reason


def test_speed_zero_is_rest(gait_planner):
    choice = gait_planner.choose(0.0)
    assert choice.point is None and choice.predicted_speed == 0.0


@pytest.mark.parametrize('bad', [-0.1, math.nan, math.inf])
def test_invalid_targets_are_refused(gait_planner, bad):
    with pytest.raises(ValueError):
        gait_planner.choose(bad)


def test_a_slower_servo_lowers_the_fastest_gait():
    slow = GaitPlanner(Table1Family(), GaitLimits(servo_rate_limit_rad_s=6.0))
    fast = GaitPlanner(Table1Family(), GaitLimits())
    assert slow.fastest.speed < fast.fastest.speed


@pytest.mark.parametrize('field, value', [('min_frequency_hz', 5.0), ('slew_margin', 1.5),
                                          ('max_offset_rad', 2.0), ('servo_limit_rad', -1.0),
                                          ('max_amplitude_scale', math.nan)])
def test_inconsistent_limits_are_refused(field, value):
    with pytest.raises(ValueError):
        GaitLimits(**{field: value})


class _Table1NotDeclaredLinear(Table1Family):
    """Table 1 seen as a family of unknown shape: the feasible scale by bisection."""

    linear_in_scale = False


@pytest.mark.parametrize('frequency', [1.0, 2.5, 3.5])
def test_bisection_finds_the_feasible_scale_the_linear_rule_gives(gait_planner, frequency):
    general = GaitPlanner(_Table1NotDeclaredLinear(), GaitLimits())
    assert general.feasible_scale(frequency)[0] == pytest.approx(
        gait_planner.feasible_scale(frequency)[0], rel=1e-6)


@pytest.fixture(scope='module')
def library_file(tmp_path_factory):
    """
    Return a gait library file holding a 4 x 2 family of the section 5.2 wave.

    The gaits are Table 1 locked at (f, s), stored as if fitted to the scaled wave: the test is
    of the planner's plumbing (family, grid bounds, blending), not of a fit.
    """
    from wirefish_cpg.gait_family import scaled_wave
    from wirefish_cpg.gait_library import Gait, GaitLibrary, geometry_key, save_library
    from wirefish_kinematics.geometry_parameters import BODY_WAVE_GEOMETRY_FIELDS
    from wirefish_kinematics.wave_spec import WaveSpec

    geometry = {name: getattr(FishGeometry(), name) for name in BODY_WAVE_GEOMETRY_FIELDS}
    gaits = tuple(Gait(wave=scaled_wave(WaveSpec(), f, s), geometry=geometry_key(geometry),
                       params=table1_locked_at(f, s), loss=0.0, rmse_theta_deg=(0.0, 0.0))
                  for f in (0.5, 1.5, 2.5, 3.5) for s in (0.5, 1.0))
    path = tmp_path_factory.mktemp('library') / 'gaits.yaml'
    save_library(GaitLibrary(gaits), path)
    return path


def test_the_library_family_is_used_inside_its_grid(library_file, make_planner):
    gaits = make_planner(gait_source='library', library_path=str(library_file)).gaits
    assert gaits.family.name == 'library' and gaits.family_note == ''
    choice = gaits.choose(0.2)
    assert 0.5 <= choice.point.frequency_hz <= 3.5 and choice.point.amplitude_scale <= 1.0
    assert choice.predicted_speed == pytest.approx(0.2, rel=1e-3)
    assert gaits.fastest.frequency_hz <= 3.5  # the grid bounds the planner


def test_without_a_library_family_the_planner_says_so_and_uses_table1(tmp_path, make_planner):
    gaits = make_planner(gait_source='library', library_path=str(tmp_path / 'none.yaml')).gaits
    assert gaits.family.name == 'table1' and 'gait library not used' in gaits.family_note


def test_an_unknown_gait_source_is_refused(make_planner):
    with pytest.raises(ValueError, match='gait_source'):
        make_planner(gait_source='magic')


def test_on_a_grid_point_the_library_family_gives_the_stored_gait(library_file, make_planner):
    gaits = make_planner(gait_source='library', library_path=str(library_file)).gaits
    stored = locked_speed_estimate(table1_locked_at(1.5, 1.0), FishGeometry()).speed
    assert gaits.frontier_point(1.5).speed == pytest.approx(stored, rel=1e-6)
