/* SPDX-License-Identifier: Apache-2.0 */
/* Servo output: angle (rad) -> pulse width (us) -> timer compare (ticks), per-servo calibration. */
#ifndef WF_SERVO_H
#define WF_SERVO_H

#include <stdbool.h>
#include <stdint.h>

/* One servo's calibration (firmware/README.md, "Calibration"): the pulse at 0 rad, the pulse
 * change per rad of reel angle, +1 or -1 for a servo mounted the other way round, and the
 * shortest and longest pulse the servo takes (its data sheet's range, 500-2500 us for a
 * 180-degree hobby servo). No pulse outside [min_us, max_us] is ever written, and a
 * configuration whose neutral +- gain x mechanical limit leaves that range is refused
 * (wf_servo_cal_fits). */
typedef struct {
    float neutral_us;
    float us_per_rad;
    int8_t direction;
    float min_us;
    float max_us;
} wf_servo_cal_t;

/* True when 0 < min_us < max_us <= frame_us and neutral_us +- us_per_rad * limit_rad lies
 * within [min_us, max_us]: every angle the clamp lets through maps to a pulse the servo takes.
 * False for a NaN anywhere. */
bool wf_servo_cal_fits(const wf_servo_cal_t *cal, float limit_rad, float frame_us);

/* Returns angle clamped to [-limit, limit] (the mechanical end stops). */
float wf_servo_clamp(float angle, float limit);

/* Returns the pulse width (us) of angle (already clamped), within [cal->min_us, cal->max_us]
 * and never above max_us (a pulse cannot outlast its frame). */
float wf_servo_pulse_us(const wf_servo_cal_t *cal, float angle, float max_us);

/* Returns the compare value: the pulse in timer ticks, rounded to the nearest tick. */
uint32_t wf_servo_compare(const wf_servo_cal_t *cal, float angle, uint32_t ticks_per_us,
                          float max_us);

#endif /* WF_SERVO_H */
