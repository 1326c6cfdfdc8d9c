/*
 * The application: link logic, failsafe, servo output, sensors and the telemetry schedule.
 *
 * The firmware rules are the virtual fish's (wirefish_sim.virtual_fish), and
 * test/firmware/test_fw_virtual_fish_parity.py holds the two to the same output frames and
 * states. One poll: read every byte the UART holds (one chunk, up to 512), act on each valid
 * frame, send one ERROR per kind of drop not yet reported (at most one per kind per 20 ms);
 * sample the sensors; run the failsafe and set the servos; send the telemetry and the
 * heartbeat that are due, in that order.
 */
#include "wf/app.h"

#include <math.h>
#include <string.h>

enum {
    RX_CHUNK = 64,
    RX_CHUNKS_PER_POLL = 8, /* 512 bytes: bounds one poll's work whatever the UART holds */
    IMU_PROBE_PERIOD_MS = 1000,
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
              in_range(c->low_battery_v, -1.0f, 100.0f);
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const wf_servo_cal_t *cal = &c->servo_cal[i];
        ok = ok && in_range(cal->neutral_us, 0.0f, 20000.0f) &&
             in_range(cal->us_per_rad, 0.0f, 100000.0f) &&
             (cal->direction == 1 || cal->direction == -1);
    }
    return ok;
}

/* --- output ----------------------------------------------------------------------------- */
static void send(wf_app_t *app, wf_msg_t *msg)
{
    uint8_t wire[WF_MAX_WIRE];
    msg->seq = app->tx_seq++;
    const size_t len = wf_encode_frame(msg, wire, sizeof wire);
    const size_t written = wf_hal_uart_write(wire, len);
    app->frames_sent++;
    if (written < len) {
        /* The receiver sees a damaged run and resynchronises at the next frame's 0x00; its
         * sequence count shows the loss. */
        app->tx_bytes_dropped += (uint32_t)(len - written);
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
    wf_telemetry_t *t = &msg.u.telemetry;
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
    send(app, &msg);
}

/* --- input ------------------------------------------------------------------------------ */
static void update_outputs(wf_app_t *app);

static void on_frame(wf_app_t *app, const wf_msg_t *msg)
{
    switch (msg->type) {
    case WF_MSG_HEARTBEAT:
        if (msg->u.heartbeat.role != WF_ROLE_HOST) {
            return; /* our own heartbeat echoed back, or another fish: not a host */
        }
        app->host_seen = true;
        app->host_version_ok = msg->u.heartbeat.version == WF_PROTOCOL_VERSION;
        if (!app->host_version_ok) {
            send_error(app, WF_ERR_VERSION_MISMATCH, msg->seq);
        }
        app->have_heartbeat = true;
        app->last_heartbeat_ms = app->now_ms;
        return;
    case WF_MSG_SERVO_CMD:
        if (!app->host_version_ok) {
            app->commands_ignored++;
            return;
        }
        app->commanded[0] = msg->u.servo_cmd.servo[0];
        app->commanded[1] = msg->u.servo_cmd.servo[1];
        app->have_command = true;
        app->last_command_ms = app->now_ms;
        app->commands_applied++;
        /* Each command reaches the compare register, also when several arrive in a poll. */
        update_outputs(app);
        return;
    default:
        return; /* TELEMETRY and ERROR are the fish's to send */
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
            wf_mpu6050_init(&app->imu);
            app->imu_sampled = false; /* the first sample after a probe restarts dt */
        }
        if (!app->imu.present) {
            return;
        }
        if (!wf_mpu6050_read(&app->imu, app->config.imu_axes)) {
            app->next_imu_probe_ms = now; /* lost: probe again at once */
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

/* --- failsafe and servos ---------------------------------------------------------------- */
static void update_outputs(wf_app_t *app)
{
    const wf_config_t *c = &app->config;
    const uint32_t now = app->now_ms;
    uint16_t status = 0;
    /* A timeout, once passed, holds until the next frame: forgetting the old time keeps the
     * modular difference from coming round again after 2^31 ms. */
    if (app->have_command && now - app->last_command_ms > c->command_timeout_ms) {
        app->have_command = false;
    }
    if (app->have_heartbeat && now - app->last_heartbeat_ms > c->heartbeat_timeout_ms) {
        app->have_heartbeat = false;
    }
    if (!app->have_command) {
        status |= WF_STATUS_FAILSAFE_COMMAND;
    }
    if (!app->have_heartbeat) {
        status |= WF_STATUS_FAILSAFE_HEARTBEAT;
    }
    if (!app->host_version_ok) {
        status |= WF_STATUS_VERSION_MISMATCH;
    }
    const bool neutral = status != 0;
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const float wanted = neutral ? 0.0f : app->commanded[i];
        if (fabsf(wanted) > c->servo_limit_rad) {
            status |= WF_STATUS_SERVO_CLAMPED;
        }
        app->target[i] = wf_servo_clamp(wanted, c->servo_limit_rad);
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
    app->host_version_ok = true; /* until a host announces another version */
    app->now_ms = wf_hal_millis();
    app->next_telemetry_ms = app->now_ms + app->config.telemetry_period_ms;
    app->next_heartbeat_ms = app->now_ms; /* identification: from power-up, unprompted */
    app->next_imu_ms = app->now_ms;
    app->next_imu_probe_ms = app->now_ms;
    for (unsigned i = 0; i < WF_REPORTED_KINDS; i++) {
        app->report_due_ms[i] = app->now_ms;
    }
    (void)wf_hal_pwm_init(app->config.servo_frame_hz); /* the rate was validated above */
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        app->compare[i] = wf_servo_compare(&app->config.servo_cal[i], 0.0f,
                                           wf_hal_pwm_ticks_per_us(), frame_us(&app->config));
        wf_hal_pwm_set_compare(i, app->compare[i]);
    }
    app->status = WF_STATUS_FAILSAFE_COMMAND | WF_STATUS_FAILSAFE_HEARTBEAT;
}

void wf_app_poll(wf_app_t *app)
{
    app->now_ms = wf_hal_millis();
    receive(app);
    sample_imu(app);
    sample_battery(app);
    update_outputs(app);
    if (due(app->now_ms, app->next_telemetry_ms)) {
        app->next_telemetry_ms += app->config.telemetry_period_ms;
        send_telemetry(app);
    }
    if (due(app->now_ms, app->next_heartbeat_ms)) {
        app->next_heartbeat_ms += app->config.heartbeat_period_ms;
        send_heartbeat(app);
    }
}
