"""
Calibrate the effective drag coefficient C_D of eq 17 on the paper, and check it.

``python -m wirefish_analysis.calibrate_drag`` chooses C_D so that eq 18 gives the paper's
0.39 m/s (section 5.3, Fig 8) at a 3 Hz tail beat with the steady-state output of the Table 1
CPG (eq 1 locked, servo angle = CPG output), on the default (estimated) geometry. eq 18 solved
for C_D is closed form: C_D = A(L_T) (<(dy/dt)^2> / U^2 - <(dy/dq)^2>) / S_c.

It then predicts the paper's other points with that C_D, scaling both Table 1 amplitudes R_i by
one factor until the tail tip's half amplitude is the stated one, and prints them beside the
paper's figures: 6.5 Hz at 5 cm (0.54 m/s, section 5.4 / Fig 11) and 1 Hz at 9 cm
(Sw about 0.33, Fig 10). The aim is the paper's own simulation-vs-experiment RMSE, 0.045 m/s.

"At f Hz" means the locked tail-beat frequency is f: the intrinsic v of eq 1 is chosen so that
the coupled network turns at f (coupling shifts it, e.g. v = 1 Hz locks at 1.0055 Hz).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, replace
import sys

import numpy as np
from wirefish_cpg.table1_gait import (amplitude_scale_for, locked_speed_estimate,
                                      one_locked_period, table1_locked_at, tip_half_amplitude)
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import (drag_coefficient_for_speed, SpeedEstimate,
                                           tail_tip_velocity_and_slope)

CALIBRATION_HZ = 3.0
CALIBRATION_SPEED = 0.39  # m/s, section 5.3 (Fig 8b)
PAPER_RMSE = 0.045  # m/s, the paper's simulation-vs-experiment RMSE (section 5.4)


@dataclass(frozen=True)
class PaperPoint:
    """A point of the paper: frequency (Hz), stated tip half amplitude (m) or None, speed."""

    label: str
    frequency_hz: float
    tip_amplitude: float | None  # None: Table 1's own amplitudes
    paper_speed: float  # m/s


PAPER_POINTS = (
    PaperPoint('3 Hz, Table 1 (calibration)', 3.0, None, CALIBRATION_SPEED),
    PaperPoint('6.5 Hz at 5 cm', 6.5, 0.05, 0.54),
    PaperPoint('1 Hz at 9 cm (Sw 0.33)', 1.0, 0.09, 0.33 * 1.0 * FishGeometry().body_length),
)


def calibrated_drag_coefficient(geometry: FishGeometry = FishGeometry(),
                                frequency_hz: float = CALIBRATION_HZ,
                                speed: float = CALIBRATION_SPEED) -> float:
    """Return the C_D for which eq 18 gives ``speed`` with Table 1 locked at frequency_hz."""
    angles, rates, _ = one_locked_period(table1_locked_at(frequency_hz))
    velocity, slope = tail_tip_velocity_and_slope(angles, rates, geometry)
    return drag_coefficient_for_speed(speed, float(np.mean(velocity ** 2)),
                                      float(np.mean(slope ** 2)), geometry)


@dataclass(frozen=True)
class Prediction:
    """A paper point with the model's prediction beside it."""

    point: PaperPoint
    amplitude_scale: float
    estimate: SpeedEstimate


def predict(point: PaperPoint, geometry: FishGeometry) -> Prediction:
    """Return the model's estimate at ``point`` (amplitudes scaled to its tip amplitude)."""
    scale = (1.0 if point.tip_amplitude is None
             else amplitude_scale_for(point.tip_amplitude, point.frequency_hz, geometry))
    params = table1_locked_at(point.frequency_hz, scale)
    result = replace(locked_speed_estimate(params, geometry),
                     tail_tip_amplitude=tip_half_amplitude(params, geometry))
    return Prediction(point=point, amplitude_scale=scale, estimate=result)


def report(geometry: FishGeometry) -> str:
    """Return the printed report: C_D, the 1 Hz tip amplitude and the paper points."""
    c_d = calibrated_drag_coefficient(geometry)
    calibrated = replace(geometry, drag_coefficient=c_d)
    lines = [f'calibrated C_D = {c_d:.9f} (eq 18: {CALIBRATION_SPEED} m/s at '
             f'{CALIBRATION_HZ:g} Hz, Table 1 steady state; default geometry, estimated)',
             f'FishGeometry default C_D = {FishGeometry().drag_coefficient:.9f}'
             + ('' if abs(FishGeometry().drag_coefficient - c_d) <= 1e-6
                else '  <-- differs: update CALIBRATED_DRAG_COEFFICIENT'),
             'Table 1 steady state at 1 Hz: tail-tip half amplitude '
             f'{100 * tip_half_amplitude(table1_locked_at(1.0), calibrated):.2f} cm '
             '(acceptance: 4-9 cm)',
             '',
             f'{"paper point":30s} {"R scale":>8s} {"tip amp":>8s} {"U model":>8s} '
             f'{"U paper":>8s} {"miss":>8s} {"Sw model":>8s} {"Sw paper":>8s}']
    for point in PAPER_POINTS:
        p = predict(point, calibrated)
        e = p.estimate
        paper_sw = point.paper_speed / (point.frequency_hz * geometry.body_length)
        lines.append(f'{point.label:30s} {p.amplitude_scale:8.4f} '
                     f'{100 * e.tail_tip_amplitude:6.2f}cm {e.speed:6.3f}m/s '
                     f'{point.paper_speed:6.3f}m/s {e.speed - point.paper_speed:+8.3f} '
                     f'{e.swimming_number:8.3f} {paper_sw:8.3f}')
    lines.append(f'(aim: |miss| <= {PAPER_RMSE} m/s, the paper sim-vs-experiment RMSE)')
    return '\n'.join(lines)


def main(argv: list[str] | None = None) -> int:
    """Print the calibration and the paper points."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.parse_args(argv)
    print(report(FishGeometry()))
    return 0


if __name__ == '__main__':
    sys.exit(main())
