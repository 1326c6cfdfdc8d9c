#include "wf/wire.h"

#include <assert.h>
#include <string.h>

#include "wf/crc16.h"

static_assert(sizeof(float) == 4, "floats on the wire are binary32");
static_assert(WF_HEARTBEAT_SIZE == 1 + 1 + 4, "HEARTBEAT: version u8, role u8, uptime u32");
static_assert(WF_SERVO_CMD_SIZE == 2 * 4, "SERVO_CMD: two f32");
static_assert(WF_TELEMETRY_SIZE == 4 + 12 * 4 + 2, "TELEMETRY: u32, 12 f32, u16");
static_assert(WF_ERROR_SIZE == 1 + 2, "ERROR: code u8, ref_seq u16");
static_assert(WF_MAX_BODY == 59, "the longest body is a TELEMETRY's");
static_assert(WF_MAX_ENCODED == 60, "TELEMETRY is 62 bytes on the wire (PROTOCOL.md)");
static_assert(WF_MAX_ENCODED <= UINT8_MAX, "run_len is a u8");

size_t wf_payload_size(uint8_t type)
{
    switch (type) {
    case WF_MSG_HEARTBEAT:
        return WF_HEARTBEAT_SIZE;
    case WF_MSG_SERVO_CMD:
        return WF_SERVO_CMD_SIZE;
    case WF_MSG_TELEMETRY:
        return WF_TELEMETRY_SIZE;
    case WF_MSG_ERROR:
        return WF_ERROR_SIZE;
    default:
        return 0;
    }
}

/* --- little-endian field access ------------------------------------------------------- */
static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, sizeof v);
    put_u32(p, v);
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

/* Reads a binary32; false when it is not finite (exponent all ones: inf or NaN). The bit
 * test needs no floating-point compare, so it holds under any compiler float mode. */
static bool get_finite_f32(const uint8_t *p, float *out)
{
    const uint32_t v = get_u32(p);
    memcpy(out, &v, sizeof *out);
    return (v & 0x7F800000u) != 0x7F800000u;
}

/* --- encoding ------------------------------------------------------------------------- */
static size_t put_payload(const wf_msg_t *msg, uint8_t *p)
{
    switch (msg->type) {
    case WF_MSG_HEARTBEAT:
        p[0] = msg->u.heartbeat.version;
        p[1] = msg->u.heartbeat.role;
        put_u32(p + 2, msg->u.heartbeat.uptime_ms);
        return WF_HEARTBEAT_SIZE;
    case WF_MSG_SERVO_CMD:
        put_f32(p, msg->u.servo_cmd.servo[0]);
        put_f32(p + 4, msg->u.servo_cmd.servo[1]);
        return WF_SERVO_CMD_SIZE;
    case WF_MSG_TELEMETRY: {
        const wf_telemetry_t *t = &msg->u.telemetry;
        const float floats[12] = {t->roll,     t->pitch,    t->yaw,      t->gyro[0],
                                  t->gyro[1],  t->gyro[2],  t->accel[0], t->accel[1],
                                  t->accel[2], t->servo[0], t->servo[1], t->battery_v};
        put_u32(p, t->board_time_ms);
        for (size_t i = 0; i < 12; i++) {
            put_f32(p + 4 + 4 * i, floats[i]);
        }
        put_u16(p + 52, t->status);
        return WF_TELEMETRY_SIZE;
    }
    case WF_MSG_ERROR:
        p[0] = msg->u.error.code;
        put_u16(p + 1, msg->u.error.ref_seq);
        return WF_ERROR_SIZE;
    default:
        return 0;
    }
}

size_t wf_encode_body(const wf_msg_t *msg, uint8_t *out)
{
    const size_t payload = put_payload(msg, out + WF_HEADER_SIZE);
    if (payload == 0) {
        return 0;
    }
    out[0] = msg->type;
    put_u16(out + 1, msg->seq);
    const size_t len = WF_HEADER_SIZE + payload;
    put_u16(out + len, wf_crc16(out, len));
    return len + WF_CRC_SIZE;
}

size_t wf_encode_frame(const wf_msg_t *msg, uint8_t *out, size_t cap)
{
    uint8_t body[WF_MAX_BODY];
    const size_t len = wf_encode_body(msg, body);
    if (len == 0 || cap < 2) {
        return 0;
    }
    const size_t stuffed = wf_cobs_encode(body, len, out + 1, cap - 2);
    if (stuffed == 0) {
        return 0;
    }
    out[0] = 0;
    out[stuffed + 1] = 0;
    return stuffed + 2;
}

