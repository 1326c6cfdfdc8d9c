/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The message table of PROTOCOL.md: payload layouts, frame encoding, the body checks and the
 * streaming decoder. Little-endian on the wire whatever the CPU; floats IEEE-754 binary32.
 *
 *   wire:  0x00 | COBS( body ) | 0x00
 *   body:  type u8 | seq u16 | payload (fixed size per type) | crc u16
 */
#ifndef WF_WIRE_H
#define WF_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wf/cobs.h"
#include "wf/cpg.h"
#include "wf/health.h"

#define WF_PROTOCOL_VERSION 2u

typedef enum {
    WF_MSG_HEARTBEAT = 0x01,
    WF_MSG_LINK_CONFIG = 0x02,
    WF_MSG_ACK = 0x03,
    WF_MSG_SERVO_CMD = 0x10,
    WF_MSG_GAIT = 0x11,
    WF_MSG_SERVO_TRIM = 0x12,
    WF_MSG_TELEMETRY = 0x20,
    WF_MSG_TELEMETRY_COMPACT = 0x21,
    WF_MSG_SERVO_TRIM_REPORT = 0x22,
    WF_MSG_HEALTH = 0x30,
    WF_MSG_ERROR = 0x7F,
} wf_msg_type_t;

typedef enum { WF_ROLE_HOST = 0, WF_ROLE_FISH = 1 } wf_role_t;

typedef enum {
    WF_ERR_BAD_CRC = 1,
    WF_ERR_BAD_FRAME = 2,
    WF_ERR_UNKNOWN_TYPE = 3,
    WF_ERR_BAD_LENGTH = 4,
    WF_ERR_VERSION_MISMATCH = 5,
    WF_ERR_COMMAND_OUT_OF_RANGE = 6,
    WF_ERR_NOT_NOW = 7,          /* a valid request, refused in the current mode */
    WF_ERR_STORAGE_FAILED = 8,   /* the storage's erase, program or read-back failed */
} wf_error_code_t;

/* SERVO_TRIM's operation. */
typedef enum {
    WF_TRIM_READ = 0,    /* report the servo's calibration; changes nothing */
    WF_TRIM_SET = 1,     /* live, not saved */
    WF_TRIM_SAVE = 2,    /* live, and written to storage */
    WF_TRIM_FACTORY = 3, /* the build's defaults, live, and the stored values of the servo
                          * dropped (a new record with valid 0), so a reboot gives them too */
} wf_trim_op_t;

/* Where a servo's running calibration comes from (SERVO_TRIM_REPORT's source). */
typedef enum {
    WF_CAL_DEFAULTS = 0, /* the build's values */
    WF_CAL_STORED = 1,   /* the values of the record in storage */
    WF_CAL_LIVE = 2,     /* set, not saved */
} wf_cal_source_t;

enum {
    WF_STATUS_FAILSAFE_COMMAND = 0x0001,
    WF_STATUS_FAILSAFE_HEARTBEAT = 0x0002,
    WF_STATUS_SERVO_CLAMPED = 0x0004,
    WF_STATUS_LOW_BATTERY = 0x0008,
    WF_STATUS_IMU_FAULT = 0x0010,
    WF_STATUS_VERSION_MISMATCH = 0x0020,
    WF_STATUS_COASTING = 0x0040,       /* gait mode, link lost: still swimming the last gait */
    WF_STATUS_RESTING = 0x0080,        /* gait mode, link lost past the coast: brought to rest */
    WF_STATUS_GAIT_MODE = 0x0100,      /* the board integrates eq 1 itself (clear: stream) */
    WF_STATUS_CLOCK_FALLBACK = 0x0200, /* running on HSI: the crystal failed */
};

typedef enum { WF_TELEMETRY_FULL = 0, WF_TELEMETRY_COMPACT = 1 } wf_telemetry_form_t;

/* LINK_CONFIG's ranges (ms). A health period of 0 turns the periodic HEALTH off. */
enum {
    WF_LINK_TELEMETRY_MIN_MS = 10,
    WF_LINK_TELEMETRY_MAX_MS = 1000,
    WF_LINK_HEALTH_MIN_MS = 200,
    WF_LINK_HEALTH_MAX_MS = 60000,
    WF_LINK_TIMEOUT_MIN_MS = 100,
    WF_LINK_TIMEOUT_MAX_MS = 10000,
    WF_LINK_COAST_MAX_MS = 60000,
};

