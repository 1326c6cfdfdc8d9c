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
a prediction of this calibration, checked by ``wirefish_bridge.fig11`` and the tests.

``python -m wirefish_bridge.servo_calibration`` prints the peak servo rate of every amplitude
of the grid at its top frequency and the slew limit they call for.
"""

from __future__ import annotations

import argparse
import math

from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import steady_state_phases
from wirefish_cpg.table1_gait import (amplitude_scale_for, PAPER_GRID_AMPLITUDES_M,
                                      PAPER_GRID_FREQUENCIES_HZ, table1_locked_at)
from wirefish_kinematics.geometry import FishGeometry

ROUND_UP_TO_RAD_S = 0.1


def peak_servo_rates(params: CpgParameters) -> tuple[float, float]:
    """Return the peak |dTheta_i/dt| (rad/s) of the locked network: |R_i| * Omega (eq 1)."""
    _, omega = steady_state_phases(params)
    return abs(params.amplitude[0]) * omega, abs(params.amplitude[1]) * omega


def grid_gait(tip_amplitude_m: float, frequency_hz: float,
              geometry: FishGeometry) -> CpgParameters:
    """Return Table 1's gait scaled to this tail-tip half amplitude (m), locked at f (Hz)."""
    scale = amplitude_scale_for(tip_amplitude_m, frequency_hz, geometry)
    return table1_locked_at(frequency_hz, scale)


def slew_rate_the_paper_needs(geometry: FishGeometry | None = None) -> float:
    """
    Return the highest peak servo rate (rad/s) over the paper's Fig 9-10 grid.

    The peak rate grows with amplitude and frequency, so it is the 9 cm, 3 Hz gait's; all
    amplitudes are evaluated at the top frequency to show it.
    """
    geometry = geometry or FishGeometry()
    top = max(PAPER_GRID_FREQUENCIES_HZ)
    return max(max(peak_servo_rates(grid_gait(a, top, geometry)))
               for a in PAPER_GRID_AMPLITUDES_M)


def calibrated_rate_limit(geometry: FishGeometry | None = None) -> float:
    """Return the slew limit (rad/s): the grid's need rounded up to 0.1 rad/s."""
    need = slew_rate_the_paper_needs(geometry)
    return math.ceil(need / ROUND_UP_TO_RAD_S - 1e-9) * ROUND_UP_TO_RAD_S


def main(argv: list[str] | None = None) -> int:
    """Print the peak servo rates of the grid's top frequency and the calibrated limit."""
    argparse.ArgumentParser(description=__doc__.split('\n\n')[0]).parse_args(argv)
    geometry = FishGeometry()
    top = max(PAPER_GRID_FREQUENCIES_HZ)
    print(f"peak servo rates at {top:g} Hz (the paper's cap), Table 1 gait scaled:")
    for amplitude in PAPER_GRID_AMPLITUDES_M:
        rate_1, rate_2 = peak_servo_rates(grid_gait(amplitude, top, geometry))
        print(f'  {100 * amplitude:4.1f} cm: servo 1 {rate_1:5.2f} rad/s, '
              f'servo 2 {rate_2:5.2f} rad/s')
    print(f'needed: {slew_rate_the_paper_needs(geometry):.3f} rad/s; '
          f'calibrated slew limit: {calibrated_rate_limit(geometry):.1f} rad/s')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
