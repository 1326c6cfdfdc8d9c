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
    wf_host_set_failsafe_compares(the_app.compare); /* what a fault handler writes */
}

size_t wf_host_board_step(uint32_t t, const uint8_t *in, size_t len, uint8_t *out, size_t cap)
{
    wf_host_set_millis(t);
    if (len > 0) {
        wf_host_feed(in, len);
    }
    wf_app_poll(&the_app);
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

size_t wf_host_config_size(void) { return sizeof(wf_config_t); }

size_t wf_host_snapshot_size(void) { return sizeof(wf_host_snapshot_t); }

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
    default:
        break;
    }
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
    default:
        break;
    }
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
