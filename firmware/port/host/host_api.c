/* SPDX-License-Identifier: Apache-2.0 */
/* The one board of a host process and the batch codec: the C API the Python tests call. */
#include <string.h>

#include "wf_host.h"

static wf_app_t the_app;

void wf_host_board_init(const wf_config_t *config)
{
    wf_config_t defaults;
    if (config == NULL) {
        wf_config_defaults(&defaults);
        config = &defaults;
    }
    wf_host_boot();
    wf_app_init(&the_app, config);
    wf_host_set_failsafe_compares(the_app.neutral_compare); /* what a fault handler writes */
}

void wf_host_board_calibration(wf_servo_trim_report_t report[2])
{
    for (unsigned i = 0; i < 2; i++) {
        const wf_servo_cal_t *cal = &the_app.config.servo_cal[i];
        report[i] = (wf_servo_trim_report_t){
            .servo = (uint8_t)(i + 1u),     .source = the_app.cal_source[i],
            .direction = cal->direction,    .reserved = 0,
            .neutral_us = cal->neutral_us,  .us_per_rad = cal->us_per_rad,
            .min_us = cal->min_us,          .max_us = cal->max_us,
        };
    }
}

size_t wf_host_calibration_size(void) { return sizeof(wf_servo_trim_report_t); }

size_t wf_host_board_step(uint32_t t, const uint8_t *in, size_t len, uint8_t *out, size_t cap)
{
    wf_host_set_millis(t);
    if (len > 0) {
        wf_host_feed(in, len);
    }
    wf_app_poll(&the_app);
    wf_host_set_failsafe_compares(the_app.neutral_compare); /* as the port's main loop does */
    return cap > 0 ? wf_host_take_output(out, cap) : 0;
}

static void copy_stats(const wf_decoder_stats_t *s, uint32_t out[12])
{
    const uint32_t values[12] = {s->bytes_in,      s->frames_ok,     s->cobs_errors,
                                 s->short_frames,  s->crc_errors,    s->unknown_type,
                                 s->length_errors, s->invalid_payload, s->overflows,
                                 s->resyncs,       s->seq_gaps,      s->seq_resets};
    memcpy(out, values, sizeof values);
}

void wf_host_board_snapshot(wf_host_snapshot_t *s)
{
    const wf_app_t *a = &the_app;
    memset(s, 0, sizeof *s);
    s->now_ms = a->now_ms;
    s->status = a->status;
    s->host_seen = a->host_seen;
    s->host_version_ok = a->host_version_ok;
    for (int i = 0; i < 2; i++) {
        s->commanded[i] = a->commanded[i];
        s->target[i] = a->target[i];
        s->compare[i] = wf_host_compare((unsigned)i);
    }
    s->roll = a->attitude.roll;
    s->pitch = a->attitude.pitch;
    s->yaw = a->attitude.yaw;
    for (int i = 0; i < 3; i++) {
        s->gyro[i] = a->imu.gyro[i];
        s->accel[i] = a->imu.accel[i];
        s->raw_accel[i] = a->imu.raw_accel[i];
        s->raw_gyro[i] = a->imu.raw_gyro[i];
    }
    s->battery_v = a->battery_v;
    s->commands_applied = a->commands_applied;
    s->commands_ignored = a->commands_ignored;
    s->frames_sent = a->frames_sent;
    s->errors_sent = a->errors_sent;
    s->tx_bytes_dropped = a->tx_bytes_dropped;
    copy_stats(&a->decoder.stats, s->decoder);
    s->config_rejected = a->config_rejected;
}

