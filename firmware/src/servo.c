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

float wf_servo_pulse_us(const wf_servo_cal_t *cal, float angle, float max_us)
{
    const float pulse = cal->neutral_us + (float)cal->direction * cal->us_per_rad * angle;
    if (!(pulse > 0.0f)) {
        return 0.0f;
    }
    return pulse < max_us ? pulse : max_us;
}

uint32_t wf_servo_compare(const wf_servo_cal_t *cal, float angle, uint32_t ticks_per_us,
                          float max_us)
{
    /* Bounded by the frame (<= 20000 us) times the tick rate: always within a u32. */
    return (uint32_t)(wf_servo_pulse_us(cal, angle, max_us) * (float)ticks_per_us + 0.5f);
}
