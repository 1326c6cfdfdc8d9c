# SPDX-License-Identifier: Apache-2.0
"""plot_body_wave writes the Fig 7(b-d) PNGs and the swing-angle RMSEs."""

import pytest
from wirefish_analysis.plot_body_wave import (main, TABLE1_AMPLITUDES,
                                              TABLE1_PHASE_DIFFERENCE, write_figures)
from wirefish_kinematics.geometry import FishGeometry


def test_writes_both_figures(tmp_path):
    assert main(['--out', str(tmp_path), '--snapshots', '4']) == 0
    for name in ('fig7bc_swing_angles.png', 'fig7d_tail_period.png'):
        assert (tmp_path / name).stat().st_size > 10_000


def test_table1_swing_angle_rmse_is_the_one_the_cpg_package_reports(tmp_path):
    rmse = write_figures(tmp_path, FishGeometry(), TABLE1_AMPLITUDES, TABLE1_PHASE_DIFFERENCE,
                         (0.15, 1.0, 8.0, 1.0), snapshots=2)
    assert rmse == pytest.approx((2.27, 2.11), abs=0.01)  # paper: 1.7165, 1.2817 deg