void wf_host_board_gait(wf_host_gait_snapshot_t *s)
{
    const wf_app_t *a = &the_app;
    memset(s, 0, sizeof *s);
    s->gait_mode = a->gait_mode;
    s->gap = a->gap;
    s->gait_id = a->gait_id;
    s->cpg_time_ms = a->cpg_time_ms;
    s->cpg_steps = a->cpg.steps;
    for (unsigned i = 0; i < 2; i++) {
        s->phase[i] = wf_cpg_phase(&a->cpg, i);
        s->r[i] = a->cpg.r[i];
        s->dr[i] = a->cpg.dr[i];
        s->b[i] = a->cpg.b[i];
        s->db[i] = a->cpg.db[i];
        s->target[i] = a->target[i];
        s->compare[i] = wf_host_compare(i);
    }
    wf_cpg_output(&a->cpg, s->output, s->rate);
    s->status = a->status;
    s->ack_count = a->ack_count;
    s->telemetry_form = a->config.telemetry_form;
    s->acks_dropped = a->acks_dropped;
    s->gaits_accepted = a->gaits_accepted;
    s->gaits_refused = a->gaits_refused;
    s->telemetry_period_ms = a->config.telemetry_period_ms;
    s->health_period_ms = a->config.health_period_ms;
    s->link_timeout_ms = a->config.link_timeout_ms;
    s->coast_ms = a->config.coast_ms;
    s->params = a->cpg.params;
}

size_t wf_host_gait_snapshot_size(void) { return sizeof(wf_host_gait_snapshot_t); }

void wf_host_board_health(wf_health_t *health) { *health = the_app.health; }

size_t wf_host_health_size(void) { return sizeof(wf_health_t); }

/* --- a lone CPG ------------------------------------------------------------------------- */
static wf_cpg_t lone_cpg;

void wf_host_cpg_init(const wf_cpg_params_t *params) { wf_cpg_init(&lone_cpg, params); }

void wf_host_cpg_set_params(const wf_cpg_params_t *params)
{
    wf_cpg_set_params(&lone_cpg, params);
}

void wf_host_cpg_run(uint32_t steps, float *angles, float *phases)
{
    for (uint32_t k = 0; k < steps; k++) {
        wf_cpg_step(&lone_cpg);
        if (angles != NULL) {
            wf_cpg_output(&lone_cpg, angles + 2 * k, NULL);
        }
        if (phases != NULL) {
            phases[2 * k] = wf_cpg_phase(&lone_cpg, 0);
            phases[2 * k + 1] = wf_cpg_phase(&lone_cpg, 1);
        }
    }
}

void wf_host_cpg_state(float state[10])
{
    const wf_cpg_t *c = &lone_cpg;
    const float values[10] = {wf_cpg_phase(c, 0), wf_cpg_phase(c, 1), c->r[0], c->r[1],
                              c->dr[0],           c->dr[1],           c->b[0], c->b[1],
                              c->db[0],           c->db[1]};
    memcpy(state, values, sizeof values);
}

void wf_host_cpg_output(float angle[2], float rate[2]) { wf_cpg_output(&lone_cpg, angle, rate); }

size_t wf_host_cpg_params_size(void) { return sizeof(wf_cpg_params_t); }

size_t wf_host_msg_size(void) { return sizeof(wf_host_msg_t); }

size_t wf_host_config_size(void) { return sizeof(wf_config_t); }

size_t wf_host_snapshot_size(void) { return sizeof(wf_host_snapshot_t); }

/* The float fields of a GAIT in wire order. */
static void gait_floats(const wf_cpg_params_t *p, float out[10])
{
    const float v[10] = {p->frequency_hz, p->amplitude[0], p->amplitude[1], p->offset[0],
                         p->offset[1],    p->w12,          p->w21,          p->phi12,
                         p->phi21,        p->alpha};
    memcpy(out, v, sizeof v);
}

static void gait_from_floats(const float v[10], wf_cpg_params_t *p)
{
    p->frequency_hz = v[0];
    p->amplitude[0] = v[1];
    p->amplitude[1] = v[2];
    p->offset[0] = v[3];
    p->offset[1] = v[4];
    p->w12 = v[5];
    p->w21 = v[6];
    p->phi12 = v[7];
    p->phi21 = v[8];
    p->alpha = v[9];
}

