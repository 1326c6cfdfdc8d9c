/* Servo output: angle (rad) -> pulse width (us) -> timer compare (ticks), per-servo calibration. */
#ifndef WF_SERVO_H
#define WF_SERVO_H

#include <stdint.h>

/* One servo's calibration (firmware/README.md, "Calibration"): the pulse at 0 rad, the pulse
 * change per rad of reel angle, and +1 or -1 for a servo mounted the other way round. */
typedef struct {
    float neutral_us;
    float us_per_rad;
    int8_t direction;
} wf_servo_cal_t;

/* Returns angle clamped to [-limit, limit] (the mechanical end stops). */
float wf_servo_clamp(float angle, float limit);

/* Returns the pulse width (us) of angle (already clamped), within [0, max_us] (a pulse
 * cannot outlast its frame). */
float wf_servo_pulse_us(const wf_servo_cal_t *cal, float angle, float max_us);

/* Returns the compare value: the pulse in timer ticks, rounded to the nearest tick. */
uint32_t wf_servo_compare(const wf_servo_cal_t *cal, float angle, uint32_t ticks_per_us,
                          float max_us);

#endif /* WF_SERVO_H */
