/* SPDX-License-Identifier: Apache-2.0 */
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
#define WF_MPU6050_SMPLRT_DIV 0x19u
#define WF_MPU6050_CONFIG 0x1Au
#define WF_MPU6050_GYRO_CONFIG 0x1Bu
#define WF_MPU6050_ACCEL_CONFIG 0x1Cu
#define WF_MPU6050_ACCEL_XOUT_H 0x3Bu
#define WF_MPU6050_PWR_MGMT_1 0x6Bu

/* The WHO_AM_I answers of the parts that share the registers this driver uses (0x19-0x1C,
 * 0x3B-0x48, 0x6B, 0x75, with the same FS_SEL / AFS_SEL coding), all sold on "MPU6050"
 * breakout boards: 0x68 MPU-6050 and MPU-6000, 0x70 MPU-6500, 0x71 MPU-9250, 0x73 MPU-9255,
 * 0x98 ICM-20689. Anything else reads as absent (firmware/README.md lists them too). */
#define WF_MPU6050_KNOWN_IDS {0x68u, 0x70u, 0x71u, 0x73u, 0x98u}
enum { WF_MPU6050_KNOWN_ID_COUNT = 5 };

/* A sensor is not trusted, only checked: the 14 data bytes unchanged over STUCK_SAMPLES reads in
 * a row (100 ms at 200 Hz: a live sensor's noise changes the gyro's low bits at every sample)
 * say it stopped (a sensor reset leaves it asleep, its data frozen); and every CHECK_PERIOD
 * reads its configuration registers are read back: a reset sensor has lost them. Either makes
 * wf_mpu6050_read fail like a bus error (present cleared): the core flags IMU_FAULT, counts an
 * IMU fault and probes again, and wf_mpu6050_init does not accept data still equal to the
 * stuck sample. */
enum { WF_MPU6050_STUCK_SAMPLES = 20, WF_MPU6050_CHECK_PERIOD = 20 };

/* Full scales chosen: FS_SEL 1 (65.5 LSB per deg/s), AFS_SEL 1 (8192 LSB per g). */
#define WF_MPU6050_FS_SEL 1u
#define WF_MPU6050_AFS_SEL 1u
#define WF_STANDARD_GRAVITY 9.80665
#define WF_MPU6050_GYRO_RAD_S_PER_LSB ((float)(3.14159265358979323846 / 180.0 / 65.5))
#define WF_MPU6050_ACCEL_M_S2_PER_LSB ((float)(WF_STANDARD_GRAVITY / 8192.0))

typedef struct {
    bool present;         /* answered, configured, data moving: trusted */
    bool stuck;           /* the last fault was frozen data: init wants a different sample */
    uint8_t who_am_i;     /* the part that answered (one of WF_MPU6050_KNOWN_IDS) */
    uint8_t last_data[14];
    uint16_t same_count;  /* reads in a row with data equal to last_data */
    uint16_t reads_since_check;
    int16_t raw_accel[3]; /* sensor axes */
    int16_t raw_gyro[3];
    float accel[3];       /* m/s^2, FLU imu_link (specific force) */
    float gyro[3];        /* rad/s, FLU imu_link */
} wf_mpu6050_t;

/* True when axes is a rotation of the sensor's axes: each of +-1, +-2, +-3 (sensor x, y, z,
 * sign) once, with determinant +1 (a mirror would turn FLU into a left-handed frame). */
bool wf_mpu6050_axes_valid(const int8_t axes[3]);

/* True for a WHO_AM_I value of WF_MPU6050_KNOWN_IDS. */
bool wf_mpu6050_known_id(uint8_t who_am_i);

/* Probes WHO_AM_I, configures the sensor and reads the configuration back; after a stuck fault
 * also takes one sample, which must differ from the stuck one. Returns present. The values
 * are zero afterwards; the fault state (stuck, its sample) is kept. */
bool wf_mpu6050_init(wf_mpu6050_t *imu);

/* Reads one sample into imu (FLU: out[i] = sign(axes[i]) * sensor[|axes[i]| - 1]); false on
 * a bus error, on data stuck for WF_MPU6050_STUCK_SAMPLES reads, or on a configuration lost
 * (then present is cleared and the values are zero). */
bool wf_mpu6050_read(wf_mpu6050_t *imu, const int8_t axes[3]);

#endif /* WF_MPU6050_H */
