/*
 * MPU6050 driver over wf_hal_i2c_transfer (register map: InvenSense RM-MPU-6000A-00 rev 4.2).
 * Configures +-500 deg/s and +-4 g, reads the 14 data bytes from ACCEL_XOUT_H (0x3B) in one
 * burst (big-endian, two's complement), scales to SI and turns the sensor's axes into the
 * FLU imu_link frame with the mounting given as a signed axis map.
 */
#ifndef WF_MPU6050_H
#define WF_MPU6050_H

#include <stdbool.h>
#include <stdint.h>

#define WF_MPU6050_ADDRESS 0x68u /* AD0 low */
#define WF_MPU6050_WHO_AM_I 0x75u
#define WF_MPU6050_WHO_AM_I_VALUE 0x68u
#define WF_MPU6050_SMPLRT_DIV 0x19u
#define WF_MPU6050_CONFIG 0x1Au
#define WF_MPU6050_GYRO_CONFIG 0x1Bu
#define WF_MPU6050_ACCEL_CONFIG 0x1Cu
#define WF_MPU6050_ACCEL_XOUT_H 0x3Bu
#define WF_MPU6050_PWR_MGMT_1 0x6Bu

/* Full scales chosen: FS_SEL 1 (65.5 LSB per deg/s), AFS_SEL 1 (8192 LSB per g). */
#define WF_MPU6050_FS_SEL 1u
#define WF_MPU6050_AFS_SEL 1u
#define WF_STANDARD_GRAVITY 9.80665
#define WF_MPU6050_GYRO_RAD_S_PER_LSB ((float)(3.14159265358979323846 / 180.0 / 65.5))
#define WF_MPU6050_ACCEL_M_S2_PER_LSB ((float)(WF_STANDARD_GRAVITY / 8192.0))

typedef struct {
    bool present;
    int16_t raw_accel[3]; /* sensor axes */
    int16_t raw_gyro[3];
    float accel[3];       /* m/s^2, FLU imu_link (specific force) */
    float gyro[3];        /* rad/s, FLU imu_link */
} wf_mpu6050_t;

/* True when axes is a rotation of the sensor's axes: each of +-1, +-2, +-3 (sensor x, y, z,
 * sign) once, with determinant +1 (a mirror would turn FLU into a left-handed frame). */
bool wf_mpu6050_axes_valid(const int8_t axes[3]);

/* Probes WHO_AM_I and configures the sensor; returns present. */
bool wf_mpu6050_init(wf_mpu6050_t *imu);

/* Reads one sample into imu (FLU: out[i] = sign(axes[i]) * sensor[|axes[i]| - 1]); false on
 * a bus error (then present is cleared and the values are zero). */
bool wf_mpu6050_read(wf_mpu6050_t *imu, const int8_t axes[3]);

#endif /* WF_MPU6050_H */
