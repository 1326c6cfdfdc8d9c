/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/wire.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#include "wf/crc16.h"

static_assert(sizeof(float) == 4, "floats on the wire are binary32");
static_assert(WF_HEARTBEAT_SIZE == 1 + 1 + 4, "HEARTBEAT: version u8, role u8, uptime u32");
static_assert(WF_LINK_CONFIG_SIZE == 2 + 1 + 2 + 2 + 2,
              "LINK_CONFIG: telemetry period u16, form u8, health period, timeout, coast u16");
static_assert(WF_ACK_SIZE == 1 + 2 + 1, "ACK: acked_type u8, acked_seq u16, result u8");
static_assert(WF_SERVO_CMD_SIZE == 2 * 4, "SERVO_CMD: two f32");
static_assert(WF_GAIT_SIZE == 2 + 10 * 4, "GAIT: gait_id u16, 10 f32");
static_assert(WF_TELEMETRY_SIZE == 4 + 12 * 4 + 2 + 2, "TELEMETRY: u32, 12 f32, u16, u16");
static_assert(WF_TELEMETRY_COMPACT_SIZE == 4 + 11 * 2 + 3 * 2,
              "TELEMETRY_COMPACT: u32, 11 i16, battery, status, gait_id u16");
static_assert(WF_HEALTH_SIZE == 3 * 1 + 5 * 4 + 2 * 2 + 7 * 4 + 3 * 2,
              "HEALTH: 3 u8, fault record and uptime u32, stack u16, 7 counters u32, 3 u16");
static_assert(WF_SERVO_TRIM_SIZE == 4 * 1 + 2 * 4,
              "SERVO_TRIM: servo u8, op u8, direction i8, reserved u8, 2 f32");
static_assert(WF_SERVO_TRIM_REPORT_SIZE == 4 * 1 + 4 * 4,
              "SERVO_TRIM_REPORT: servo u8, source u8, direction i8, reserved u8, 4 f32");
static_assert(WF_ERROR_SIZE == 1 + 2, "ERROR: code u8, ref_seq u16");
static_assert(WF_MAX_BODY == 66, "the longest body is a HEALTH's");
static_assert(WF_MAX_ENCODED == 67, "HEALTH is 69 bytes on the wire at most (PROTOCOL.md)");
static_assert(WF_MAX_ENCODED <= UINT8_MAX, "run_len is a u8");
static_assert(sizeof(wf_cpg_params_t) == 10 * sizeof(float), "GAIT's floats, in wire order");

