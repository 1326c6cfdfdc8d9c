/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/mpu6050.h"

#include <string.h>

#include "wf/hal.h"

static bool write_register(uint8_t reg, uint8_t value)
{
    const uint8_t tx[2] = {reg, value};
    return wf_hal_i2c_transfer(WF_MPU6050_ADDRESS, tx, sizeof tx, NULL, 0);
}

static bool read_registers(uint8_t reg, uint8_t *rx, size_t len)
{
    return wf_hal_i2c_transfer(WF_MPU6050_ADDRESS, &reg, 1, rx, len);
}

bool wf_mpu6050_axes_valid(const int8_t axes[3])
{
    int seen = 0;
    int m[3][3] = {{0}};
    for (int i = 0; i < 3; i++) {
        const int a = axes[i] < 0 ? -axes[i] : axes[i];
        if (a < 1 || a > 3 || (seen & (1 << a))) {
            return false;
        }
        seen |= 1 << a;
        m[i][a - 1] = axes[i] < 0 ? -1 : 1;
    }
    const int det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                    m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                    m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    return det == 1;
}

bool wf_mpu6050_known_id(uint8_t who_am_i)
{
    static const uint8_t known[WF_MPU6050_KNOWN_ID_COUNT] = WF_MPU6050_KNOWN_IDS;
    for (unsigned i = 0; i < WF_MPU6050_KNOWN_ID_COUNT; i++) {
        if (who_am_i == known[i]) {
            return true;
        }
    }
    return false;
}

/* What the driver writes, register after register from SMPLRT_DIV (0x19): 1 kHz / (1 + 4) =
 * 200 Hz sample rate; DLPF 44 Hz; the full scales. */
static const uint8_t configuration[4] = {0x04, 0x03, WF_MPU6050_FS_SEL << 3,
                                         WF_MPU6050_AFS_SEL << 3};
/* PWR_MGMT_1: awake (SLEEP is set at power-up) with the X gyro's PLL as clock (more stable
 * than the internal oscillator, the datasheet's recommendation). */
#define PWR_MGMT_1_VALUE 0x01u

static bool configuration_intact(void)
{
    uint8_t back[4];
    uint8_t power = 0;
    return read_registers(WF_MPU6050_SMPLRT_DIV, back, sizeof back) &&
           memcmp(back, configuration, sizeof back) == 0 &&
           read_registers(WF_MPU6050_PWR_MGMT_1, &power, 1) && power == PWR_MGMT_1_VALUE;
}

static void clear_values(wf_mpu6050_t *imu)
{
    memset(imu->raw_accel, 0, sizeof imu->raw_accel);
    memset(imu->raw_gyro, 0, sizeof imu->raw_gyro);
    memset(imu->accel, 0, sizeof imu->accel);
    memset(imu->gyro, 0, sizeof imu->gyro);
}

static bool lose(wf_mpu6050_t *imu)
{
    imu->present = false;
    clear_values(imu);
    return false;
}

bool wf_mpu6050_init(wf_mpu6050_t *imu)
{
    imu->present = false;
    imu->same_count = 0;
    imu->reads_since_check = 0;
    clear_values(imu);
    uint8_t who = 0;
    if (!read_registers(WF_MPU6050_WHO_AM_I, &who, 1) || !wf_mpu6050_known_id(who)) {
        return false;
    }
    imu->who_am_i = who;
    bool ok = write_register(WF_MPU6050_PWR_MGMT_1, PWR_MGMT_1_VALUE);
    for (unsigned i = 0; ok && i < sizeof configuration; i++) {
        ok = write_register((uint8_t)(WF_MPU6050_SMPLRT_DIV + i), configuration[i]);
    }
    ok = ok && configuration_intact();
    if (ok && imu->stuck) {
        uint8_t data[14];
        ok = read_registers(WF_MPU6050_ACCEL_XOUT_H, data, sizeof data) &&
             memcmp(data, imu->last_data, sizeof data) != 0;
        imu->stuck = !ok;
    }
    imu->present = ok;
    return ok;
}

static int16_t big_endian_i16(const uint8_t *p)
{
    return (int16_t)(uint16_t)((p[0] << 8) | p[1]);
}

static void remap(const int8_t axes[3], const float sensor[3], float out[3])
{
    for (int i = 0; i < 3; i++) {
        const int a = axes[i] < 0 ? -axes[i] : axes[i];
        out[i] = axes[i] < 0 ? -sensor[a - 1] : sensor[a - 1];
    }
}

bool wf_mpu6050_read(wf_mpu6050_t *imu, const int8_t axes[3])
{
    uint8_t rx[14]; /* accel x, y, z; temperature; gyro x, y, z */
    if (!read_registers(WF_MPU6050_ACCEL_XOUT_H, rx, sizeof rx)) {
        return lose(imu);
    }
    if (memcmp(rx, imu->last_data, sizeof rx) == 0) {
        if (++imu->same_count >= WF_MPU6050_STUCK_SAMPLES - 1) {
            imu->stuck = true;   /* STUCK_SAMPLES equal reads: this one and the ones before */
            return lose(imu);
        }
    } else {
        imu->same_count = 0;
        memcpy(imu->last_data, rx, sizeof rx);
    }
    if (++imu->reads_since_check >= WF_MPU6050_CHECK_PERIOD) {
        imu->reads_since_check = 0;
        if (!configuration_intact()) {
            return lose(imu);
        }
    }
    float accel[3];
    float gyro[3];
    for (int i = 0; i < 3; i++) {
        imu->raw_accel[i] = big_endian_i16(rx + 2 * i);
        imu->raw_gyro[i] = big_endian_i16(rx + 8 + 2 * i);
        accel[i] = (float)imu->raw_accel[i] * WF_MPU6050_ACCEL_M_S2_PER_LSB;
        gyro[i] = (float)imu->raw_gyro[i] * WF_MPU6050_GYRO_RAD_S_PER_LSB;
    }
    remap(axes, accel, imu->accel);
    remap(axes, gyro, imu->gyro);
    return true;
}