/* The integer fields of a message in n's order (wf_host.h); returns how many. */
static size_t ints_of(const wf_msg_t *m, int64_t n[WF_HOST_MSG_INTS])
{
    switch (m->type) {
    case WF_MSG_TELEMETRY:
        n[0] = m->u.telemetry.gait_id;
        return 1;
    case WF_MSG_LINK_CONFIG: {
        const wf_link_config_t *c = &m->u.link_config;
        const int64_t v[5] = {c->telemetry_period_ms, c->telemetry_form, c->health_period_ms,
                              c->link_timeout_ms, c->coast_ms};
        memcpy(n, v, sizeof v);
        return 5;
    }
    case WF_MSG_ACK:
        n[0] = m->u.ack.acked_type;
        n[1] = m->u.ack.acked_seq;
        n[2] = m->u.ack.result;
        return 3;
    case WF_MSG_GAIT:
        n[0] = m->u.gait.gait_id;
        return 1;
    case WF_MSG_SERVO_TRIM: {
        const wf_servo_trim_t *t = &m->u.servo_trim;
        const int64_t v[4] = {t->servo, t->op, t->direction, t->reserved};
        memcpy(n, v, sizeof v);
        return 4;
    }
    case WF_MSG_SERVO_TRIM_REPORT: {
        const wf_servo_trim_report_t *r = &m->u.servo_trim_report;
        const int64_t v[4] = {r->servo, r->source, r->direction, r->reserved};
        memcpy(n, v, sizeof v);
        return 4;
    }
    case WF_MSG_TELEMETRY_COMPACT: {
        const wf_telemetry_compact_t *c = &m->u.compact;
        const int64_t v[15] = {c->board_time_ms, c->roll,     c->pitch,    c->yaw,
                               c->gyro[0],       c->gyro[1],  c->gyro[2],  c->accel[0],
                               c->accel[1],      c->accel[2], c->servo[0], c->servo[1],
                               c->battery_mv,    c->status,   c->gait_id};
        memcpy(n, v, sizeof v);
        return 15;
    }
    case WF_MSG_HEALTH: {
        const wf_health_t *h = &m->u.health;
        const int64_t v[20] = {h->reset_cause,      h->clock_source,     h->flags,
                               h->fault_pc,         h->fault_lr,         h->fault_cfsr,
                               h->fault_hfsr,       h->uptime_ms,        h->stack_free_min,
                               h->stack_size,       h->uart_rx_overruns, h->tx_bytes_dropped,
                               h->rx_crc,           h->rx_frame,         h->rx_unknown_type,
                               h->rx_length,        h->rx_invalid,       h->imu_faults,
                               h->imu_recoveries,   h->i2c_bus_recoveries};
        memcpy(n, v, sizeof v);
        return 20;
    }
    default:
        return 0;
    }
}

