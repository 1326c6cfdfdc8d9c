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

/* The process's one board (for ctypes): init with config (NULL: the defaults), then step:
 * feed len bytes at time t, poll once, move up to cap output bytes to out (returns how many). */
void wf_host_board_init(const wf_config_t *config);
size_t wf_host_board_step(uint32_t t, const uint8_t *in, size_t len, uint8_t *out, size_t cap);
void wf_host_board_snapshot(wf_host_snapshot_t *snapshot);
size_t wf_host_config_size(void);
size_t wf_host_snapshot_size(void);

/* Batch codec for tests. A flat message: every field of every type (the type's own are used). */
typedef struct {
    uint8_t type;
    uint8_t version_or_code;
    uint8_t role;
    uint8_t pad;
    uint16_t seq;
    uint16_t ref_seq_or_status;
    uint32_t uptime_or_time_ms;
    float f[12];  /* SERVO_CMD: f[0], f[1]; TELEMETRY: roll..battery_v in wire order */
} wf_host_msg_t;

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
