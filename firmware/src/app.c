/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The application: link logic, the two drive modes, failsafe, servo output, sensors and the
 * telemetry schedule.
 *
 * Stream mode (from boot): the host's SERVO_CMD sets the servos; a failsafe moves them to
 * neutral at a bounded slew. Gait mode (from an accepted GAIT): the board integrates eq 1
 * itself (wf/cpg.h) one 1 ms step per millisecond of its clock, starting from the angles
 * stream mode held, and through a link gap it coasts on the last gait, then brings the
 * oscillator to rest through its own convergence.
 *
 * The firmware rules are the virtual fish's (wirefish_sim.virtual_fish), and
 * test/firmware/test_fw_virtual_fish_parity.py holds the two to the same output frames and
 * states. One poll: step the CPG up to now (gait mode); read every byte the UART holds (one
 * chunk, up to 512), act on each valid frame, send one ERROR per kind of drop not yet reported
 * (at most one per kind per 20 ms); send one waiting ACK; sample the sensors; run the gap
 * rules and the failsafe and set the servos; send the telemetry, the heartbeat and the HEALTH
 * that are due, in that order, then a boot SERVO_TRIM_REPORT when one is due: at most one
 * frame of each kind per poll (ERROR aside).
 */
#include "wf/app.h"

#include <math.h>
#include <string.h>

enum {
    RX_CHUNK = 64,
    RX_CHUNKS_PER_POLL = 8, /* 512 bytes: bounds one poll's work whatever the UART holds */
    /* An absent or failed IMU is probed again this often: a probe of an empty bus costs one
     * NACKed address (25 us at 400 kHz) and a bus recovery that finds it idle, so a sensor
     * that comes back (a short gone, a reset part) is trusted again within ~0.1 s. */
    IMU_PROBE_PERIOD_MS = 100,
};

static bool due(uint32_t now, uint32_t at)
{
    return (int32_t)(now - at) >= 0;
}

void wf_config_defaults(wf_config_t *config)
{
    memset(config, 0, sizeof *config);
    config->command_timeout_ms = 500;
    config->heartbeat_timeout_ms = 1500;
    config->telemetry_period_ms = 10;
    config->heartbeat_period_ms = 500;
    config->imu_period_ms = 5;
    config->servo_frame_hz = 50;
    /* The largest binary32 not above pi/2, the virtual fish's limit: a command clamps here
     * exactly when it clamps there (the command is a binary32, the limit a double). */
    config->servo_limit_rad = 1.57079625f;
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        /* A 180-degree hobby servo: 500..2500 us over -pi/2..pi/2, 1500 us neutral. */
        config->servo_cal[i].neutral_us = 1500.0f;
        config->servo_cal[i].us_per_rad = 636.619772f;
        config->servo_cal[i].direction = 1;
        config->servo_cal[i].min_us = 500.0f;
        config->servo_cal[i].max_us = 2500.0f;
    }
    /* The board's mounting: the MPU6050's +Y to the head, +X to the fish's right, +Z up. */
    config->imu_axes[0] = 2;
    config->imu_axes[1] = -1;
    config->imu_axes[2] = 3;
    config->imu_mode = WF_IMU_MPU6050;
    config->attitude_tau_s = 1.0f;
    /* 3.3 V reference over 4095 counts behind a 3:1 divider (2S LiPo, 8.4 V full). */
    config->battery_v_per_count = 3.3f * 3.0f / 4095.0f;
    config->low_battery_v = 6.6f;
    config->health_period_ms = 2000;
    config->link_timeout_ms = 1500;
    /* A few tail beats ride out a burst loss at the surface; at 0.3 m/s, 3 s is <= 1 m of
     * unguided swimming. */
    config->coast_ms = 3000;
    config->telemetry_form = WF_TELEMETRY_FULL;
    /* Neutral from the far limit (pi/2) in 0.8 s: a slew the reel's wires follow, where a
     * step at the servo's full speed snaps the tail. */
    config->failsafe_slew_rad_s = 2.0f;
}

static bool in_range(float value, float low, float high)
{
    return value > low && value <= high; /* false for NaN */
}

/* The servo frame's length (us): no pulse is longer. */
static float frame_us(const wf_config_t *c)
{
    return 1e6f / (float)c->servo_frame_hz;
}

