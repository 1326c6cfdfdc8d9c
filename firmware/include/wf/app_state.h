/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The application's state and configuration (see wf/app.h). Everything the firmware keeps is
 * in wf_app_t: no heap, no hidden statics in the core, so a test can run several boards.
 */
#ifndef WF_APP_STATE_H
#define WF_APP_STATE_H

#include <stdbool.h>
#include <stdint.h>

#include "wf/attitude.h"
#include "wf/calibration_store.h"
#include "wf/cpg.h"
#include "wf/hal.h"
#include "wf/health.h"
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
    /* The link settings at boot; LINK_CONFIG changes them (and telemetry_period_ms) in the
     * running copy, app.config, in the same ranges. */
    uint32_t health_period_ms;     /* 2000; 0: HEALTH only once, after boot */
    uint32_t link_timeout_ms;      /* 1500: gait mode, no valid host frame this long: COASTING */
    uint32_t coast_ms;             /* 3000: then RESTING */
    uint8_t telemetry_form;        /* wf_telemetry_form_t: FULL */
    float failsafe_slew_rad_s;     /* 2.0: stream mode's failsafe moves to neutral this fast */
} wf_config_t;

/* The decoder's drop counters that an ERROR reports, one per code (ERROR codes 1-4, 6), and
 * the shortest time between two ERRORs of one kind: 5 kinds of 11 bytes each every 20 ms take
 * at most 2.75 kB/s, so a flood of garbage never crowds the telemetry (6.2 kB/s) off 115200
 * baud. */
enum { WF_REPORTED_KINDS = 5, WF_ERROR_MIN_INTERVAL_MS = 20 };

/* ACKs wait here and go out one per poll, oldest first (a poll's output stays bounded); a
 * GAIT, LINK_CONFIG or SERVO_TRIM that finds the queue full gets no ACK (the host resends
 * it). An accepted SERVO_TRIM's ACK takes its SERVO_TRIM_REPORT with it, right after. */
enum { WF_ACK_QUEUE = 4 };

/* In gait mode a poll steps the CPG at most this many 1 ms steps: a larger backlog (a blocked
 * poll loop, an emulator descheduled by its host, the clock going back) is dropped, cpg_time
 * re-based to now minus this, the state kept: the gait pauses and goes on from where it
 * stood, never jumps. The output then moves by at most 5 ms of the gait's own motion within a
 * PWM frame, less than the gait itself moves in a 20 ms frame at 50 Hz (and the 5 steps
 * cost about 6 us of a Cortex-M4's 1 ms poll). A healthy loop polls every millisecond, a late poll
 * (an I2C bus recovery, a full RX chunk) a few ms late: up to 5 ms is caught up whole, so
 * the gait's frequency stays exact. */
enum { WF_CPG_MAX_LAG_MS = 5 };

/* Where gait mode is with the link: swimming, coasting (link lost) or resting (lost past the
 * coast). */
typedef enum { WF_GAP_NONE = 0, WF_GAP_COASTING = 1, WF_GAP_RESTING = 2 } wf_gap_t;

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
    uint32_t last_host_frame_ms;   /* the last valid frame of any host type */
    float commanded[WF_SERVO_COUNT];

    /* gait mode: the board integrates eq 1 itself */
    bool gait_mode;
    uint16_t gait_id;              /* the last accepted GAIT's id (0 in stream mode) */
    wf_cpg_params_t gait;          /* the last accepted GAIT's parameters */
    uint8_t gap;                   /* wf_gap_t */
    uint32_t cpg_time_ms;          /* the board time the CPG's state is at */
    wf_cpg_t cpg;

    /* acknowledgements waiting to be sent */
    wf_ack_t acks[WF_ACK_QUEUE];
    uint8_t ack_report[WF_ACK_QUEUE]; /* the servo (1, 2) whose report follows; 0 none */
    uint8_t ack_count;

    /* calibration: config.servo_cal holds the one in force (the next PWM write uses it) */
    wf_servo_cal_t cal_defaults[WF_SERVO_COUNT]; /* the build's (wf_app_init's config) */
    uint8_t cal_source[WF_SERVO_COUNT];          /* wf_cal_source_t */
    wf_cal_record_t cal_stored;  /* the storage's winning record (all zero: none) */
    uint32_t neutral_compare[WF_SERVO_COUNT]; /* 0 rad under the calibration in force: what
                                               * a port's fault path writes */
    uint32_t trims_accepted;
    uint32_t trims_refused;

    /* outputs */
    float target[WF_SERVO_COUNT];  /* after the failsafe and the clamp: what the PWM shows */
    uint32_t compare[WF_SERVO_COUNT];
    uint32_t last_output_ms;       /* the stream failsafe's slew: time of the last update */
    uint16_t status;

    /* schedule (ms of wf_hal_millis; every comparison is modular) */
    uint32_t now_ms;
    uint32_t next_telemetry_ms;
    uint32_t next_heartbeat_ms;
    uint32_t next_health_ms;
    bool health_sent;              /* the boot HEALTH is out */
    uint8_t boot_report;           /* the servo (1, 2) whose boot SERVO_TRIM_REPORT is due
                                    * next; 0: none (before the boot HEALTH, or all out) */
    uint32_t next_imu_ms;
    uint32_t next_imu_probe_ms;
    uint32_t last_imu_ms;
    bool imu_sampled;
    bool imu_lost;                 /* a read failed since the last successful probe */

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
    uint32_t tx_bytes_dropped;     /* bytes of the frames the transmit queue had no room for */
    uint32_t acks_dropped;         /* ACKs that found the queue full */
    uint32_t gaits_accepted;
    uint32_t gaits_refused;

    /* What HEALTH reports: the port's fields from wf_hal_health_port (at wf_app_init and
     * before each HEALTH), the core's (uptime, decoder and transmit drops, IMU faults and
     * recoveries) from its own counters. */
    wf_health_t health;
} wf_app_t;

/* True when every value of config is in range: timeouts and periods 1..2^31-1 ms, frame rate
 * 50..333 Hz, limit (0, pi], neutral (0, 20000] us, gain (0, 1e5] us/rad, direction +-1,
 * axes a rotation, a known IMU mode, tau (0, 1000] s, (0, 1] V per count, low battery
 * (-1, 100] V; the link settings in LINK_CONFIG's ranges (health 0 or 200..60000 ms, link
 * timeout 100..10000 ms, coast 0..60000 ms, form FULL or COMPACT), failsafe slew
 * (0, 1000] rad/s. */
bool wf_config_valid(const wf_config_t *config);

#endif /* WF_APP_STATE_H */
