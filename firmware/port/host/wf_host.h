/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The host port's controls: what a test (C, or Python through ctypes) or the wirefish-fw-host
 * program sets and reads around the core. One board per process (the HAL is global, as a
 * board's peripherals are); wf_host_reset() gives a fresh one.
 */
#ifndef WF_HOST_H
#define WF_HOST_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wf/app.h"
#include "wf/cpg.h"
#include "wf/health.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An I2C device model: one transaction as wf_hal_i2c_transfer describes it. */
typedef bool (*wf_host_i2c_fn)(void *context, uint8_t address7, const uint8_t *tx,
                               size_t tx_len, uint8_t *rx, size_t rx_len);

enum { WF_HOST_RX_CAPACITY = 4096, WF_HOST_TX_CAPACITY = 65536 };

/* Clock 0, empty queues, compares 0, no I2C device (every transfer NACKs), ADC 3392 counts
 * (8.2 V with the default divider), PWM not started. */
void wf_host_reset(void);

void wf_host_set_millis(uint32_t now_ms);
void wf_host_set_i2c_device(wf_host_i2c_fn device, void *context);
void wf_host_set_adc_raw(int32_t raw);
/* Limits the transmit queue (bytes, <= WF_HOST_TX_CAPACITY) to model a slow UART. */
void wf_host_set_tx_capacity(size_t capacity);

/* Queues received bytes; returns how many fitted. */
size_t wf_host_feed(const uint8_t *data, size_t len);
/* Moves up to max transmitted bytes out; returns how many. */
size_t wf_host_take_output(uint8_t *out, size_t max);

uint32_t wf_host_compare(unsigned servo);
uint32_t wf_host_pwm_frame_hz(void);

/* The I2C lines as open-drain GPIO, for the bus recovery (wf/i2c_bus.h): the model answers
 * one operation at a time; the READ operations return the line's level (0 low, 1 high). With
 * no lines set the bus always reads idle. */
enum {
    WF_HOST_SCL_LOW = 0,
    WF_HOST_SCL_RELEASE = 1,
    WF_HOST_SDA_LOW = 2,
    WF_HOST_SDA_RELEASE = 3,
    WF_HOST_READ_SCL = 4,
    WF_HOST_READ_SDA = 5,
    WF_HOST_HALF_BIT = 6,
};
typedef int (*wf_host_i2c_lines_fn)(void *context, int op);
void wf_host_set_i2c_lines(wf_host_i2c_lines_fn lines, void *context);

/* The stm32f4 port's reset path, modelled. wf_host_reset is a power cycle (reset flags POR,
 * BOR, PIN; no record). wf_host_fault does what the port's fault handler does (both compares
 * to the failsafe values, the record saved, a software reset requested); wf_host_watchdog_reset
 * what the IWDG does; wf_host_set_reset_flags sets RCC_CSR's flags (wf/fault_record.h) for the
 * next boot. wf_host_boot is the port's start-up (reset cause from the flags and the record,
 * flags cleared, I2C bus recovery): wf_host_board_init calls it before wf_app_init, and then
 * gives the neutral compares to wf_host_set_failsafe_compares as the port's main does. */
void wf_host_boot(void);
void wf_host_fault(uint32_t pc, uint32_t lr, uint32_t cfsr, uint32_t hfsr);
void wf_host_watchdog_reset(void);
void wf_host_set_reset_flags(uint32_t flags);
void wf_host_set_failsafe_compares(const uint32_t compare[WF_SERVO_COUNT]);
void wf_host_set_uart_overruns(uint32_t count);
/* The clock source the next boot reaches (wf_clock_source_t; EMULATED after wf_host_reset):
 * HSI_PLL or HSI model the stm32f4 port's fallback from a dead crystal. */
void wf_host_set_clock_source(uint8_t source);

/* The calibration's storage (wf_hal_storage_*): one 16 KB unit, the size of the stm32f4
 * port's flash sector, with flash's rules (erase sets every byte 0xFF, programming clears bits
 * only). It outlives wf_host_reset and wf_host_board_init (a power cycle keeps flash); it lives
 * in RAM unless wf_host_storage_use_file names a file, which it is then read from (absent:
 * erased; shorter: erased past its end) and written back to, whole, at each erase and program.
 * wf_host_storage_clear: an erased unit in RAM, no file, no fault, counts 0. A fault stays
 * until set back to WF_HOST_STORAGE_OK. peek and poke read and write bytes as they are
 * (poke: no flash rule, to damage a record); both return how many bytes they moved. */
enum { WF_HOST_STORAGE_SIZE = 16384 };
typedef enum {
    WF_HOST_STORAGE_OK = 0,
    WF_HOST_STORAGE_FAIL_ERASE = 1,   /* erase returns false, nothing erased */
    WF_HOST_STORAGE_FAIL_PROGRAM = 2, /* program returns false, nothing programmed */
    WF_HOST_STORAGE_CUT_PROGRAM = 3,  /* the first half of the words programmed, then false */
    WF_HOST_STORAGE_STUCK_BITS = 4,   /* program returns true but the first byte stays
                                       * 0xFF: only a read-back finds it */
} wf_host_storage_fault_t;
void wf_host_storage_clear(void);
bool wf_host_storage_use_file(const char *path);
void wf_host_storage_set_fault(int fault);
size_t wf_host_storage_peek(uint32_t offset, uint8_t *out, size_t len);
size_t wf_host_storage_poke(uint32_t offset, const uint8_t *data, size_t len);
uint32_t wf_host_storage_erases(void);
uint32_t wf_host_storage_programs(void);

/* A flat view of a board for tests. */
typedef struct {
    uint32_t now_ms;
    uint16_t status;
    uint8_t host_seen;
    uint8_t host_version_ok;
    float commanded[2];
    float target[2];
    uint32_t compare[2];
    float roll, pitch, yaw;
    float gyro[3];
    float accel[3];
    int16_t raw_accel[3];
    int16_t raw_gyro[3];
    float battery_v;
    uint32_t commands_applied;
    uint32_t commands_ignored;
    uint32_t frames_sent;
    uint32_t errors_sent;
    uint32_t tx_bytes_dropped;
    uint32_t decoder[12];  /* wf_decoder_stats_t in order */
    uint8_t config_rejected;
} wf_host_snapshot_t;

/* The process's one board (for ctypes): init with config (NULL: the defaults; the storage as
 * it is), then step: feed len bytes at time t, poll once, hand the neutral compares of the
 * calibration in force to the fault model (as the port's main loop does), move up to cap
 * output bytes to out (returns how many). */
void wf_host_board_init(const wf_config_t *config);
size_t wf_host_board_step(uint32_t t, const uint8_t *in, size_t len, uint8_t *out, size_t cap);
void wf_host_board_snapshot(wf_host_snapshot_t *snapshot);
size_t wf_host_config_size(void);
size_t wf_host_snapshot_size(void);

/* Gait mode, the CPG and the link settings of the board (a view next to the snapshot). */
typedef struct {
    uint8_t gait_mode;
    uint8_t gap;           /* wf_gap_t: 0 none, 1 coasting, 2 resting */
    uint16_t gait_id;      /* the last accepted GAIT's (also after leaving gait mode: 0) */
    uint32_t cpg_time_ms;  /* the board time the CPG's state is at */
    uint32_t cpg_steps;    /* RK4 steps since gait mode was entered */
    float phase[2];        /* xi_i wrapped to [-pi, pi) */
    float r[2], dr[2], b[2], db[2];
    float output[2];       /* Theta_i of the state, before the clamp */
    float rate[2];         /* their time derivatives */
    float target[2];       /* what the PWM shows (after the clamp / the failsafe's slew) */
    uint32_t compare[2];
    uint16_t status;
    uint8_t ack_count;
    uint8_t telemetry_form;
    uint32_t acks_dropped;
    uint32_t gaits_accepted;
    uint32_t gaits_refused;
    uint32_t telemetry_period_ms;
    uint32_t health_period_ms;
    uint32_t link_timeout_ms;
    uint32_t coast_ms;
    wf_cpg_params_t params; /* the targets the CPG runs on now (at rest: R = B = 0) */
} wf_host_gait_snapshot_t;

void wf_host_board_gait(wf_host_gait_snapshot_t *snapshot);
size_t wf_host_gait_snapshot_size(void);
/* Each servo's calibration in force and its source, as a SERVO_TRIM_REPORT would give them
 * (report[0] servo 1, report[1] servo 2). */
void wf_host_board_calibration(wf_servo_trim_report_t report[2]);
size_t wf_host_calibration_size(void);
/* The board's wf_health_t as last sent (the core fills its fields when it sends HEALTH). */
void wf_host_board_health(wf_health_t *health);
size_t wf_host_health_size(void);

/* A lone CPG (wf/cpg.h) next to the board, for the parity with wirefish_cpg. */
void wf_host_cpg_init(const wf_cpg_params_t *params);
void wf_host_cpg_set_params(const wf_cpg_params_t *params);
/* Takes steps RK4 steps; angles (NULL: none) gets Theta_1, Theta_2 after each step and phases
 * (NULL: none) xi_1, xi_2 (wrapped) after each. */
void wf_host_cpg_run(uint32_t steps, float *angles, float *phases);
/* The state in CpgIntegrator's flat order: xi1, xi2, r1, r2, r1', r2', b1, b2, b1', b2'. */
void wf_host_cpg_state(float state[10]);
void wf_host_cpg_output(float angle[2], float rate[2]);
size_t wf_host_cpg_params_size(void);

/* Batch codec for tests. A flat message: every field of every type (the type's own are used).
 * n holds the integer fields the first part has no place for, each widened, in wire order:
 * TELEMETRY gait_id; LINK_CONFIG period, form, health period, link timeout, coast; ACK
 * acked_type, acked_seq, result; GAIT gait_id (its floats in f[0..9], wire order);
 * TELEMETRY_COMPACT all 15 fields; HEALTH all 20 fields; SERVO_TRIM servo, op, direction,
 * reserved (neutral_us, us_per_rad in f[0], f[1]); SERVO_TRIM_REPORT servo, source,
 * direction, reserved (neutral_us, us_per_rad, min_us, max_us in f[0..3]). */
enum { WF_HOST_MSG_INTS = 20 };
typedef struct {
    uint8_t type;
    uint8_t version_or_code;
    uint8_t role;
    uint8_t pad;
    uint16_t seq;
    uint16_t ref_seq_or_status;
    uint32_t uptime_or_time_ms;
    float f[12];  /* SERVO_CMD: f[0], f[1]; TELEMETRY: roll..battery_v in wire order */
    uint32_t pad2;
    int64_t n[WF_HOST_MSG_INTS];
} wf_host_msg_t;

size_t wf_host_msg_size(void);

/* Decodes a stream (any bytes) into at most max messages; returns how many; *stats gets the
 * decoder's counters (wf_decoder_stats_t order) when not NULL. */
size_t wf_host_decode_stream(const uint8_t *in, size_t len, wf_host_msg_t *out, size_t max,
                             uint32_t *stats);
/* Encodes n messages as frames one after the other; returns the bytes written (0 if cap is
 * short or a type is unknown). */
size_t wf_host_encode_stream(const wf_host_msg_t *msgs, size_t n, uint8_t *out, size_t cap);

#ifdef __cplusplus
}
#endif

#endif /* WF_HOST_H */