bool wf_config_valid(const wf_config_t *c)
{
    bool ok = c->command_timeout_ms > 0 && c->heartbeat_timeout_ms > 0 &&
              c->telemetry_period_ms > 0 && c->heartbeat_period_ms > 0 &&
              c->imu_period_ms > 0 && c->command_timeout_ms < 0x80000000u &&
              c->heartbeat_timeout_ms < 0x80000000u && c->telemetry_period_ms < 0x80000000u &&
              c->heartbeat_period_ms < 0x80000000u && c->imu_period_ms < 0x80000000u &&
              c->servo_frame_hz >= 50 && c->servo_frame_hz <= 333 &&
              in_range(c->servo_limit_rad, 0.0f, 3.14159265f) &&
              wf_mpu6050_axes_valid(c->imu_axes) &&
              (c->imu_mode == WF_IMU_MPU6050 || c->imu_mode == WF_IMU_SYNTHETIC) &&
              in_range(c->attitude_tau_s, 0.0f, 1000.0f) &&
              in_range(c->battery_v_per_count, 0.0f, 1.0f) &&
              in_range(c->low_battery_v, -1.0f, 100.0f) &&
              (c->health_period_ms == 0 || (c->health_period_ms >= WF_LINK_HEALTH_MIN_MS &&
                                            c->health_period_ms <= WF_LINK_HEALTH_MAX_MS)) &&
              c->link_timeout_ms >= WF_LINK_TIMEOUT_MIN_MS &&
              c->link_timeout_ms <= WF_LINK_TIMEOUT_MAX_MS &&
              c->coast_ms <= WF_LINK_COAST_MAX_MS &&
              (c->telemetry_form == WF_TELEMETRY_FULL ||
               c->telemetry_form == WF_TELEMETRY_COMPACT) &&
              in_range(c->failsafe_slew_rad_s, 0.0f, 1000.0f);
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const wf_servo_cal_t *cal = &c->servo_cal[i];
        ok = ok && in_range(cal->neutral_us, 0.0f, 20000.0f) &&
             in_range(cal->us_per_rad, 0.0f, 100000.0f) &&
             (cal->direction == 1 || cal->direction == -1) &&
             wf_servo_cal_fits(cal, c->servo_limit_rad, frame_us(c));
    }
    return ok;
}

/* --- output ----------------------------------------------------------------------------- */
static void send(wf_app_t *app, wf_msg_t *msg)
{
    uint8_t wire[WF_MAX_WIRE];
    msg->seq = app->tx_seq++;
    const size_t len = wf_encode_frame(msg, wire, sizeof wire);
    app->frames_sent++;
    if (wf_hal_uart_write(wire, len) != len) {
        /* No room for the whole frame: none of it goes (wf/hal.h), so nothing cut reaches the
         * wire; the receiver's sequence count shows the loss, HEALTH the bytes. */
        app->tx_bytes_dropped += (uint32_t)len;
    }
}

static void send_error(wf_app_t *app, uint8_t code, uint16_t ref_seq)
{
    wf_msg_t msg = {.type = WF_MSG_ERROR};
    msg.u.error.code = code;
    msg.u.error.ref_seq = ref_seq;
    app->errors_sent++;
    send(app, &msg);
}

static void send_heartbeat(wf_app_t *app)
{
    wf_msg_t msg = {.type = WF_MSG_HEARTBEAT};
    msg.u.heartbeat.version = WF_PROTOCOL_VERSION;
    msg.u.heartbeat.role = WF_ROLE_FISH;
    msg.u.heartbeat.uptime_ms = app->now_ms;
    send(app, &msg);
}

static void send_telemetry(wf_app_t *app)
{
    wf_msg_t msg = {.type = WF_MSG_TELEMETRY};
    wf_telemetry_t full;
    wf_telemetry_t *t = &full;
    t->board_time_ms = app->now_ms;
    t->roll = app->attitude.roll;
    t->pitch = app->attitude.pitch;
    t->yaw = app->attitude.yaw;
    for (int i = 0; i < 3; i++) {
        t->gyro[i] = app->imu.gyro[i];
        t->accel[i] = app->imu.accel[i];
    }
    /* A hobby servo reports nothing back: the angles are the ones commanded (PROTOCOL.md). */
    t->servo[0] = app->target[0];
    t->servo[1] = app->target[1];
    t->battery_v = app->have_battery ? app->battery_v : 0.0f;
    t->status = app->status;
    t->gait_id = app->gait_mode ? app->gait_id : 0;
    if (app->config.telemetry_form == WF_TELEMETRY_COMPACT) {
        msg.type = WF_MSG_TELEMETRY_COMPACT;
        wf_telemetry_compact(t, &msg.u.compact);
    } else {
        msg.u.telemetry = full;
    }
    send(app, &msg);
}

