/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/servo.h"

float wf_servo_clamp(float angle, float limit)
{
    if (angle > limit) {
        return limit;
    }
    if (angle < -limit) {
        return -limit;
    }
    return angle;
}

bool wf_servo_cal_fits(const wf_servo_cal_t *cal, float limit_rad, float frame_us)
{
    const float swing = cal->us_per_rad * limit_rad;
    return cal->min_us > 0.0f && cal->min_us < cal->max_us && cal->max_us <= frame_us &&
           cal->neutral_us - swing >= cal->min_us && cal->neutral_us + swing <= cal->max_us;
}

float wf_servo_pulse_us(const wf_servo_cal_t *cal, float angle, float max_us)
{
    const float pulse = cal->neutral_us + (float)cal->direction * cal->us_per_rad * angle;
    const float high = cal->max_us < max_us ? cal->max_us : max_us;
    if (!(pulse > cal->min_us)) {
        return cal->min_us > 0.0f && cal->min_us < high ? cal->min_us : 0.0f; /* NaN too */
    }
    return pulse < high ? pulse : high;
}

uint32_t wf_servo_compare(const wf_servo_cal_t *cal, float angle, uint32_t ticks_per_us,
                          float max_us)
{
    /* Bounded by the frame (<= 20000 us) times the tick rate: always within a u32. */
    return (uint32_t)(wf_servo_pulse_us(cal, angle, max_us) * (float)ticks_per_us + 0.5f);
}
