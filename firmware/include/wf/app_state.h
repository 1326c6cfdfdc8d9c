/*
 * The application's state and configuration (see wf/app.h). Everything the firmware keeps is
 * in wf_app_t: no heap, no hidden statics in the core, so a test can run several boards.
 */
#ifndef WF_APP_STATE_H
#define WF_APP_STATE_H

#include <stdbool.h>
#include <stdint.h>

#include "wf/attitude.h"
#include "wf/hal.h"
#include "wf/mpu6050.h"
#include "wf/servo.h"
#include "wf/wire.h"

/* Where the IMU values come from. SYNTHETIC is for boards or emulators without the sensor: a
 * level fish at rest (accel 0, 0, +g; gyro 0), with IMU_FAULT set so that no consumer takes
 * it for a measurement (the bridge publishes it with covariance -1). */
typedef enum { WF_IMU_MPU6050 = 0, WF_IMU_SYNTHETIC = 1 } wf_imu_mode_t;

typedef struct {
    uint32_t command_timeout_ms;   /* neutral after this long without SERVO_CMD (500) */
    uint32_t heartbeat_timeout_ms; /* neutral after this long without a host HEARTBEAT (1500) */
    uint32_t telemetry_period_ms;  /* 10: 100 Hz */
    uint32_t heartbeat_period_ms;  /* 500: 2 Hz */
    uint32_t imu_period_ms;        /* 5: the IMU and the filter at 200 Hz */
    uint32_t servo_frame_hz;       /* PWM frame rate, 50..333 Hz */
    float servo_limit_rad;         /* mechanical limit, +-rad */
    wf_servo_cal_t servo_cal[WF_SERVO_COUNT];
    int8_t imu_axes[3];            /* FLU axis i = sign * sensor axis |imu_axes[i]| (1 x .. 3 z) */
    uint8_t imu_mode;              /* wf_imu_mode_t */
    float attitude_tau_s;          /* complementary filter's time constant for roll, pitch */
    float battery_v_per_count;     /* ADC count -> battery volts (reference and divider) */
    float low_battery_v;           /* LOW_BATTERY below this */
} wf_config_t;

/* The decoder's drop counters that an ERROR reports, one per code (ERROR codes 1-4, 6), and
 * the shortest time between two ERRORs of one kind: 5 kinds of 11 bytes each every 20 ms take
 * at most 2.75 kB/s, so a flood of garbage never crowds the telemetry (6.2 kB/s) off 115200
 * baud. */
enum { WF_REPORTED_KINDS = 5, WF_ERROR_MIN_INTERVAL_MS = 20 };

typedef struct {
    wf_config_t config;
    bool config_rejected;          /* wf_app_init was given an invalid config: defaults used */
    wf_decoder_t decoder;
    uint16_t tx_seq;

    /* link */
    bool host_seen;                /* a host HEARTBEAT (the hello) has arrived */
    bool host_version_ok;          /* the last host HEARTBEAT announced our version */
    bool have_command;             /* a SERVO_CMD within the command timeout */
    bool have_heartbeat;           /* a host HEARTBEAT within the heartbeat timeout */
    uint32_t last_command_ms;
    uint32_t last_heartbeat_ms;
    float commanded[WF_SERVO_COUNT];

    /* outputs */
    float target[WF_SERVO_COUNT];  /* after the failsafe and the clamp: what the PWM shows */
    uint32_t compare[WF_SERVO_COUNT];
    uint16_t status;

    /* schedule (ms of wf_hal_millis; every comparison is modular) */
    uint32_t now_ms;
    uint32_t next_telemetry_ms;
    uint32_t next_heartbeat_ms;
    uint32_t next_imu_ms;
    uint32_t next_imu_probe_ms;
    uint32_t last_imu_ms;
    bool imu_sampled;

    /* sensors */
    wf_mpu6050_t imu;
    wf_attitude_t attitude;
    bool have_battery;
    float battery_v;

    /* counters */
    uint32_t reported[WF_REPORTED_KINDS];
    uint32_t report_due_ms[WF_REPORTED_KINDS];
    uint32_t commands_applied;
    uint32_t commands_ignored;     /* SERVO_CMD while the host's version differs */
    uint32_t frames_sent;
    uint32_t errors_sent;
    uint32_t tx_bytes_dropped;     /* bytes the UART's transmit queue had no room for */
} wf_app_t;

/* True when every value of config is in range: timeouts and periods 1..2^31-1 ms, frame rate
 * 50..333 Hz, limit (0, pi], neutral (0, 20000] us, gain (0, 1e5] us/rad, direction +-1,
 * axes a rotation, a known IMU mode, tau (0, 1000] s, (0, 1] V per count, low battery
 * (-1, 100] V. */
bool wf_config_valid(const wf_config_t *config);

#endif /* WF_APP_STATE_H */
