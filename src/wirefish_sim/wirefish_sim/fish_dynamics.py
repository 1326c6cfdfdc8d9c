"""
Surge and yaw dynamics of the virtual fish (pure functions; SI units).

Surge: (m + m_added) dU/dt = s (F_T(t) - F_D(U)), with F_T the instantaneous Lighthill thrust
(the integrand of eq 16, from the kinematics core) and F_D the drag of eq 17. The factor s
scales thrust and drag alike, so the steady mean speed (where the period mean of F_T equals
F_D, i.e. eq 18) does not depend on it; only the transient does. With the paper's effective
drag (C_D rho S_c ~ 140 kg/m) the unscaled time constant M / (C_D rho S_c U) is ~0.07 s at
0.39 m/s, far quicker than a 3.6 kg body accelerates in water. The linearised time constant
is M / (s C_D rho S_c U): it grows as 1/U, so a constant s would give 0.75 s at 0.39 m/s but
4 s at 0.07 m/s (1 Hz). s is therefore set from the current speed (floored at
``speed_floor``), s = M / (tau C_D rho S_c max(U, floor)), which gives the same realistic time
constant tau (0.5-1 s) at every speed (``force_scale_for_time_constant``). s varies with U
only by the speed ripple within a tail beat (~1 %), so the period means of s F_T and s F_D
still balance exactly where F_T = F_D.

Yaw: a model assumption (the paper has none): the yaw rate relaxes with ``time_constant`` to
-gain U y_tip / L (gain 20 by default), where y_tip is the tail tip's lateral offset (+ = right
in C0). A tail held to the right turns the fish right (negative yaw about z up); the beating
part of y_tip averages out and leaves the head's small yaw oscillation.
"""

from __future__ import annotations

import math

GRAVITY = 9.80665  # m/s^2, standard gravity


def force_scale_for_time_constant(total_mass: float, time_constant: float, speed: float,
                                  speed_floor: float, drag_coefficient: float,
                                  water_density: float, wetted_area: float) -> float:
    """
    Return s such that the surge time constant at ``speed`` is ``time_constant``.

    Linearising s F_D (eq 17) about U gives d(s F_D)/dU = s C_D rho S_c U, hence
    tau = M / (s C_D rho S_c U) and s = M / (tau C_D rho S_c max(|U|, floor)). (The thrust's
    -U^2 (dy/dq)^2 term adds a few percent to the damping; it is left out of this choice.)
    """
    return total_mass / (time_constant * drag_coefficient * water_density * wetted_area
                         * max(abs(speed), speed_floor))


def surge_acceleration(thrust: float, drag: float, total_mass: float,
                       force_scale: float) -> float:
    """Return dU/dt (m/s^2) = s (F_T - F_D) / (m + m_added): the surge equation above."""
    return force_scale * (thrust - drag) / total_mass


def yaw_acceleration(yaw_rate: float, tail_tip_offset: float, speed: float, gain: float,
                     time_constant: float, body_length: float) -> float:
    """Return d(yaw rate)/dt (rad/s^2) of the yaw model above (a model assumption)."""
    target = -gain * speed * tail_tip_offset / body_length
    return (target - yaw_rate) / time_constant


def wrap_angle(angle: float) -> float:
    """Return ``angle`` wrapped into [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