/* TELEMETRY_COMPACT's units (one count, SI): a value is v / lsb rounded to the nearest count,
 * halves away from zero, in binary64, saturated to the field's range. */
#define WF_COMPACT_ANGLE_LSB_RAD 1e-4  /* roll, pitch, yaw, servo angles: +-3.2767 rad */
#define WF_COMPACT_RATE_LSB_RAD_S 1e-3 /* gyro: +-32.767 rad/s */
#define WF_COMPACT_ACCEL_LSB_M_S2 1e-3 /* accel: +-32.767 m/s^2 */
#define WF_COMPACT_BATTERY_LSB_V 1e-3  /* battery_mv: 0..65.535 V */

/* Wire sizes, each the sum of its fields (checked by static_assert in wire.c). */
#define WF_HEADER_SIZE 3u
#define WF_CRC_SIZE 2u
#define WF_HEARTBEAT_SIZE 6u
#define WF_LINK_CONFIG_SIZE 9u
#define WF_ACK_SIZE 4u
#define WF_SERVO_CMD_SIZE 8u
#define WF_GAIT_SIZE 42u
#define WF_TELEMETRY_SIZE 56u
#define WF_TELEMETRY_COMPACT_SIZE 32u
#define WF_SERVO_TRIM_SIZE 12u
#define WF_SERVO_TRIM_REPORT_SIZE 20u
#define WF_HEALTH_SIZE 61u
#define WF_ERROR_SIZE 3u
#define WF_MAX_PAYLOAD WF_HEALTH_SIZE
#define WF_MIN_BODY (WF_HEADER_SIZE + WF_CRC_SIZE)
#define WF_MAX_BODY (WF_MIN_BODY + WF_MAX_PAYLOAD)
/* The longest COBS run that can be a frame (67 bytes); a longer run is a lost delimiter. */
#define WF_MAX_ENCODED WF_COBS_MAX_ENCODED(WF_MAX_BODY)
/* The longest frame on the wire: both delimiters and the stuffed body (69 bytes). */
#define WF_MAX_WIRE (WF_MAX_ENCODED + 2u)

typedef struct {
    uint8_t version;
    uint8_t role;
    uint32_t uptime_ms;
} wf_heartbeat_t;

typedef struct {
    uint16_t telemetry_period_ms;
    uint8_t telemetry_form; /* wf_telemetry_form_t */
    uint16_t health_period_ms;
    uint16_t link_timeout_ms;
    uint16_t coast_ms;
} wf_link_config_t;

typedef struct {
    uint8_t acked_type;
    uint16_t acked_seq;
    uint8_t result; /* 0 accepted, else the wf_error_code_t of the refusal */
} wf_ack_t;

typedef struct {
    float servo[2];
} wf_servo_cmd_t;

typedef struct {
    uint16_t gait_id; /* 1..65535 (0: none) */
    wf_cpg_params_t params;
} wf_gait_t;

typedef struct {
    uint32_t board_time_ms;
    float roll, pitch, yaw;
    float gyro[3];
    float accel[3];
    float servo[2];
    float battery_v;
    uint16_t status;
    uint16_t gait_id;
} wf_telemetry_t;

typedef struct {
    uint32_t board_time_ms;
    int16_t roll, pitch, yaw; /* 1e-4 rad */
    int16_t gyro[3];          /* 1e-3 rad/s */
    int16_t accel[3];         /* 1e-3 m/s^2 */
    int16_t servo[2];         /* 1e-4 rad */
    uint16_t battery_mv;
    uint16_t status;
    uint16_t gait_id;
} wf_telemetry_compact_t;

typedef struct {
    uint8_t servo;      /* 1 or 2 */
    uint8_t op;         /* wf_trim_op_t */
    int8_t direction;   /* +1 or -1 (SET, SAVE); READ and FACTORY ignore it */
    uint8_t reserved;   /* 0 */
    float neutral_us;   /* SET, SAVE: the pulse at 0 rad */
    float us_per_rad;   /* SET, SAVE: > 0 */
} wf_servo_trim_t;

typedef struct {
    uint8_t servo;      /* 1 or 2 */
    uint8_t source;     /* wf_cal_source_t */
    int8_t direction;
    uint8_t reserved;   /* 0 */
    float neutral_us;
    float us_per_rad;
    float min_us;       /* the build's, read-only */
    float max_us;       /* the build's, read-only */
} wf_servo_trim_report_t;