static void send_health(wf_app_t *app)
{
    wf_health_t *h = &app->health;
    const wf_decoder_stats_t *s = &app->decoder.stats;
    wf_hal_health_port(h);
    h->uptime_ms = app->now_ms;
    h->tx_bytes_dropped = app->tx_bytes_dropped;
    h->rx_crc = s->crc_errors;
    h->rx_frame = s->cobs_errors + s->short_frames + s->overflows;
    h->rx_unknown_type = s->unknown_type;
    h->rx_length = s->length_errors;
    h->rx_invalid = s->invalid_payload;
    wf_msg_t msg = {.type = WF_MSG_HEALTH};
    msg.u.health = *h;
    send(app, &msg);
}

/* servo 0 or 1: its calibration as it is in force now, and where it comes from. */
static void send_trim_report(wf_app_t *app, unsigned servo)
{
    const wf_servo_cal_t *cal = &app->config.servo_cal[servo];
    wf_msg_t msg = {.type = WF_MSG_SERVO_TRIM_REPORT};
    wf_servo_trim_report_t *r = &msg.u.servo_trim_report;
    r->servo = (uint8_t)(servo + 1u);
    r->source = app->cal_source[servo];
    r->direction = cal->direction;
    r->reserved = 0;
    r->neutral_us = cal->neutral_us;
    r->us_per_rad = cal->us_per_rad;
    r->min_us = cal->min_us;
    r->max_us = cal->max_us;
    send(app, &msg);
}

/* The oldest waiting ACK; a refused GAIT's ERROR (its code, the GAIT's seq) goes just before
 * it, an accepted SERVO_TRIM's SERVO_TRIM_REPORT just after it. True when a report went. */
static bool send_ack(wf_app_t *app)
{
    if (app->ack_count == 0) {
        return false;
    }
    wf_msg_t msg = {.type = WF_MSG_ACK};
    msg.u.ack = app->acks[0];
    const uint8_t report = app->ack_report[0];
    app->ack_count--;
    memmove(app->acks, app->acks + 1, app->ack_count * sizeof app->acks[0]);
    memmove(app->ack_report, app->ack_report + 1, app->ack_count * sizeof app->ack_report[0]);
    if (msg.u.ack.acked_type == WF_MSG_GAIT && msg.u.ack.result != 0) {
        send_error(app, msg.u.ack.result, msg.u.ack.acked_seq);
    }
    send(app, &msg);
    if (report != 0) {
        send_trim_report(app, report - 1u);
    }
    return report != 0;
}

/* report: the servo (1, 2) whose SERVO_TRIM_REPORT follows the ACK, 0 for none. */
static void queue_ack_report(wf_app_t *app, const wf_msg_t *msg, uint8_t result, uint8_t report)
{
    if (app->ack_count >= WF_ACK_QUEUE) {
        app->acks_dropped++;
        return;
    }
    app->ack_report[app->ack_count] = report;
    wf_ack_t *ack = &app->acks[app->ack_count++];
    ack->acked_type = msg->type;
    ack->acked_seq = msg->seq;
    ack->result = result;
}

static void queue_ack(wf_app_t *app, const wf_msg_t *msg, uint8_t result)
{
    queue_ack_report(app, msg, result, 0);
}

static uint16_t saturating_increment(uint16_t count)
{
    return count == UINT16_MAX ? count : (uint16_t)(count + 1u);
}

/* --- input ------------------------------------------------------------------------------ */
static void update_outputs(wf_app_t *app);

static void leave_gait_mode(wf_app_t *app)
{
    app->gait_mode = false;
    app->gait_id = 0;
    app->gap = WF_GAP_NONE;
}

/* True for the frames a host sends: they, and only they, show that the link is up. */
static bool from_host(const wf_msg_t *msg)
{
    switch (msg->type) {
    case WF_MSG_HEARTBEAT:
        return msg->u.heartbeat.role == WF_ROLE_HOST; /* not our own echoed, not a fish's */
    case WF_MSG_LINK_CONFIG:
    case WF_MSG_SERVO_CMD:
    case WF_MSG_GAIT:
    case WF_MSG_SERVO_TRIM:
        return true;
    default:
        return false; /* TELEMETRY, ACK, HEALTH, ERROR, SERVO_TRIM_REPORT are a fish's */
    }
}

