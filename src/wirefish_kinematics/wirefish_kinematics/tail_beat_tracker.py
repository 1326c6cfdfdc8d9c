# SPDX-License-Identifier: Apache-2.0
"""
Tail-beat tracking over a live servo stream: when a speed estimate is due, and the tail's phase.

The kinematics node feeds every accepted servo sample into the tracker's ``history`` and calls
``update`` at each publish tick. The tracker finds the last full tail beat (``tail_beat``) at
most once per ``detection_period_s`` of sample time, so an estimate is at most that late and
the history is not re-scanned at every tick. It reports:

* one eq 16-22 estimate per new tail beat, stamped at the end of the beat;
* all zeros while the tail is at rest (tip half range below ``rest_half_range_m``), once the
  history spans ``max_period_s`` and then at most once per ``max_period_s``;
* the phase of y(q1)'s fundamental (paper eq 25 aligns at O1), for the desired-wave overlay.

Everything the node resets lives here, in two depths: ``reset`` (a new source) forgets
samples and beats, ``forget_beat`` (a new geometry) only the overlay's phase.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from wirefish_kinematics.body_wave import body_positions
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import SpeedEstimate, tail_tip_lateral_positions
from wirefish_kinematics.servo_history import ServoHistory
from wirefish_kinematics.tail_beat import (estimate_speed_over, fundamental_phase,
                                           last_tail_beat, TailBeat)
from wirefish_kinematics.wire_coupling import bend_angles

# Below this half range (m) of the tip's lateral motion the tail counts as at rest.
REST_HALF_RANGE_M = 1e-4
# The tail-beat search runs at most this often (s of sample time).
DETECTION_PERIOD_S = 0.1


@dataclass(frozen=True)
class SpeedReport:
    """An estimate to publish and the sample time (s, relative to the history) it is for."""

    estimate: SpeedEstimate
    time_s: float


class TailBeatTracker:
    """The servo history of the last two ``max_period_s`` and the tail beats found in it."""

    def __init__(self, max_period_s: float, detection_period_s: float = DETECTION_PERIOD_S,
                 rest_half_range_m: float = REST_HALF_RANGE_M) -> None:
        """Create an empty tracker detecting tail beats up to ``max_period_s`` long (s)."""
        self.history = ServoHistory(2.0 * max_period_s)
        self._max_period_s = float(max_period_s)
        self.detection_period_s = float(detection_period_s)
        self.rest_half_range_m = float(rest_half_range_m)
        self.reset()

    @property
    def max_period_s(self) -> float:
        """Return the longest tail-beat period detected (s); twice it is kept in history."""
        return self._max_period_s

    @max_period_s.setter
    def max_period_s(self, value: float) -> None:
        self._max_period_s = float(value)
        self.history.span_s = 2.0 * self._max_period_s

    @property
    def beat(self) -> TailBeat | None:
        """Return the last full tail beat found, or None (none yet, at rest, new geometry)."""
        return self._beat

    def reset(self) -> None:
        """Forget every sample and every tail beat (a new servo source)."""
        self.history.clear()
        self._last_beat_end: float | None = None
        self._last_rest_t: float | None = None
        self._last_detection_t: float | None = None
        self.forget_beat()

    def forget_beat(self) -> None:
        """Forget the overlay's tail beat, so that its phase is re-measured (a new geometry)."""
        self._beat: TailBeat | None = None
        self._beat_phase = 0.0  # phase (rad) of y(q1)'s fundamental at the beat's start

    def update(self, geometry: FishGeometry) -> SpeedReport | None:
        """
        Look for the last tail beat if ``detection_period_s`` has passed; return what is due.

        Returns the estimate of a tail beat not reported before, a zero estimate at rest, or
        None. A history empty or with time running backwards re-arms the detection at once.
        """
        if len(self.history) == 0:
            return None
        t = self.history.last_time()
        last = self._last_detection_t
        if last is not None and 0.0 <= t - last < self.detection_period_s:
            return None
        self._last_detection_t = t
        return self._detect(geometry)

    def phase_at(self, t: float) -> float | None:
        """Return the phase (rad) of y(q1)'s fundamental at sample time t (s), or None."""
        if self._beat is None:
            return None
        return self._beat_phase + 2.0 * math.pi * (t - self._beat.start) / self._beat.period

    def _detect(self, geometry: FishGeometry) -> SpeedReport | None:
        times, angles, rates = self.history.arrays()
        y_tip = tail_tip_lateral_positions(angles, geometry)
        beat = last_tail_beat(times, y_tip, self.rest_half_range_m)
        if beat is None:
            self._beat = None
            half_range = 0.5 * float(np.ptp(y_tip))
            span = self._max_period_s
            if (half_range < self.rest_half_range_m and self.history.duration_s() >= span
                    and (self._last_rest_t is None or times[-1] - self._last_rest_t >= span)):
                self._last_rest_t = float(times[-1])
                return SpeedReport(SpeedEstimate(0.0, 0.0, 0.0, 0.0, 0.0, half_range),
                                   float(times[-1]))
            return None
        report = None
        # The crossings move by a few ms as the history's range slides (they are interpolated
        # at its middle): the same beat found again is not a new one.
        if self._last_beat_end is None or beat.end - self._last_beat_end > 0.5 * beat.period:
            self._last_beat_end = beat.end
            report = SpeedReport(estimate_speed_over(times, angles, rates, beat.start, beat.end,
                                                     geometry), beat.end)
        if self._beat is None or self._beat.end != beat.end:
            beta1, beta2 = bend_angles(angles[:, 0], angles[:, 1], geometry)
            _, y_q1 = body_positions(np.array([geometry.l1]), beta1, beta2, geometry)
            self._beat = beat
            self._beat_phase = float(fundamental_phase(times, y_q1[:, 0], beat, beat.start))
        return report