static void ints_to(const int64_t n[WF_HOST_MSG_INTS], wf_msg_t *m)
{
    switch (m->type) {
    case WF_MSG_TELEMETRY:
        m->u.telemetry.gait_id = (uint16_t)n[0];
        break;
    case WF_MSG_LINK_CONFIG: {
        wf_link_config_t *c = &m->u.link_config;
        c->telemetry_period_ms = (uint16_t)n[0];
        c->telemetry_form = (uint8_t)n[1];
        c->health_period_ms = (uint16_t)n[2];
        c->link_timeout_ms = (uint16_t)n[3];
        c->coast_ms = (uint16_t)n[4];
        break;
    }
    case WF_MSG_ACK:
        m->u.ack.acked_type = (uint8_t)n[0];
        m->u.ack.acked_seq = (uint16_t)n[1];
        m->u.ack.result = (uint8_t)n[2];
        break;
    case WF_MSG_GAIT:
        m->u.gait.gait_id = (uint16_t)n[0];
        break;
    case WF_MSG_SERVO_TRIM: {
        wf_servo_trim_t *t = &m->u.servo_trim;
        t->servo = (uint8_t)n[0];
        t->op = (uint8_t)n[1];
        t->direction = (int8_t)n[2];
        t->reserved = (uint8_t)n[3];
        break;
    }
    case WF_MSG_SERVO_TRIM_REPORT: {
        wf_servo_trim_report_t *r = &m->u.servo_trim_report;
        r->servo = (uint8_t)n[0];
        r->source = (uint8_t)n[1];
        r->direction = (int8_t)n[2];
        r->reserved = (uint8_t)n[3];
        break;
    }
    case WF_MSG_TELEMETRY_COMPACT: {
        wf_telemetry_compact_t *c = &m->u.compact;
        int16_t *const fields[11] = {&c->roll,     &c->pitch,    &c->yaw,      &c->gyro[0],
                                     &c->gyro[1],  &c->gyro[2],  &c->accel[0], &c->accel[1],
                                     &c->accel[2], &c->servo[0], &c->servo[1]};
        c->board_time_ms = (uint32_t)n[0];
        for (int i = 0; i < 11; i++) {
            *fields[i] = (int16_t)n[1 + i];
        }
        c->battery_mv = (uint16_t)n[12];
        c->status = (uint16_t)n[13];
        c->gait_id = (uint16_t)n[14];
        break;
    }
    case WF_MSG_HEALTH: {
        wf_health_t *h = &m->u.health;
        uint32_t *const words[12] = {&h->fault_pc,         &h->fault_lr,
                                     &h->fault_cfsr,       &h->fault_hfsr,
                                     &h->uptime_ms,        &h->uart_rx_overruns,
                                     &h->tx_bytes_dropped, &h->rx_crc,
                                     &h->rx_frame,         &h->rx_unknown_type,
                                     &h->rx_length,        &h->rx_invalid};
        static const int word_index[12] = {3, 4, 5, 6, 7, 10, 11, 12, 13, 14, 15, 16};
        h->reset_cause = (uint8_t)n[0];
        h->clock_source = (uint8_t)n[1];
        h->flags = (uint8_t)n[2];
        for (int i = 0; i < 12; i++) {
            *words[i] = (uint32_t)n[word_index[i]];
        }
        h->stack_free_min = (uint16_t)n[8];
        h->stack_size = (uint16_t)n[9];
        h->imu_faults = (uint16_t)n[17];
        h->imu_recoveries = (uint16_t)n[18];
        h->i2c_bus_recoveries = (uint16_t)n[19];
        break;
    }
    default:
        break;
    }
}

static void flatten(const wf_msg_t *m, wf_host_msg_t *f)
{
    memset(f, 0, sizeof *f);
    f->type = m->type;
    f->seq = m->seq;
    switch (m->type) {
    case WF_MSG_HEARTBEAT:
        f->version_or_code = m->u.heartbeat.version;
        f->role = m->u.heartbeat.role;
        f->uptime_or_time_ms = m->u.heartbeat.uptime_ms;
        break;
    case WF_MSG_SERVO_CMD:
        f->f[0] = m->u.servo_cmd.servo[0];
        f->f[1] = m->u.servo_cmd.servo[1];
        break;
    case WF_MSG_TELEMETRY: {
        const wf_telemetry_t *t = &m->u.telemetry;
        const float v[12] = {t->roll,     t->pitch,    t->yaw,      t->gyro[0],
                             t->gyro[1],  t->gyro[2],  t->accel[0], t->accel[1],
                             t->accel[2], t->servo[0], t->servo[1], t->battery_v};
        memcpy(f->f, v, sizeof v);
        f->uptime_or_time_ms = t->board_time_ms;
        f->ref_seq_or_status = t->status;
        break;
    }
    case WF_MSG_ERROR:
        f->version_or_code = m->u.error.code;
        f->ref_seq_or_status = m->u.error.ref_seq;
        break;
    case WF_MSG_GAIT:
        gait_floats(&m->u.gait.params, f->f);
        break;
    case WF_MSG_SERVO_TRIM:
        f->f[0] = m->u.servo_trim.neutral_us;
        f->f[1] = m->u.servo_trim.us_per_rad;
        break;
    case WF_MSG_SERVO_TRIM_REPORT: {
        const wf_servo_trim_report_t *r = &m->u.servo_trim_report;
        const float v[4] = {r->neutral_us, r->us_per_rad, r->min_us, r->max_us};
        memcpy(f->f, v, sizeof v);
        break;
    }
    default:
        break;
    }
    (void)ints_of(m, f->n);
}

