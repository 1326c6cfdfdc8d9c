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

bool wf_mpu6050_init(wf_mpu6050_t *imu)
{
    memset(imu, 0, sizeof *imu);
    uint8_t who = 0;
    if (!read_registers(WF_MPU6050_WHO_AM_I, &who, 1) || who != WF_MPU6050_WHO_AM_I_VALUE) {
        return false;
    }
    /* Wake up (SLEEP is set at power-up) with the X gyro's PLL as clock (more stable than the
     * internal oscillator, the datasheet's recommendation); DLPF 44 Hz; 1 kHz / (1 + 4) =
     * 200 Hz sample rate; the full scales. */
    imu->present = write_register(WF_MPU6050_PWR_MGMT_1, 0x01) &&
                   write_register(WF_MPU6050_CONFIG, 0x03) &&
                   write_register(WF_MPU6050_SMPLRT_DIV, 0x04) &&
                   write_register(WF_MPU6050_GYRO_CONFIG, WF_MPU6050_FS_SEL << 3) &&
                   write_register(WF_MPU6050_ACCEL_CONFIG, WF_MPU6050_AFS_SEL << 3);
    return imu->present;
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
        memset(imu, 0, sizeof *imu);
        return false;
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
