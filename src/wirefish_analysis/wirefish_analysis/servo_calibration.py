# SPDX-License-Identifier: Apache-2.0
"""
The virtual fish's servo slew limit, read from the paper's frequency cap (section 5.4).

The paper gives no servo data. What it does say: "Since the performance of servomotors is
limited, we choose the maximum frequency of 3 Hz" for the speed grid of Figs 9-10 (tail-tip
half amplitudes 4-9 cm, 1-3 Hz; "the motion on large amplitude and high frequency can't be
achieved"). So the servos follow every gait of that grid, and the most demanding one, 9 cm at
3 Hz, is about as fast as they go. The slowest slew limit that still follows it is the peak
servo rate that gait commands: R_i * Omega of the locked network (9.03 rad/s, servo 2).
``ServoParameters.rate_limit_rad_s`` is that value rounded up to 0.1 rad/s (9.1 rad/s).

Fig 11 (5 cm, speed peaks at 6.5 Hz) is not used here: where the virtual fish's speed peaks is
a prediction of this calibration, checked by ``wirefish_analysis.fig11`` and the tests.

``python -m wirefish_analysis.servo_calibration`` prints the peak servo rate of every amplitude
of the grid at its top frequency and the slew limit they call for.
"""

from __future__ import annotations

import argparse
import math

from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import steady_state_phases
from wirefish_cpg.table1_gait import (PAPER_GRID_AMPLITUDES_M, PAPER_GRID_FREQUENCIES_HZ,
                                      table1_at_tip_amplitude)
from wirefish_kinematics.geometry import FishGeometry

ROUND_UP_TO_RAD_S = 0.1


def peak_servo_rates(params: CpgParameters) -> tuple[float, float]:
    """Return the peak |dTheta_i/dt| (rad/s) of the locked network: |R_i| * Omega (eq 1)."""
    _, omega = steady_state_phases(params)
    return abs(params.amplitude[0]) * omega, abs(params.amplitude[1]) * omega


def grid_peak_rates(geometry: FishGeometry | None = None
                    ) -> dict[float, tuple[float, float]]:
    """
    Return {tail-tip amplitude (m): peak servo rates (rad/s)} of the grid at its top frequency.

    The peak rate grows with amplitude and frequency, so the grid's highest need is at its top
    frequency (3 Hz); every amplitude is listed to show which one sets it.
    """
    geometry = geometry or FishGeometry()
    top = max(PAPER_GRID_FREQUENCIES_HZ)
    return {a: peak_servo_rates(table1_at_tip_amplitude(a, top, geometry))
            for a in PAPER_GRID_AMPLITUDES_M}


def slew_rate_the_paper_needs(rates: dict[float, tuple[float, float]] | None = None) -> float:
    """Return the highest peak servo rate (rad/s) of ``rates`` (default: grid_peak_rates())."""
    rates = grid_peak_rates() if rates is None else rates
    return max(max(pair) for pair in rates.values())


def rounded_up(rate: float) -> float:
    """Return ``rate`` (rad/s) rounded up to ROUND_UP_TO_RAD_S."""
    return math.ceil(rate / ROUND_UP_TO_RAD_S - 1e-9) * ROUND_UP_TO_RAD_S


def calibrated_rate_limit() -> float:
    """Return the slew limit (rad/s): the grid's need rounded up to 0.1 rad/s."""
    return rounded_up(slew_rate_the_paper_needs())


def main(argv: list[str] | None = None) -> int:
    """Print the peak servo rates of the grid's top frequency and the calibrated limit."""
    argparse.ArgumentParser(description=__doc__.split('\n\n')[0]).parse_args(argv)
    rates = grid_peak_rates()
    print(f"peak servo rates at {max(PAPER_GRID_FREQUENCIES_HZ):g} Hz (the paper's cap), "
          'Table 1 gait scaled:')
    for amplitude, (rate_1, rate_2) in rates.items():
        print(f'  {100 * amplitude:4.1f} cm: servo 1 {rate_1:5.2f} rad/s, '
              f'servo 2 {rate_2:5.2f} rad/s')
    need = slew_rate_the_paper_needs(rates)
    print(f'needed: {need:.3f} rad/s; calibrated slew limit: {rounded_up(need):.1f} rad/s')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