static void on_link_config(wf_app_t *app, const wf_msg_t *msg)
{
    const wf_link_config_t *l = &msg->u.link_config;
    uint8_t result = 0;
    if (!app->host_version_ok) {
        result = WF_ERR_VERSION_MISMATCH;
    } else if (!wf_link_config_valid(l)) {
        result = WF_ERR_COMMAND_OUT_OF_RANGE;
    } else {
        wf_config_t *c = &app->config;
        c->telemetry_period_ms = l->telemetry_period_ms;
        c->telemetry_form = l->telemetry_form;
        c->health_period_ms = l->health_period_ms;
        c->link_timeout_ms = l->link_timeout_ms;
        c->coast_ms = l->coast_ms;
        /* At once: both schedules start again from now. */
        app->next_telemetry_ms = app->now_ms + c->telemetry_period_ms;
        app->next_health_ms = app->now_ms + c->health_period_ms;
    }
    queue_ack(app, msg, result);
}

static void on_gait(wf_app_t *app, const wf_msg_t *msg)
{
    uint8_t result = 0;
    if (!app->host_version_ok) {
        result = WF_ERR_VERSION_MISMATCH;
    } else if (!wf_gait_valid(&msg->u.gait, app->config.servo_limit_rad)) {
        result = WF_ERR_COMMAND_OUT_OF_RANGE;
    }
    if (result != 0) {
        app->gaits_refused++;
        queue_ack(app, msg, result);
        return;
    }
    app->gait = msg->u.gait.params;
    app->gait_id = msg->u.gait.gait_id;
    if (app->gait_mode) {
        wf_cpg_set_params(&app->cpg, &app->gait); /* targets only: no step */
    } else {
        /* From rest at this poll's time, but with the offsets where stream mode left the
         * servos (the last command, or part way through the failsafe's slew): the output
         * starts at the angles the servos hold and converges to the gait through alpha. */
        app->gait_mode = true;
        wf_cpg_start(&app->cpg, &app->gait, app->target);
        app->cpg_time_ms = app->now_ms;
    }
    app->gaits_accepted++;
    queue_ack(app, msg, 0);
}

/* --- calibration ------------------------------------------------------------------------ */
static uint32_t neutral_compare(const wf_app_t *app, unsigned servo)
{
    return wf_servo_compare(&app->config.servo_cal[servo], 0.0f, wf_hal_pwm_ticks_per_us(),
                            frame_us(&app->config));
}

/* The build's calibration of servo (0, 1) with the given values: true when it is one the
 * board may run (direction +-1, gain > 0, every pulse of the limit's range within the
 * build's min_us..max_us and the frame). NaN fails. */
static bool trim_fits(const wf_app_t *app, unsigned servo, float neutral_us, float us_per_rad,
                      int8_t direction, wf_servo_cal_t *cal)
{
    *cal = app->cal_defaults[servo];
    cal->neutral_us = neutral_us;
    cal->us_per_rad = us_per_rad;
    cal->direction = direction;
    return (direction == 1 || direction == -1) && us_per_rad > 0.0f &&
           wf_servo_cal_fits(cal, app->config.servo_limit_rad, frame_us(&app->config));
}

static void set_calibration(wf_app_t *app, unsigned servo, const wf_servo_cal_t *cal,
                            wf_cal_source_t source)
{
    app->config.servo_cal[servo] = *cal;
    app->cal_source[servo] = (uint8_t)source;
    app->neutral_compare[servo] = neutral_compare(app, servo);
}

/* At boot: the stored record's servos with valid 1 that fit the build run on it (STORED), the
 * others on the build's values (DEFAULTS). */
static void load_calibration(wf_app_t *app)
{
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        app->cal_defaults[i] = app->config.servo_cal[i];
        app->cal_source[i] = WF_CAL_DEFAULTS;
    }
    (void)wf_cal_store_load(&app->cal_stored); /* none, or unreadable: all zero, none valid */
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const wf_cal_entry_t *e = &app->cal_stored.servo[i];
        wf_servo_cal_t cal;
        if (e->valid == 1 && trim_fits(app, i, e->neutral_us, e->us_per_rad, e->direction,
                                       &cal)) {
            set_calibration(app, i, &cal, WF_CAL_STORED);
        }
    }
}

/* SET, SAVE or FACTORY of servo (0, 1), already judged in range and allowed now. SAVE and
 * FACTORY write a record first (the other servo's entry as stored) and change nothing when
 * that fails. */