static void unflatten(const wf_host_msg_t *f, wf_msg_t *m)
{
    memset(m, 0, sizeof *m);
    m->type = f->type;
    m->seq = f->seq;
    switch (f->type) {
    case WF_MSG_HEARTBEAT:
        m->u.heartbeat.version = f->version_or_code;
        m->u.heartbeat.role = f->role;
        m->u.heartbeat.uptime_ms = f->uptime_or_time_ms;
        break;
    case WF_MSG_SERVO_CMD:
        m->u.servo_cmd.servo[0] = f->f[0];
        m->u.servo_cmd.servo[1] = f->f[1];
        break;
    case WF_MSG_TELEMETRY: {
        wf_telemetry_t *t = &m->u.telemetry;
        float *const v[12] = {&t->roll,     &t->pitch,    &t->yaw,      &t->gyro[0],
                              &t->gyro[1],  &t->gyro[2],  &t->accel[0], &t->accel[1],
                              &t->accel[2], &t->servo[0], &t->servo[1], &t->battery_v};
        for (int i = 0; i < 12; i++) {
            *v[i] = f->f[i];
        }
        t->board_time_ms = f->uptime_or_time_ms;
        t->status = f->ref_seq_or_status;
        break;
    }
    case WF_MSG_ERROR:
        m->u.error.code = f->version_or_code;
        m->u.error.ref_seq = f->ref_seq_or_status;
        break;
    case WF_MSG_GAIT:
        gait_from_floats(f->f, &m->u.gait.params);
        break;
    case WF_MSG_SERVO_TRIM:
        m->u.servo_trim.neutral_us = f->f[0];
        m->u.servo_trim.us_per_rad = f->f[1];
        break;
    case WF_MSG_SERVO_TRIM_REPORT: {
        wf_servo_trim_report_t *r = &m->u.servo_trim_report;
        r->neutral_us = f->f[0];
        r->us_per_rad = f->f[1];
        r->min_us = f->f[2];
        r->max_us = f->f[3];
        break;
    }
    default:
        break;
    }
    ints_to(f->n, m);
}

size_t wf_host_decode_stream(const uint8_t *in, size_t len, wf_host_msg_t *out, size_t max,
                             uint32_t *stats)
{
    static wf_decoder_t decoder; /* 100 bytes: static keeps deep test stacks small */
    wf_decoder_init(&decoder);
    size_t n = 0;
    for (size_t i = 0; i < len; i++) {
        wf_msg_t msg;
        if (wf_decoder_push(&decoder, in[i], &msg) == WF_RX_FRAME && n < max) {
            flatten(&msg, &out[n++]);
        }
    }
    if (stats != NULL) {
        copy_stats(&decoder.stats, stats);
    }
    return n;
}

size_t wf_host_encode_stream(const wf_host_msg_t *msgs, size_t n, uint8_t *out, size_t cap)
{
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        wf_msg_t msg;
        unflatten(&msgs[i], &msg);
        const size_t len = wf_encode_frame(&msg, out + used, cap - used);
        if (len == 0) {
            return 0;
        }
        used += len;
    }
    return used;
}
