/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Attitude filter: roll, pitch, yaw as PROTOCOL.md defines them (ZYX intrinsic Euler angles of
 * imu_link relative to ENU, R = Rz(yaw) Ry(pitch) Rx(roll)). A complementary filter: the gyro
 * propagates all three through the Euler-angle kinematics; roll and pitch are pulled toward the
 * gravity direction of the accelerometer with time constant tau (only while |accel| is near g:
 * a swimming fish's surge would tilt the estimate); yaw has no reference (no magnetometer): it
 * integrates the gyro, relative to power-up, and drifts with the gyro's bias.
 */
#ifndef WF_ATTITUDE_H
#define WF_ATTITUDE_H

#include <stdbool.h>

typedef struct {
    bool initialised;
    float roll, pitch, yaw;
} wf_attitude_t;

void wf_attitude_reset(wf_attitude_t *att);

/* Updates with one sample (FLU, SI) taken dt_s after the previous one. The first sample sets
 * roll and pitch from the accelerometer alone (yaw 0). */
void wf_attitude_update(wf_attitude_t *att, const float gyro[3], const float accel[3],
                        float dt_s, float tau_s);

#endif /* WF_ATTITUDE_H */