static bool apply_trim(wf_app_t *app, const wf_servo_trim_t *t, unsigned servo,
                       const wf_servo_cal_t *cal)
{
    if (t->op == WF_TRIM_SET) {
        set_calibration(app, servo, cal, WF_CAL_LIVE);
        return true;
    }
    wf_cal_record_t record = app->cal_stored;
    wf_cal_entry_t *e = &record.servo[servo];
    memset(e, 0, sizeof *e); /* FACTORY: valid 0 and zero values */
    if (t->op == WF_TRIM_SAVE) {
        e->neutral_us = cal->neutral_us;
        e->us_per_rad = cal->us_per_rad;
        e->direction = cal->direction;
        e->valid = 1;
    }
    if (!wf_cal_store_append(&record)) {
        return false;
    }
    app->cal_stored = record;
    set_calibration(app, servo, cal, t->op == WF_TRIM_SAVE ? WF_CAL_STORED : WF_CAL_DEFAULTS);
    return true;
}

/* PROTOCOL.md's order: the host's version, the fields' ranges and the fit (6), the mode (7:
 * only READ in gait mode), the storage (8); then applied, and the ACK of 0 takes the servo's
 * report with it. */
static void on_servo_trim(wf_app_t *app, const wf_msg_t *msg)
{
    const wf_servo_trim_t *t = &msg->u.servo_trim;
    const unsigned servo = t->servo - 1u; /* wraps for servo 0: out of range below */
    const bool sets = t->op == WF_TRIM_SET || t->op == WF_TRIM_SAVE;
    wf_servo_cal_t cal;
    uint8_t result = 0;
    if (!app->host_version_ok) {
        result = WF_ERR_VERSION_MISMATCH;
    } else if (servo >= WF_SERVO_COUNT || t->op > WF_TRIM_FACTORY || t->reserved != 0 ||
               (sets && !trim_fits(app, servo, t->neutral_us, t->us_per_rad, t->direction,
                                   &cal))) {
        result = WF_ERR_COMMAND_OUT_OF_RANGE;
    } else if (t->op != WF_TRIM_READ && app->gait_mode) {
        result = WF_ERR_NOT_NOW;
    } else {
        if (t->op == WF_TRIM_FACTORY) {
            cal = app->cal_defaults[servo];
        }
        if (t->op != WF_TRIM_READ && !apply_trim(app, t, servo, &cal)) {
            result = WF_ERR_STORAGE_FAILED;
        }
    }
    if (result == 0) {
        app->trims_accepted++;
    } else {
        app->trims_refused++;
    }
    queue_ack_report(app, msg, result, result == 0 ? t->servo : 0);
}

static void on_frame(wf_app_t *app, const wf_msg_t *msg)
{
    if (!from_host(msg)) {
        return;
    }
    app->last_host_frame_ms = app->now_ms;
    if (app->gap == WF_GAP_RESTING) {
        wf_cpg_set_params(&app->cpg, &app->gait); /* the last gait again, converging */
    }
    app->gap = WF_GAP_NONE;
    switch (msg->type) {
    case WF_MSG_HEARTBEAT:
        app->host_seen = true;
        app->host_version_ok = msg->u.heartbeat.version == WF_PROTOCOL_VERSION;
        if (!app->host_version_ok) {
            send_error(app, WF_ERR_VERSION_MISMATCH, msg->seq);
            leave_gait_mode(app); /* stream mode's failsafe: to neutral, slewed */
        }
        app->have_heartbeat = true;
        app->last_heartbeat_ms = app->now_ms;
        return;
    case WF_MSG_LINK_CONFIG:
        on_link_config(app, msg);
        return;
    case WF_MSG_GAIT:
        on_gait(app, msg);
        return;
    case WF_MSG_SERVO_TRIM:
        on_servo_trim(app, msg);
        return;
    case WF_MSG_SERVO_CMD:
        if (!app->host_version_ok) {
            app->commands_ignored++;
            return;
        }
        leave_gait_mode(app);
        app->commanded[0] = msg->u.servo_cmd.servo[0];
        app->commanded[1] = msg->u.servo_cmd.servo[1];
        app->have_command = true;
        app->last_command_ms = app->now_ms;
        app->commands_applied++;
        /* Each command reaches the compare register, also when several arrive in a poll. */
        update_outputs(app);
        return;
    default:
        return;
    }
}

