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

#define WF_PROTOCOL_VERSION 1u

typedef enum {
    WF_MSG_HEARTBEAT = 0x01,
    WF_MSG_SERVO_CMD = 0x10,
    WF_MSG_TELEMETRY = 0x20,
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
} wf_error_code_t;

enum {
    WF_STATUS_FAILSAFE_COMMAND = 0x0001,
    WF_STATUS_FAILSAFE_HEARTBEAT = 0x0002,
    WF_STATUS_SERVO_CLAMPED = 0x0004,
    WF_STATUS_LOW_BATTERY = 0x0008,
    WF_STATUS_IMU_FAULT = 0x0010,
    WF_STATUS_VERSION_MISMATCH = 0x0020,
};

/* Wire sizes, each the sum of its fields (checked by static_assert in wire.c). */
#define WF_HEADER_SIZE 3u
#define WF_CRC_SIZE 2u
#define WF_HEARTBEAT_SIZE 6u
#define WF_SERVO_CMD_SIZE 8u
#define WF_TELEMETRY_SIZE 54u
#define WF_ERROR_SIZE 3u
#define WF_MAX_PAYLOAD WF_TELEMETRY_SIZE
#define WF_MIN_BODY (WF_HEADER_SIZE + WF_CRC_SIZE)
#define WF_MAX_BODY (WF_MIN_BODY + WF_MAX_PAYLOAD)
/* The longest COBS run that can be a frame (60 bytes); a longer run is a lost delimiter. */
#define WF_MAX_ENCODED WF_COBS_MAX_ENCODED(WF_MAX_BODY)
/* The longest frame on the wire: both delimiters and the stuffed body (62 bytes). */
#define WF_MAX_WIRE (WF_MAX_ENCODED + 2u)

typedef struct {
    uint8_t version;
    uint8_t role;
    uint32_t uptime_ms;
} wf_heartbeat_t;

typedef struct {
    float servo[2];
} wf_servo_cmd_t;

typedef struct {
    uint32_t board_time_ms;
    float roll, pitch, yaw;
    float gyro[3];
    float accel[3];
    float servo[2];
    float battery_v;
    uint16_t status;
} wf_telemetry_t;

typedef struct {
    uint8_t code;
    uint16_t ref_seq;
} wf_error_t;

typedef struct {
    uint8_t type; /* wf_msg_type_t */
    uint16_t seq;
    union {
        wf_heartbeat_t heartbeat;
        wf_servo_cmd_t servo_cmd;
        wf_telemetry_t telemetry;
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
