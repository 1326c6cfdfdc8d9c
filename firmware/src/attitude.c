/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/attitude.h"

#include <math.h>

#define WF_PI 3.14159265358979f
#define WF_GRAVITY 9.80665f

static float wrap_pi(float angle)
{
    if (!(fabsf(angle) < 1e6f)) {
        return 0.0f; /* NaN or absurd: the loop below would never end */
    }
    while (angle >= WF_PI) {
        angle -= 2.0f * WF_PI;
    }
    while (angle < -WF_PI) {
        angle += 2.0f * WF_PI;
    }
    return angle;
}

void wf_attitude_reset(wf_attitude_t *att)
{
    att->initialised = false;
    att->roll = 0.0f;
    att->pitch = 0.0f;
    att->yaw = 0.0f;
}

void wf_attitude_update(wf_attitude_t *att, const float gyro[3], const float accel[3],
                        float dt_s, float tau_s)
{
    const float horizontal = sqrtf(accel[1] * accel[1] + accel[2] * accel[2]);
    const float norm = sqrtf(accel[0] * accel[0] + horizontal * horizontal);
    /* At rest the specific force in imu_link is R^T (0, 0, g) = g (-sin p, sin r cos p,
     * cos r cos p): roll and pitch follow from its direction. */
    const float roll_acc = atan2f(accel[1], accel[2]);
    const float pitch_acc = atan2f(-accel[0], horizontal);
    if (!att->initialised) {
        if (norm > 0.0f) {
            att->roll = roll_acc;
            att->pitch = pitch_acc;
            att->yaw = 0.0f;
            att->initialised = true;
        }
        return;
    }
    const float sr = sinf(att->roll);
    const float cr = cosf(att->roll);
    float cp = cosf(att->pitch);
    if (fabsf(cp) < 1e-3f) {
        cp = cp < 0.0f ? -1e-3f : 1e-3f; /* gimbal lock: keep the rates finite */
    }
    const float tp = sinf(att->pitch) / cp;
    const float up = sr * gyro[1] + cr * gyro[2];
    att->roll += (gyro[0] + up * tp) * dt_s;
    att->pitch += (cr * gyro[1] - sr * gyro[2]) * dt_s;
    att->yaw += up / cp * dt_s;
    if (norm > 0.8f * WF_GRAVITY && norm < 1.2f * WF_GRAVITY) {
        const float k = dt_s / (tau_s + dt_s);
        att->roll += k * wrap_pi(roll_acc - att->roll);
        att->pitch += k * (pitch_acc - att->pitch);
    }
    att->roll = wrap_pi(att->roll);
    att->yaw = wrap_pi(att->yaw);
    if (att->pitch > 0.5f * WF_PI) {
        att->pitch = 0.5f * WF_PI;
    } else if (att->pitch < -0.5f * WF_PI) {
        att->pitch = -0.5f * WF_PI;
    }
}