/* One ERROR per kind of dropped run seen since that kind's last ERROR (ref_seq 0: a dropped
 * frame's seq is not to be trusted), in code order, after the chunk's frames; at most one per
 * kind per WF_ERROR_MIN_INTERVAL_MS (drops in between go in the next). */
static void report_drops(wf_app_t *app)
{
    const wf_decoder_stats_t *s = &app->decoder.stats;
    const uint32_t counts[WF_REPORTED_KINDS] = {
        s->crc_errors, s->cobs_errors + s->short_frames + s->overflows, s->unknown_type,
        s->length_errors, s->invalid_payload,
    };
    static const uint8_t codes[WF_REPORTED_KINDS] = {
        WF_ERR_BAD_CRC, WF_ERR_BAD_FRAME, WF_ERR_UNKNOWN_TYPE, WF_ERR_BAD_LENGTH,
        WF_ERR_COMMAND_OUT_OF_RANGE,
    };
    for (unsigned i = 0; i < WF_REPORTED_KINDS; i++) {
        if (counts[i] != app->reported[i] && due(app->now_ms, app->report_due_ms[i])) {
            app->reported[i] = counts[i];
            app->report_due_ms[i] = app->now_ms + WF_ERROR_MIN_INTERVAL_MS;
            send_error(app, codes[i], 0);
        }
    }
}

static void receive(wf_app_t *app)
{
    uint8_t chunk[RX_CHUNK];
    for (unsigned c = 0; c < RX_CHUNKS_PER_POLL; c++) {
        const size_t n = wf_hal_uart_read(chunk, sizeof chunk);
        for (size_t i = 0; i < n; i++) {
            wf_msg_t msg;
            if (wf_decoder_push(&app->decoder, chunk[i], &msg) == WF_RX_FRAME) {
                on_frame(app, &msg);
            }
        }
        if (n < sizeof chunk) {
            break;
        }
    }
    report_drops(app);
}

/* --- sensors ---------------------------------------------------------------------------- */
static void sample_imu(wf_app_t *app)
{
    const uint32_t now = app->now_ms;
    if (!due(now, app->next_imu_ms)) {
        return;
    }
    app->next_imu_ms += app->config.imu_period_ms;
    if (due(now, app->next_imu_ms)) {
        app->next_imu_ms = now + app->config.imu_period_ms; /* fell behind: no burst */
    }
    if (app->config.imu_mode == WF_IMU_SYNTHETIC) {
        memset(&app->imu, 0, sizeof app->imu);
        app->imu.accel[2] = (float)WF_STANDARD_GRAVITY;
    } else {
        if (!app->imu.present && due(now, app->next_imu_probe_ms)) {
            app->next_imu_probe_ms = now + IMU_PROBE_PERIOD_MS;
            if (wf_mpu6050_init(&app->imu) && app->imu_lost) {
                app->imu_lost = false;
                app->health.imu_recoveries = saturating_increment(app->health.imu_recoveries);
            }
            app->imu_sampled = false; /* the first sample after a probe restarts dt */
        }
        if (!app->imu.present) {
            return;
        }
        if (!wf_mpu6050_read(&app->imu, app->config.imu_axes)) {
            app->next_imu_probe_ms = now; /* lost: probe again at once */
            app->imu_lost = true;
            app->health.imu_faults = saturating_increment(app->health.imu_faults);
            return;
        }
    }
    const float dt = app->imu_sampled ? (float)(now - app->last_imu_ms) * 1e-3f : 0.0f;
    wf_attitude_update(&app->attitude, app->imu.gyro, app->imu.accel, dt,
                       app->config.attitude_tau_s);
    app->last_imu_ms = now;
    app->imu_sampled = true;
}

static void sample_battery(wf_app_t *app)
{
    const int32_t raw = wf_hal_adc_battery_raw();
    if (raw >= 0) {
        app->have_battery = true;
        app->battery_v = (float)raw * app->config.battery_v_per_count;
    }
}

/* --- gait mode: the CPG and the gap ------------------------------------------------------ */
/* One RK4 step per millisecond of the board's clock, up to now; a backlog beyond
 * WF_CPG_MAX_LAG_MS is dropped (a pause of the gait, never a jump of its output). */
static void advance_cpg(wf_app_t *app)
{
    if (!app->gait_mode) {
        return;
    }
    if (app->now_ms - app->cpg_time_ms > WF_CPG_MAX_LAG_MS) {
        /* Stalled, or the clock went back (a huge modular lag): go on from the state. */
        app->cpg_time_ms = app->now_ms - WF_CPG_MAX_LAG_MS;
    }
    while (app->cpg_time_ms != app->now_ms) {
        wf_cpg_step(&app->cpg);
        app->cpg_time_ms += WF_CPG_STEP_MS;
    }
}

