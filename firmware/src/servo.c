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

float wf_servo_pulse_us(const wf_servo_cal_t *cal, float angle)
{
    const float pulse = cal->neutral_us + (float)cal->direction * cal->us_per_rad * angle;
    return pulse > 0.0f ? pulse : 0.0f;
}

uint32_t wf_servo_compare(const wf_servo_cal_t *cal, float angle, uint32_t ticks_per_us)
{
    return (uint32_t)(wf_servo_pulse_us(cal, angle) * (float)ticks_per_us + 0.5f);
}