/* --- decoding ------------------------------------------------------------------------- */
static bool get_payload(uint8_t type, const uint8_t *p, wf_msg_t *msg)
{
    switch (type) {
    case WF_MSG_HEARTBEAT:
        msg->u.heartbeat.version = p[0];
        msg->u.heartbeat.role = p[1];
        msg->u.heartbeat.uptime_ms = get_u32(p + 2);
        return p[1] == WF_ROLE_HOST || p[1] == WF_ROLE_FISH;
    case WF_MSG_SERVO_CMD: {
        const bool ok0 = get_finite_f32(p, &msg->u.servo_cmd.servo[0]);
        const bool ok1 = get_finite_f32(p + 4, &msg->u.servo_cmd.servo[1]);
        return ok0 && ok1;
    }
    case WF_MSG_TELEMETRY: {
        wf_telemetry_t *t = &msg->u.telemetry;
        float *const floats[12] = {&t->roll,     &t->pitch,    &t->yaw,      &t->gyro[0],
                                   &t->gyro[1],  &t->gyro[2],  &t->accel[0], &t->accel[1],
                                   &t->accel[2], &t->servo[0], &t->servo[1], &t->battery_v};
        bool finite = true;
        t->board_time_ms = get_u32(p);
        for (size_t i = 0; i < 12; i++) {
            finite = get_finite_f32(p + 4 + 4 * i, floats[i]) && finite;
        }
        t->status = get_u16(p + 52);
        return finite;
    }
    case WF_MSG_ERROR:
        msg->u.error.code = p[0];
        msg->u.error.ref_seq = get_u16(p + 1);
        return true; /* any code: an unknown one is still worth reporting */
    default:
        return false;
    }
}

wf_rx_t wf_check_body(const uint8_t *body, size_t len, wf_msg_t *msg)
{
    if (len < WF_MIN_BODY) {
        return WF_RX_SHORT;
    }
    if (wf_crc16(body, len - WF_CRC_SIZE) != get_u16(body + len - WF_CRC_SIZE)) {
        return WF_RX_CRC;
    }
    const size_t expected = wf_payload_size(body[0]);
    if (expected == 0) {
        return WF_RX_UNKNOWN_TYPE;
    }
    if (len - WF_MIN_BODY != expected) {
        return WF_RX_LENGTH;
    }
    msg->type = body[0];
    msg->seq = get_u16(body + 1);
    if (!get_payload(body[0], body + WF_HEADER_SIZE, msg)) {
        return WF_RX_INVALID;
    }
    return WF_RX_FRAME;
}

void wf_decoder_init(wf_decoder_t *decoder)
{
    memset(decoder, 0, sizeof *decoder);
}

static wf_rx_t reject(wf_decoder_t *d, wf_rx_t why)
{
    uint32_t *const counter[] = {
        [WF_RX_COBS] = &d->stats.cobs_errors,          [WF_RX_SHORT] = &d->stats.short_frames,
        [WF_RX_CRC] = &d->stats.crc_errors,            [WF_RX_UNKNOWN_TYPE] = &d->stats.unknown_type,
        [WF_RX_LENGTH] = &d->stats.length_errors,      [WF_RX_INVALID] = &d->stats.invalid_payload,
        [WF_RX_OVERFLOW] = &d->stats.overflows,
    };
    (*counter[why])++;
    d->stats.resyncs++;
    return why;
}

static void count_sequence(wf_decoder_t *d, uint16_t seq)
{
    if (d->have_seq) {
        const uint16_t gap = (uint16_t)(seq - d->last_seq - 1u);
        if (gap >= 0x8000u) {
            d->stats.seq_resets++; /* a jump back or of half the range: the peer restarted */
        } else {
            d->stats.seq_gaps += gap;
        }
    }
    d->have_seq = true;
    d->last_seq = seq;
}

static wf_rx_t end_of_run(wf_decoder_t *d, wf_msg_t *msg)
{
    if (d->discarding) {
        d->discarding = false;
        return WF_RX_NONE;
    }
    if (d->run_len == 0) {
        return WF_RX_NONE; /* back-to-back delimiters are idle fill, not an error */
    }
    uint8_t body[WF_MAX_ENCODED];
    size_t len = 0;
    const bool decoded = wf_cobs_decode(d->run, d->run_len, body, sizeof body, &len);
    d->run_len = 0;
    if (!decoded) {
        return reject(d, WF_RX_COBS);
    }
    const wf_rx_t verdict = wf_check_body(body, len, msg);
    if (verdict != WF_RX_FRAME) {
        return reject(d, verdict);
    }
    count_sequence(d, msg->seq);
    d->stats.frames_ok++;
    return WF_RX_FRAME;
}

wf_rx_t wf_decoder_push(wf_decoder_t *decoder, uint8_t byte, wf_msg_t *msg)
{
    decoder->stats.bytes_in++;
    if (byte == 0) {
        return end_of_run(decoder, msg);
    }
    if (decoder->discarding) {
        return WF_RX_NONE;
    }
    if (decoder->run_len >= WF_MAX_ENCODED) {
        /* Longer than any frame: a lost delimiter. Skip to the next one, memory bounded. */
        decoder->run_len = 0;
        decoder->discarding = true;
        return reject(decoder, WF_RX_OVERFLOW);
    }
    decoder->run[decoder->run_len++] = byte;
    return WF_RX_NONE;
}