/* No valid host frame for link_timeout_ms: COASTING on the last gait; coast_ms later,
 * RESTING: amplitude and offset targets 0 (frequency, couplings, alpha kept), reached through
 * the oscillator's own convergence. RESTING holds until a host frame (on_frame) ends it. */
static void update_gap(wf_app_t *app)
{
    const wf_config_t *c = &app->config;
    if (!app->gait_mode || app->gap == WF_GAP_RESTING) {
        return;
    }
    const uint32_t quiet = app->now_ms - app->last_host_frame_ms;
    if (app->gap == WF_GAP_NONE && quiet > c->link_timeout_ms) {
        app->gap = WF_GAP_COASTING;
    }
    if (app->gap == WF_GAP_COASTING && quiet > c->link_timeout_ms + c->coast_ms) {
        app->gap = WF_GAP_RESTING;
        wf_cpg_params_t rest = app->gait;
        for (unsigned i = 0; i < WF_CPG_OSCILLATORS; i++) {
            rest.amplitude[i] = 0.0f;
            rest.offset[i] = 0.0f;
        }
        wf_cpg_set_params(&app->cpg, &rest);
    }
}

/* --- failsafe and servos ---------------------------------------------------------------- */
/* v moved toward 0 by at most step. */
static float toward_neutral(float v, float step)
{
    return v > step ? v - step : (v < -step ? v + step : 0.0f);
}

/* Stream mode: the command, or (any failsafe) a slew to neutral at failsafe_slew_rad_s;
 * returns the failsafe bits and sets *clamped when a command was beyond the limit. */
static uint16_t stream_targets(wf_app_t *app, uint32_t dt_ms, bool *clamped)
{
    const wf_config_t *c = &app->config;
    uint16_t status = 0;
    if (!app->have_command) {
        status |= WF_STATUS_FAILSAFE_COMMAND;
    }
    if (!app->have_heartbeat) {
        status |= WF_STATUS_FAILSAFE_HEARTBEAT;
    }
    if (!app->host_version_ok) {
        status |= WF_STATUS_VERSION_MISMATCH;
    }
    /* At most a second per update: a long pause reaches neutral anyway. */
    const float step =
        c->failsafe_slew_rad_s * (float)(dt_ms < 1000u ? dt_ms : 1000u) * 1e-3f;
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        if (status != 0) {
            app->target[i] = toward_neutral(app->target[i], step);
        } else {
            *clamped = *clamped || fabsf(app->commanded[i]) > c->servo_limit_rad;
            app->target[i] = wf_servo_clamp(app->commanded[i], c->servo_limit_rad);
        }
    }
    return status;
}

/* Gait mode: the CPG's output now, clipped to the limit (clamp_to_limit's rule). */
static uint16_t gait_targets(wf_app_t *app, bool *clamped)
{
    float angle[WF_CPG_OSCILLATORS];
    wf_cpg_output(&app->cpg, angle, NULL);
    *clamped = wf_cpg_clamp(angle, NULL, app->config.servo_limit_rad);
    app->target[0] = angle[0];
    app->target[1] = angle[1];
    return (uint16_t)(WF_STATUS_GAIT_MODE |
                      (app->gap == WF_GAP_COASTING ? WF_STATUS_COASTING : 0) |
                      (app->gap == WF_GAP_RESTING ? WF_STATUS_RESTING : 0));
}

/* Sets the targets and the compares. Called every poll (at least once a millisecond), so each
 * PWM frame latches the newest target (the timer's compare is preloaded at the frame's
 * update event) and each SERVO_CMD (so two commands in one poll both reach the register). */