size_t wf_payload_size(uint8_t type)
{
    switch (type) {
    case WF_MSG_HEARTBEAT:
        return WF_HEARTBEAT_SIZE;
    case WF_MSG_LINK_CONFIG:
        return WF_LINK_CONFIG_SIZE;
    case WF_MSG_ACK:
        return WF_ACK_SIZE;
    case WF_MSG_SERVO_CMD:
        return WF_SERVO_CMD_SIZE;
    case WF_MSG_GAIT:
        return WF_GAIT_SIZE;
    case WF_MSG_SERVO_TRIM:
        return WF_SERVO_TRIM_SIZE;
    case WF_MSG_SERVO_TRIM_REPORT:
        return WF_SERVO_TRIM_REPORT_SIZE;
    case WF_MSG_TELEMETRY:
        return WF_TELEMETRY_SIZE;
    case WF_MSG_TELEMETRY_COMPACT:
        return WF_TELEMETRY_COMPACT_SIZE;
    case WF_MSG_HEALTH:
        return WF_HEALTH_SIZE;
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

/* GAIT's floats in wire order: frequency, amplitude 1, 2, offset 1, 2, w12, w21, phi12,
 * phi21, alpha (the field order of wf_cpg_params_t). */
static void gait_floats(wf_cpg_params_t *p, float *out[10])
{
    float *const fields[10] = {&p->frequency_hz, &p->amplitude[0], &p->amplitude[1],
                               &p->offset[0],    &p->offset[1],    &p->w12,
                               &p->w21,          &p->phi12,        &p->phi21,
                               &p->alpha};
    memcpy(out, fields, sizeof fields);
}

/* HEALTH's u32 fields after the three u8 and after the stack u16s, in wire order. */
static void health_words(wf_health_t *h, uint32_t *head[5], uint32_t *tail[7])
{
    uint32_t *const first[5] = {&h->fault_pc, &h->fault_lr, &h->fault_cfsr, &h->fault_hfsr,
                                &h->uptime_ms};
    uint32_t *const second[7] = {&h->uart_rx_overruns, &h->tx_bytes_dropped, &h->rx_crc,
                                 &h->rx_frame,         &h->rx_unknown_type,  &h->rx_length,
                                 &h->rx_invalid};
    memcpy(head, first, sizeof first);
    memcpy(tail, second, sizeof second);
}

static void put_health(const wf_health_t *health, uint8_t *p)
{
    wf_health_t h = *health;
    uint32_t *head[5], *tail[7];
    health_words(&h, head, tail);
    p[0] = h.reset_cause;
    p[1] = h.clock_source;
    p[2] = h.flags;
    for (size_t i = 0; i < 5; i++) {
        put_u32(p + 3 + 4 * i, *head[i]);
    }
    put_u16(p + 23, h.stack_free_min);
    put_u16(p + 25, h.stack_size);
    for (size_t i = 0; i < 7; i++) {
        put_u32(p + 27 + 4 * i, *tail[i]);
    }
    put_u16(p + 55, h.imu_faults);
    put_u16(p + 57, h.imu_recoveries);
    put_u16(p + 59, h.i2c_bus_recoveries);
}

static void get_health(const uint8_t *p, wf_health_t *h)
{
    uint32_t *head[5], *tail[7];
    health_words(h, head, tail);
    h->reset_cause = p[0];
    h->clock_source = p[1];
    h->flags = p[2];
    for (size_t i = 0; i < 5; i++) {
        *head[i] = get_u32(p + 3 + 4 * i);
    }
    h->stack_free_min = get_u16(p + 23);
    h->stack_size = get_u16(p + 25);
    for (size_t i = 0; i < 7; i++) {
        *tail[i] = get_u32(p + 27 + 4 * i);
    }
    h->imu_faults = get_u16(p + 55);
    h->imu_recoveries = get_u16(p + 57);
    h->i2c_bus_recoveries = get_u16(p + 59);
}

/* TELEMETRY_COMPACT's i16 fields after board_time_ms, in wire order. */
static void compact_fields(wf_telemetry_compact_t *c, int16_t *out[11])
{
    int16_t *const fields[11] = {&c->roll,     &c->pitch,    &c->yaw,      &c->gyro[0],
                                 &c->gyro[1],  &c->gyro[2],  &c->accel[0], &c->accel[1],
                                 &c->accel[2], &c->servo[0], &c->servo[1]};
    memcpy(out, fields, sizeof fields);
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
    case WF_MSG_LINK_CONFIG: {
        const wf_link_config_t *c = &msg->u.link_config;
        put_u16(p, c->telemetry_period_ms);
        p[2] = c->telemetry_form;
        put_u16(p + 3, c->health_period_ms);
        put_u16(p + 5, c->link_timeout_ms);
        put_u16(p + 7, c->coast_ms);
        return WF_LINK_CONFIG_SIZE;
    }
    case WF_MSG_ACK:
        p[0] = msg->u.ack.acked_type;
        put_u16(p + 1, msg->u.ack.acked_seq);
        p[3] = msg->u.ack.result;
        return WF_ACK_SIZE;
    case WF_MSG_SERVO_CMD:
        put_f32(p, msg->u.servo_cmd.servo[0]);
        put_f32(p + 4, msg->u.servo_cmd.servo[1]);
        return WF_SERVO_CMD_SIZE;
    case WF_MSG_GAIT: {
        wf_cpg_params_t params = msg->u.gait.params;
        float *floats[10];
        gait_floats(&params, floats);
        put_u16(p, msg->u.gait.gait_id);
        for (size_t i = 0; i < 10; i++) {
            put_f32(p + 2 + 4 * i, *floats[i]);
        }
        return WF_GAIT_SIZE;
    }
    case WF_MSG_SERVO_TRIM: {
        const wf_servo_trim_t *t = &msg->u.servo_trim;
        p[0] = t->servo;
        p[1] = t->op;
        p[2] = (uint8_t)t->direction;
        p[3] = t->reserved;
        put_f32(p + 4, t->neutral_us);
        put_f32(p + 8, t->us_per_rad);
        return WF_SERVO_TRIM_SIZE;
    }
    case WF_MSG_SERVO_TRIM_REPORT: {
        const wf_servo_trim_report_t *r = &msg->u.servo_trim_report;
        p[0] = r->servo;
        p[1] = r->source;
        p[2] = (uint8_t)r->direction;
        p[3] = r->reserved;
        put_f32(p + 4, r->neutral_us);
        put_f32(p + 8, r->us_per_rad);
        put_f32(p + 12, r->min_us);
        put_f32(p + 16, r->max_us);
        return WF_SERVO_TRIM_REPORT_SIZE;
    }
    case WF_MSG_TELEMETRY_COMPACT: {
        wf_telemetry_compact_t c = msg->u.compact;
        int16_t *fields[11];
        compact_fields(&c, fields);
        put_u32(p, c.board_time_ms);
        for (size_t i = 0; i < 11; i++) {
            put_u16(p + 4 + 2 * i, (uint16_t)*fields[i]);
        }
        put_u16(p + 26, c.battery_mv);
        put_u16(p + 28, c.status);
        put_u16(p + 30, c.gait_id);
        return WF_TELEMETRY_COMPACT_SIZE;
    }
    case WF_MSG_HEALTH:
        put_health(&msg->u.health, p);
        return WF_HEALTH_SIZE;
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
        put_u16(p + 54, t->gait_id);
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
    case WF_MSG_LINK_CONFIG: {
        wf_link_config_t *c = &msg->u.link_config;
        c->telemetry_period_ms = get_u16(p);
        c->telemetry_form = p[2];
        c->health_period_ms = get_u16(p + 3);
        c->link_timeout_ms = get_u16(p + 5);
        c->coast_ms = get_u16(p + 7);
        return true; /* ranges are the receiver's rules (wf_link_config_valid): ACK 6 */
    }
    case WF_MSG_ACK:
        msg->u.ack.acked_type = p[0];
        msg->u.ack.acked_seq = get_u16(p + 1);
        msg->u.ack.result = p[3];
        return true;
    case WF_MSG_GAIT: {
        float *floats[10];
        bool finite = true;
        gait_floats(&msg->u.gait.params, floats);
        msg->u.gait.gait_id = get_u16(p);
        for (size_t i = 0; i < 10; i++) {
            finite = get_finite_f32(p + 2 + 4 * i, floats[i]) && finite;
        }
        return finite; /* ranges are the receiver's rules (wf_gait_valid): ACK 6 */
    }
    case WF_MSG_SERVO_TRIM: {
        wf_servo_trim_t *t = &msg->u.servo_trim;
        t->servo = p[0];
        t->op = p[1];
        t->direction = (int8_t)p[2];
        t->reserved = p[3];
        const bool ok0 = get_finite_f32(p + 4, &t->neutral_us);
        const bool ok1 = get_finite_f32(p + 8, &t->us_per_rad);
        return ok0 && ok1; /* every other value is the receiver's rule: ACK 6 */
    }
    case WF_MSG_SERVO_TRIM_REPORT: {
        wf_servo_trim_report_t *r = &msg->u.servo_trim_report;
        float *const floats[4] = {&r->neutral_us, &r->us_per_rad, &r->min_us, &r->max_us};
        bool finite = true;
        r->servo = p[0];
        r->source = p[1];
        r->direction = (int8_t)p[2];
        r->reserved = p[3];
        for (size_t i = 0; i < 4; i++) {
            finite = get_finite_f32(p + 4 + 4 * i, floats[i]) && finite;
        }
        return finite;
    }
    case WF_MSG_TELEMETRY_COMPACT: {
        wf_telemetry_compact_t *c = &msg->u.compact;
        int16_t *fields[11];
        compact_fields(c, fields);
        c->board_time_ms = get_u32(p);
        for (size_t i = 0; i < 11; i++) {
            *fields[i] = (int16_t)get_u16(p + 4 + 2 * i);
        }
        c->battery_mv = get_u16(p + 26);
        c->status = get_u16(p + 28);
        c->gait_id = get_u16(p + 30);
        return true;
    }
    case WF_MSG_HEALTH:
        get_health(p, &msg->u.health);
        return true;
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
        t->gait_id = get_u16(p + 54);
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

/* --- the receiver's rules and the compact form ----------------------------------------- */
bool wf_link_config_valid(const wf_link_config_t *c)
{
    return c->telemetry_period_ms >= WF_LINK_TELEMETRY_MIN_MS &&
           c->telemetry_period_ms <= WF_LINK_TELEMETRY_MAX_MS &&
           (c->telemetry_form == WF_TELEMETRY_FULL || c->telemetry_form == WF_TELEMETRY_COMPACT) &&
           (c->health_period_ms == 0 || (c->health_period_ms >= WF_LINK_HEALTH_MIN_MS &&
                                         c->health_period_ms <= WF_LINK_HEALTH_MAX_MS)) &&
           c->link_timeout_ms >= WF_LINK_TIMEOUT_MIN_MS &&
           c->link_timeout_ms <= WF_LINK_TIMEOUT_MAX_MS && c->coast_ms <= WF_LINK_COAST_MAX_MS;
}

bool wf_gait_valid(const wf_gait_t *gait, float servo_limit_rad)
{
    return gait->gait_id != 0 && wf_cpg_params_valid(&gait->params, servo_limit_rad);
}

/* v in counts of lsb: nearest, halves away from zero, saturated to [low, high], NaN 0. In
 * binary64, as the host's codec computes it (wirefish_bridge.protocol.quantize): the two
 * agree on every value, ties included; a binary32 product would round some differently. */
static int32_t fixed(float v, double lsb, int32_t low, int32_t high)
{
    const double scaled = (double)v / lsb;
    if (scaled != scaled) {
        return 0;
    }
    const double count = floor(fabs(scaled) + 0.5);
    const double rounded = scaled >= 0.0 ? count : -count;
    if (rounded <= (double)low) {
        return low;
    }
    if (rounded >= (double)high) {
        return high;
    }
    return (int32_t)rounded;
}

static int16_t fixed_i16(float v, double lsb)
{
    return (int16_t)fixed(v, lsb, INT16_MIN, INT16_MAX);
}

void wf_telemetry_compact(const wf_telemetry_t *t, wf_telemetry_compact_t *c)
{
    c->board_time_ms = t->board_time_ms;
    c->roll = fixed_i16(t->roll, WF_COMPACT_ANGLE_LSB_RAD);
    c->pitch = fixed_i16(t->pitch, WF_COMPACT_ANGLE_LSB_RAD);
    c->yaw = fixed_i16(t->yaw, WF_COMPACT_ANGLE_LSB_RAD);
    for (unsigned i = 0; i < 3; i++) {
        c->gyro[i] = fixed_i16(t->gyro[i], WF_COMPACT_RATE_LSB_RAD_S);
        c->accel[i] = fixed_i16(t->accel[i], WF_COMPACT_ACCEL_LSB_M_S2);
    }
    c->servo[0] = fixed_i16(t->servo[0], WF_COMPACT_ANGLE_LSB_RAD);
    c->servo[1] = fixed_i16(t->servo[1], WF_COMPACT_ANGLE_LSB_RAD);
    c->battery_mv = (uint16_t)fixed(t->battery_v, WF_COMPACT_BATTERY_LSB_V, 0, UINT16_MAX);
    c->status = t->status;
    c->gait_id = t->gait_id;
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