typedef struct {
    uint8_t code;
    uint16_t ref_seq;
} wf_error_t;

typedef struct {
    uint8_t type; /* wf_msg_type_t */
    uint16_t seq;
    union {
        wf_heartbeat_t heartbeat;
        wf_link_config_t link_config;
        wf_ack_t ack;
        wf_servo_cmd_t servo_cmd;
        wf_gait_t gait;
        wf_servo_trim_t servo_trim;
        wf_servo_trim_report_t servo_trim_report;
        wf_telemetry_t telemetry;
        wf_telemetry_compact_t compact;
        wf_health_t health;
        wf_error_t error;
    } u;
} wf_msg_t;

/* The payload size of a type, 0 for an unknown type. */
size_t wf_payload_size(uint8_t type);

/* Writes the unstuffed body of msg (with msg->seq) into out (>= WF_MAX_BODY bytes); returns
 * its length, 0 for an unknown type. */
size_t wf_encode_body(const wf_msg_t *msg, uint8_t *out);

/* Writes 0x00 COBS(body) 0x00 into out (capacity cap, WF_MAX_WIRE always suffices); returns
 * the wire length, 0 if the type is unknown or cap is short. */
size_t wf_encode_frame(const wf_msg_t *msg, uint8_t *out, size_t cap);

/* The compact form of a full telemetry (each value scaled, rounded and saturated). */
void wf_telemetry_compact(const wf_telemetry_t *full, wf_telemetry_compact_t *compact);

/* The rules a receiver applies to a well-formed LINK_CONFIG: every field in its range. */
bool wf_link_config_valid(const wf_link_config_t *config);

/* The rules a receiver applies to a well-formed GAIT: gait_id 1..65535 and the parameters
 * within wf_cpg_params_valid for the board's servo limit (frequency, amplitudes and offsets,
 * couplings |w| <= 100/s, phase biases |phi| <= 2 pi, alpha). */
bool wf_gait_valid(const wf_gait_t *gait, float servo_limit_rad);

/* Why a run was dropped, or that it is a frame; the checks in the order they are made. */
typedef enum {
    WF_RX_NONE = 0,      /* no run ended with this byte */
    WF_RX_FRAME,         /* a valid frame: act on it */
    WF_RX_COBS,          /* does not COBS-decode */
    WF_RX_SHORT,         /* shorter than 5 bytes */
    WF_RX_CRC,           /* fails the CRC */
    WF_RX_UNKNOWN_TYPE,  /* unknown type */
    WF_RX_LENGTH,        /* wrong payload size for its type */
    WF_RX_INVALID,       /* a non-finite float or an unknown role */
    WF_RX_OVERFLOW,      /* longer than any frame before a delimiter: skipped to the next 0x00 */
} wf_rx_t;

/* Checks an unstuffed body; on WF_RX_FRAME fills *msg. */
wf_rx_t wf_check_body(const uint8_t *body, size_t len, wf_msg_t *msg);

/* Counters of a decoder (monotonic, wrap at 2^32); the same as the bridge's DecoderStats.
 * Every dropped run counts once in resyncs and once in exactly one of the reasons. */
typedef struct {
    uint32_t bytes_in;
    uint32_t frames_ok;
    uint32_t cobs_errors;
    uint32_t short_frames;
    uint32_t crc_errors;
    uint32_t unknown_type;
    uint32_t length_errors;
    uint32_t invalid_payload;
    uint32_t overflows;
    uint32_t resyncs;
    uint32_t seq_gaps;
    uint32_t seq_resets;
} wf_decoder_stats_t;

typedef struct {
    uint8_t run[WF_MAX_ENCODED];
    uint8_t run_len;
    bool discarding;  /* an over-long run is being skipped up to the next 0x00 */
    bool have_seq;
    uint16_t last_seq;
    wf_decoder_stats_t stats;
} wf_decoder_t;

void wf_decoder_init(wf_decoder_t *decoder);

/* Takes one received byte; returns WF_RX_FRAME with *msg filled when it completes a valid
 * frame, a WF_RX_ reason when it ends a dropped run, WF_RX_NONE otherwise. */
wf_rx_t wf_decoder_push(wf_decoder_t *decoder, uint8_t byte, wf_msg_t *msg);

#endif /* WF_WIRE_H */