static void update_outputs(wf_app_t *app)
{
    const wf_config_t *c = &app->config;
    const uint32_t now = app->now_ms;
    /* A timeout, once passed, holds until the next frame: forgetting the old time keeps the
     * modular difference from coming round again after 2^31 ms. */
    if (app->have_command && now - app->last_command_ms > c->command_timeout_ms) {
        app->have_command = false;
    }
    if (app->have_heartbeat && now - app->last_heartbeat_ms > c->heartbeat_timeout_ms) {
        app->have_heartbeat = false;
    }
    bool clamped = false;
    uint16_t status = app->gait_mode ? gait_targets(app, &clamped)
                                     : stream_targets(app, now - app->last_output_ms, &clamped);
    app->last_output_ms = now;
    if (clamped) {
        status |= WF_STATUS_SERVO_CLAMPED;
    }
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const uint32_t compare = wf_servo_compare(&c->servo_cal[i], app->target[i],
                                                  wf_hal_pwm_ticks_per_us(), frame_us(c));
        if (compare != app->compare[i]) {
            app->compare[i] = compare;
            wf_hal_pwm_set_compare(i, compare);
        }
    }
    if (app->have_battery && app->battery_v < c->low_battery_v) {
        status |= WF_STATUS_LOW_BATTERY;
    }
    if (c->imu_mode == WF_IMU_SYNTHETIC || !app->imu.present) {
        status |= WF_STATUS_IMU_FAULT;
    }
    if (app->health.clock_source == WF_CLOCK_HSI_PLL ||
        app->health.clock_source == WF_CLOCK_HSI) {
        status |= WF_STATUS_CLOCK_FALLBACK;
    }
    app->status = status;
}

/* --- entry points ----------------------------------------------------------------------- */
void wf_app_init(wf_app_t *app, const wf_config_t *config)
{
    memset(app, 0, sizeof *app);
    if (config != NULL && wf_config_valid(config)) {
        app->config = *config;
    } else {
        wf_config_defaults(&app->config);
        app->config_rejected = true;
    }
    wf_decoder_init(&app->decoder);
    wf_attitude_reset(&app->attitude);
    wf_hal_health_port(&app->health); /* the clock source, for CLOCK_FALLBACK from the start */
    app->host_version_ok = true; /* until a host announces another version */
    app->now_ms = wf_hal_millis();
    app->next_telemetry_ms = app->now_ms + app->config.telemetry_period_ms;
    app->next_heartbeat_ms = app->now_ms; /* identification: from power-up, unprompted */
    app->next_health_ms = app->now_ms;    /* once right after boot, then every period */
    app->last_output_ms = app->now_ms;
    app->last_host_frame_ms = app->now_ms;
    app->next_imu_ms = app->now_ms;
    app->next_imu_probe_ms = app->now_ms;
    for (unsigned i = 0; i < WF_REPORTED_KINDS; i++) {
        app->report_due_ms[i] = app->now_ms;
    }
    (void)wf_hal_pwm_init(app->config.servo_frame_hz); /* the rate was validated above */
    load_calibration(app); /* before the first pulse: a stored neutral is the one to hold */
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        app->neutral_compare[i] = neutral_compare(app, i);
        app->compare[i] = app->neutral_compare[i];
        wf_hal_pwm_set_compare(i, app->compare[i]);
    }
    app->status = WF_STATUS_FAILSAFE_COMMAND | WF_STATUS_FAILSAFE_HEARTBEAT;
}

void wf_app_poll(wf_app_t *app)
{
    app->now_ms = wf_hal_millis();
    advance_cpg(app); /* with the parameters in force until now */
    receive(app);
    const bool reported = send_ack(app);
    sample_imu(app);
    sample_battery(app);
    update_gap(app);
    update_outputs(app);
    if (due(app->now_ms, app->next_telemetry_ms)) {
        app->next_telemetry_ms += app->config.telemetry_period_ms;
        send_telemetry(app);
    }
    if (due(app->now_ms, app->next_heartbeat_ms)) {
        app->next_heartbeat_ms += app->config.heartbeat_period_ms;
        send_heartbeat(app);
    }
    if (!app->health_sent ||
        (app->config.health_period_ms != 0 && due(app->now_ms, app->next_health_ms))) {
        app->next_health_ms = app->health_sent ? app->next_health_ms + app->config.health_period_ms
                                               : app->now_ms + app->config.health_period_ms;
        if (!app->health_sent) {
            app->boot_report = 1; /* from this poll on, after the boot HEALTH */
        }
        app->health_sent = true;
        send_health(app);
    }
    if (app->boot_report != 0 && !reported) {
        /* Where each servo's calibration comes from after this boot (a stored one may not
         * fit this build: then DEFAULTS), servo 1 first. Last in the poll and one a poll, as
         * every kind but ERROR: an ACK's report in this poll puts it off to the next. */
        send_trim_report(app, app->boot_report - 1u);
        app->boot_report = app->boot_report < WF_SERVO_COUNT ? (uint8_t)(app->boot_report + 1u)
                                                             : 0u;
    }
}
