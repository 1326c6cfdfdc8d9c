/* SPDX-License-Identifier: Apache-2.0 */
/*
 * C unit tests of the core on the host port: CRC, COBS, the link logic, the failsafe and the
 * servo output. Each test is one claim; the program exits 1 at the first failed check.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wf/calibration_store.h"
#include "wf/cobs.h"
#include "wf/crc16.h"
#include "wf_host.h"

static int checks;

#define CHECK(cond)                                                                       \
    do {                                                                                  \
        checks++;                                                                         \
        if (!(cond)) {                                                                    \
            fprintf(stderr, "%s:%d: %s: check failed: %s\n", __FILE__, __LINE__, __func__, \
                    #cond);                                                               \
            exit(1);                                                                      \
        }                                                                                 \
    } while (0)

/* --- helpers: a host that sends frames and reads the board's ----------------------------- */
static uint16_t host_seq;

static size_t frame_of(const wf_msg_t *msg, uint8_t *wire)
{
    return wf_encode_frame(msg, wire, WF_MAX_WIRE);
}

static void send_msg(uint32_t t, wf_msg_t *msg)
{
    uint8_t wire[WF_MAX_WIRE];
    msg->seq = host_seq++;
    const size_t len = frame_of(msg, wire);
    wf_host_board_step(t, wire, len, NULL, 0);
}

static void send_heartbeat(uint32_t t, uint8_t version)
{
    wf_msg_t msg = {.type = WF_MSG_HEARTBEAT};
    msg.u.heartbeat.version = version;
    msg.u.heartbeat.role = WF_ROLE_HOST;
    msg.u.heartbeat.uptime_ms = t;
    send_msg(t, &msg);
}

static void send_command(uint32_t t, float a, float b)
{
    wf_msg_t msg = {.type = WF_MSG_SERVO_CMD};
    msg.u.servo_cmd.servo[0] = a;
    msg.u.servo_cmd.servo[1] = b;
    send_msg(t, &msg);
}

static wf_host_snapshot_t raw_snap(void)
{
    wf_host_snapshot_t s;
    wf_host_board_snapshot(&s);
    return s;
}

/* The board without an I2C device flags IMU_FAULT (its own test below): the link tests look
 * at every other bit. */
static wf_host_snapshot_t snap(void)
{
    wf_host_snapshot_t s = raw_snap();
    s.status &= (uint16_t)~WF_STATUS_IMU_FAULT;
    return s;
}

/* Decodes everything the board sent so far into out (at most max). */
static size_t board_output(wf_host_msg_t *out, size_t max)
{
    static uint8_t bytes[WF_HOST_TX_CAPACITY];
    const size_t len = wf_host_take_output(bytes, sizeof bytes);
    return wf_host_decode_stream(bytes, len, out, max, NULL);
}

/* A new board with an erased calibration storage. */
static void fresh_board(void)
{
    wf_host_storage_clear();
    wf_host_reset();
    wf_host_board_init(NULL);
    host_seq = 0;
}

/* The same board powered off and on: the storage kept, everything else new. */
static void reboot_board(void)
{
    wf_host_reset();
    wf_host_board_init(NULL);
    host_seq = 0;
}

static void run_until(uint32_t from, uint32_t to)
{
    for (uint32_t t = from; t <= to; t++) {
        wf_host_board_step(t, NULL, 0, NULL, 0);
    }
}

/* --- codec ------------------------------------------------------------------------------ */
static void test_crc_check_value(void)
{
    CHECK(wf_crc16((const uint8_t *)"123456789", 9) == 0x29B1);
}

static void test_cobs_round_trip_of_every_zero_pattern(void)
{
    for (unsigned pattern = 0; pattern < 256; pattern++) {
        uint8_t in[8], enc[16], dec[16];
        for (unsigned i = 0; i < 8; i++) {
            in[i] = (pattern >> i) & 1u ? 0 : (uint8_t)(i + 1);
        }
        const size_t n = wf_cobs_encode(in, 8, enc, sizeof enc);
        size_t m = 0;
        CHECK(n == 9 && memchr(enc, 0, n) == NULL);
        CHECK(wf_cobs_decode(enc, n, dec, sizeof dec, &m) && m == 8 && !memcmp(in, dec, 8));
    }
}

static void test_cobs_rejects_a_code_past_the_end(void)
{
    const uint8_t bad[] = {0x05, 0x11, 0x22};
    uint8_t out[8];
    size_t m;
    CHECK(!wf_cobs_decode(bad, sizeof bad, out, sizeof out, &m));
}

static void test_decoder_drops_an_over_long_run_and_resyncs(void)
{
    wf_decoder_t d;
    wf_msg_t msg;
    wf_decoder_init(&d);
    for (int i = 0; i < 100; i++) {
        CHECK(wf_decoder_push(&d, 0x11, &msg) != WF_RX_FRAME);
    }
    CHECK(d.stats.overflows == 1 && d.run_len == 0);
    wf_msg_t hb = {.type = WF_MSG_HEARTBEAT, .seq = 4};
    hb.u.heartbeat.version = 1;
    uint8_t wire[WF_MAX_WIRE];
    const size_t len = frame_of(&hb, wire);
    int frames = 0;
    for (size_t i = 0; i < len; i++) {
        frames += wf_decoder_push(&d, wire[i], &msg) == WF_RX_FRAME;
    }
    CHECK(frames == 1 && msg.seq == 4 && d.stats.resyncs == 1);
}

static void test_decoder_rejects_a_non_finite_command(void)
{
    wf_decoder_t d;
    wf_msg_t msg = {.type = WF_MSG_SERVO_CMD};
    msg.u.servo_cmd.servo[0] = NAN;
    uint8_t wire[WF_MAX_WIRE];
    const size_t len = frame_of(&msg, wire);
    wf_decoder_init(&d);
    wf_rx_t last = WF_RX_NONE;
    for (size_t i = 0; i < len; i++) {
        const wf_rx_t r = wf_decoder_push(&d, wire[i], &msg);
        last = r != WF_RX_NONE ? r : last;
    }
    CHECK(last == WF_RX_INVALID && d.stats.invalid_payload == 1);
}

/* --- link ------------------------------------------------------------------------------- */
static void test_fish_heartbeats_from_power_up_at_2_hz(void)
{
    fresh_board();
    wf_host_msg_t out[512];
    run_until(0, 1999);
    const size_t n = board_output(out, 512);
    uint32_t beats[8];
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (out[i].type == WF_MSG_HEARTBEAT) {
            CHECK(out[i].role == WF_ROLE_FISH && out[i].version_or_code == WF_PROTOCOL_VERSION);
            beats[k++] = out[i].uptime_or_time_ms;
        }
    }
    CHECK(k == 4 && beats[0] == 0 && beats[1] == 500 && beats[2] == 1000 && beats[3] == 1500);
}

static void test_telemetry_every_10_ms_with_consecutive_seq(void)
{
    fresh_board();
    wf_host_msg_t out[512];
    run_until(0, 1000);
    const size_t n = board_output(out, 512);
    size_t telemetry = 0;
    for (size_t i = 0; i < n; i++) {
        CHECK(out[i].seq == i);
        if (out[i].type == WF_MSG_TELEMETRY) {
            telemetry++;
            CHECK(out[i].uptime_or_time_ms == 10 * telemetry);
        }
    }
    CHECK(telemetry == 100);
}

static void test_hello_with_our_version_lets_commands_through(void)
{
    fresh_board();
    send_heartbeat(1, WF_PROTOCOL_VERSION);
    send_command(2, 0.25f, -0.5f);
    const wf_host_snapshot_t s = snap();
    CHECK(s.host_seen && s.host_version_ok && s.status == 0);
    CHECK(s.target[0] == 0.25f && s.target[1] == -0.5f && s.commands_applied == 1);
}

static void test_other_version_answers_error_5_and_stays_neutral(void)
{
    fresh_board();
    run_until(0, 1); /* the boot HEALTH and both servos' reports out */
    wf_host_msg_t out[64];
    board_output(out, 64);
    send_heartbeat(2, 1); /* a version-1 host */
    send_command(3, 0.25f, 0.25f);
    const size_t n = board_output(out, 64);
    CHECK(n == 1 && out[0].type == WF_MSG_ERROR && out[0].version_or_code == 5);
    CHECK(out[0].ref_seq_or_status == 0); /* the heartbeat was the host's frame 0 */
    const wf_host_snapshot_t s = snap();
    CHECK((s.status & WF_STATUS_VERSION_MISMATCH) && s.target[0] == 0.0f);
    CHECK(s.commands_ignored == 1 && s.compare[0] == 1500);
}

static void test_bad_crc_answers_one_error_and_applies_nothing(void)
{
    fresh_board();
    send_heartbeat(1, WF_PROTOCOL_VERSION);
    run_until(2, 2); /* the second boot report out */
    wf_msg_t msg = {.type = WF_MSG_SERVO_CMD, .seq = 9};
    msg.u.servo_cmd.servo[0] = 0.5f;
    uint8_t wire[WF_MAX_WIRE];
    const size_t len = frame_of(&msg, wire);
    wire[3] ^= 0x10; /* one bit of the seq: COBS still decodes, the CRC fails */
    wf_host_msg_t out[64];
    board_output(out, 64);
    wf_host_board_step(3, wire, len, NULL, 0);
    const size_t n = board_output(out, 64);
    CHECK(n == 1 && out[0].type == WF_MSG_ERROR && out[0].version_or_code == WF_ERR_BAD_CRC);
    CHECK(snap().commands_applied == 0 && snap().decoder[4] == 1);
}

static void test_unknown_type_answers_error_3(void)
{
    fresh_board();
    uint8_t body[5] = {0x42, 0x01, 0x00};
    const uint16_t crc = wf_crc16(body, 3);
    body[3] = (uint8_t)crc;
    body[4] = (uint8_t)(crc >> 8);
    uint8_t wire[16] = {0};
    const size_t n = wf_cobs_encode(body, 5, wire + 1, sizeof wire - 2);
    wf_host_msg_t out[64];
    run_until(0, 1); /* the power-up heartbeat, HEALTH and boot reports */
    board_output(out, 64);
    wf_host_board_step(2, wire, n + 2, NULL, 0);
    CHECK(board_output(out, 64) == 1 && out[0].version_or_code == WF_ERR_UNKNOWN_TYPE);
}

static void test_a_flood_of_garbage_leaves_room_for_the_telemetry(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    wf_host_msg_t out[512];
    board_output(out, 512);
    const uint8_t garbage[12] = {0x07, 0x01, 0x00, 0x02, 0x05, 0x00, 0x55, 0x00,
                                 0x03, 0x10, 0x00, 0x00}; /* bad COBS and short runs */
    for (uint32_t t = 1; t <= 1000; t++) {
        wf_host_board_step(t, garbage, sizeof garbage, NULL, 0);
    }
    const size_t n = board_output(out, 512);
    size_t errors = 0, telemetry = 0;
    for (size_t i = 0; i < n; i++) {
        errors += out[i].type == WF_MSG_ERROR;
        telemetry += out[i].type == WF_MSG_TELEMETRY;
    }
    CHECK(telemetry == 100);
    CHECK(errors == 50); /* one BAD_FRAME per 20 ms, not one per chunk (1000) */
    CHECK(snap().decoder[2] == 3000 && snap().decoder[3] == 1000); /* COBS, short */
}

/* --- failsafe --------------------------------------------------------------------------- */
static void test_command_timeout_slews_to_neutral_after_500_ms(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(100, 0.5f, -0.3f);
    for (uint32_t t = 101; t <= 600; t += 100) {
        send_heartbeat(t, WF_PROTOCOL_VERSION);
    }
    run_until(502, 600);
    CHECK(snap().status == 0 && snap().target[0] == 0.5f); /* 500 ms since: not yet */
    wf_host_board_step(601, NULL, 0, NULL, 0);
    /* 1 ms at 2 rad/s since the last update: 2 mrad toward neutral, not a step. */
    CHECK(snap().status == WF_STATUS_FAILSAFE_COMMAND);
    CHECK(fabsf(snap().target[0] - 0.498f) < 1e-6f && fabsf(snap().target[1] + 0.298f) < 1e-6f);
    float last = snap().target[0];
    for (uint32_t t = 602; t <= 900; t++) {
        wf_host_board_step(t, NULL, 0, NULL, 0);
        const float now = snap().target[0];
        CHECK(now <= last && last - now <= 2.0f * 1e-3f + 1e-6f); /* the slew bound per ms */
        last = now;
    }
    CHECK(snap().target[0] == 0.0f && snap().target[1] == 0.0f); /* 0.25 s at 2 rad/s */
    CHECK(snap().compare[0] == 1500 && snap().compare[1] == 1500);
}

static void test_heartbeat_timeout_slews_to_neutral_after_1500_ms(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    for (uint32_t t = 10; t <= 1500; t += 10) {
        send_command(t, 0.25f, 0.25f);
    }
    CHECK(snap().status == 0);
    send_command(1501, 0.25f, 0.25f);
    CHECK(snap().status == WF_STATUS_FAILSAFE_HEARTBEAT && snap().target[1] < 0.25f &&
          snap().target[1] > 0.24f);
    run_until(1502, 1630);
    CHECK(snap().target[0] == 0.0f && snap().target[1] == 0.0f);
}

static void test_slew_rate_is_configurable(void)
{
    wf_config_t c;
    wf_config_defaults(&c);
    CHECK(c.failsafe_slew_rad_s == 2.0f);
    c.failsafe_slew_rad_s = 10.0f;
    wf_host_reset();
    wf_host_board_init(&c);
    host_seq = 0;
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(1, 1.0f, -1.0f);
    wf_host_board_step(502, NULL, 0, NULL, 0); /* 501 ms since: failsafe, 501 ms of slew */
    CHECK(snap().target[0] == 0.0f && snap().target[1] == 0.0f);
    c.failsafe_slew_rad_s = 0.0f;
    CHECK(!wf_config_valid(&c));
    c.failsafe_slew_rad_s = NAN;
    CHECK(!wf_config_valid(&c));
}

static void test_failsafe_holds_across_the_clock_wrap(void)
{
    fresh_board();
    wf_host_set_millis(0xFFFFFF00u);
    wf_host_board_init(NULL);
    send_heartbeat(0xFFFFFF00u, WF_PROTOCOL_VERSION);
    send_command(0xFFFFFF10u, 0.1f, 0.1f);
    send_heartbeat(0x00000010u, WF_PROTOCOL_VERSION); /* 272 ms later, across 2^32 */
    CHECK(snap().status == 0 && snap().target[0] == 0.1f);
    wf_host_board_step(0xFFFFFF10u + 501u, NULL, 0, NULL, 0);
    CHECK(snap().status == WF_STATUS_FAILSAFE_COMMAND);
}

/* --- servo output ----------------------------------------------------------------------- */
static void test_beyond_the_limit_is_clamped_and_flagged(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(1, 3.0f, -0.1f);
    const wf_host_snapshot_t s = snap();
    CHECK(s.status == WF_STATUS_SERVO_CLAMPED && s.target[0] == 1.57079625f);
    CHECK(s.compare[0] == 2500 && s.compare[1] == 1436);
}

static void test_calibration_neutral_gain_and_direction(void)
{
    wf_config_t c;
    wf_config_defaults(&c);
    c.servo_cal[1].neutral_us = 1520.0f;
    c.servo_cal[1].us_per_rad = 500.0f;
    c.servo_cal[1].direction = -1;
    wf_host_reset();
    wf_host_board_init(&c);
    host_seq = 0;
    CHECK(wf_host_compare(1) == 1520);
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(1, 0.0f, 0.5f);
    CHECK(wf_host_compare(1) == 1270 && wf_host_compare(0) == 1500);
}

static void test_invalid_config_falls_back_to_defaults(void)
{
    wf_config_t c;
    wf_config_defaults(&c);
    c.servo_frame_hz = 1000;
    wf_host_reset();
    wf_host_board_init(&c);
    CHECK(snap().config_rejected && wf_host_pwm_frame_hz() == 50);
    wf_config_defaults(&c);
    c.servo_cal[0].us_per_rad = 1e30f;
    CHECK(!wf_config_valid(&c));
    c.servo_cal[0].us_per_rad = NAN;
    CHECK(!wf_config_valid(&c));
    wf_config_defaults(&c);
    c.imu_axes[1] = 1; /* a mirror: y = x? not a rotation */
    CHECK(!wf_config_valid(&c));
}

static void test_a_pulse_never_outlasts_its_frame(void)
{
    wf_config_t c;
    wf_config_defaults(&c);
    c.servo_frame_hz = 333; /* a 3003 us frame */
    c.servo_cal[0].max_us = 3100.0f; /* a servo range longer than the frame: refused */
    CHECK(!wf_config_valid(&c));
    c.servo_cal[0].min_us = 1.0f;
    c.servo_cal[0].max_us = 3003.0f;
    c.servo_cal[0].us_per_rad = 950.0f; /* 1500 +- 950 x pi/2 = 8..2992 us: within */
    wf_host_reset();
    wf_host_board_init(&c);
    host_seq = 0;
    CHECK(!snap().config_rejected);
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(1, 1.5f, -1.5f);
    CHECK(wf_host_compare(0) == 2925 && wf_host_compare(1) == 545);
}

static void test_imu_absent_sets_imu_fault(void)
{
    fresh_board();
    run_until(0, 20);
    CHECK(raw_snap().status & WF_STATUS_IMU_FAULT);
}

static void test_battery_below_threshold_sets_low_battery(void)
{
    fresh_board();
    wf_host_set_adc_raw(2000); /* 4.8 V */
    run_until(0, 1);
    CHECK(snap().status & WF_STATUS_LOW_BATTERY);
    wf_host_set_adc_raw(-1); /* no new reading: the last one stands */
    run_until(2, 3);
    CHECK(snap().status & WF_STATUS_LOW_BATTERY);
}

/* A minimal MPU6050 for the sanitizer build (the register-level model is the Python one). */
static uint8_t mpu_regs[128];

static bool tiny_mpu(void *context, uint8_t address7, const uint8_t *tx, size_t tx_len,
                     uint8_t *rx, size_t rx_len)
{
    (void)context;
    if (address7 != 0x68 || tx_len == 0) {
        return false;
    }
    uint8_t reg = tx[0] & 0x7F;
    for (size_t i = 1; i < tx_len; i++) {
        mpu_regs[reg] = tx[i];
        reg = (uint8_t)((reg + 1) & 0x7F);
    }
    const bool data_read = reg == 0x3B && rx_len == 14;
    if (reg == 0x3B) {
        mpu_regs[0x42] ^= 1u; /* the temperature's noise bit: live data never stands still */
    }
    for (size_t i = 0; i < rx_len; i++) {
        rx[i] = mpu_regs[reg];
        reg = (uint8_t)((reg + 1) & 0x7F);
    }
    if (data_read) {
        mpu_regs[0x48] ^= 1u; /* a live sensor's noise: gyro z's lowest bit changes */
    }
    return true;
}

static void test_imu_sample_reaches_the_telemetry(void)
{
    memset(mpu_regs, 0, sizeof mpu_regs);
    mpu_regs[0x75] = 0x68;
    mpu_regs[0x3B + 4] = 0x20; /* accel z = 0x2000 = 8192 counts: 1 g at +-4 g */
    mpu_regs[0x43 + 4] = 0x01; /* gyro z = 256 counts */
    fresh_board();
    wf_host_set_i2c_device(tiny_mpu, NULL);
    run_until(0, 1000);
    const wf_host_snapshot_t s = raw_snap();
    CHECK(!(s.status & WF_STATUS_IMU_FAULT) && mpu_regs[0x6B] == 0x01);
    CHECK(fabsf(s.accel[2] - 9.80665f) < 1e-5f && s.gyro[2] > 0.0f);
    CHECK(s.yaw > 0.0f && fabsf(s.roll) < 1e-6f && fabsf(s.pitch) < 1e-6f);
    wf_host_set_i2c_device(NULL, NULL); /* the sensor drops off the bus */
    run_until(1001, 1010);
    CHECK(raw_snap().status & WF_STATUS_IMU_FAULT);
}

/* --- protocol v2: gait mode, LINK_CONFIG, ACK, HEALTH, compact telemetry ----------------- */
static wf_cpg_params_t table1_gait(void)
{
    /* Table 1 of the paper at 2 Hz, alpha 20, a small offset on the second oscillator. */
    wf_cpg_params_t p = {.frequency_hz = 2.0f, .amplitude = {0.38f, 0.47f},
                         .offset = {0.0f, 0.1f}, .w12 = -0.41f, .w21 = 0.64f,
                         .phi12 = 1.76f, .phi21 = 1.06f, .alpha = 20.0f};
    return p;
}

static uint16_t send_gait(uint32_t t, uint16_t gait_id, const wf_cpg_params_t *p)
{
    wf_msg_t msg = {.type = WF_MSG_GAIT};
    msg.u.gait.gait_id = gait_id;
    msg.u.gait.params = *p;
    send_msg(t, &msg);
    return msg.seq;
}

static uint16_t send_link_config(uint32_t t, uint16_t telemetry_ms, uint8_t form,
                                 uint16_t health_ms, uint16_t timeout_ms, uint16_t coast_ms)
{
    wf_msg_t msg = {.type = WF_MSG_LINK_CONFIG};
    msg.u.link_config.telemetry_period_ms = telemetry_ms;
    msg.u.link_config.telemetry_form = form;
    msg.u.link_config.health_period_ms = health_ms;
    msg.u.link_config.link_timeout_ms = timeout_ms;
    msg.u.link_config.coast_ms = coast_ms;
    send_msg(t, &msg);
    return msg.seq;
}

static wf_host_gait_snapshot_t gait_snap(void)
{
    wf_host_gait_snapshot_t g;
    wf_host_board_gait(&g);
    return g;
}

/* Index of the first message of type in out[0..n), or n. */
static size_t find(const wf_host_msg_t *out, size_t n, uint8_t type)
{
    size_t i = 0;
    while (i < n && out[i].type != type) {
        i++;
    }
    return i;
}

static size_t count(const wf_host_msg_t *out, size_t n, uint8_t type)
{
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        k += out[i].type == type;
    }
    return k;
}

static void test_gait_is_acked_and_the_board_runs_eq_1_at_1_khz(void)
{
    static wf_host_msg_t out[4096];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    board_output(out, 4096);
    const wf_cpg_params_t p = table1_gait();
    const uint16_t seq = send_gait(5, 7, &p);
    size_t n = board_output(out, 4096);
    const size_t ack = find(out, n, WF_MSG_ACK);
    CHECK(ack < n && out[ack].n[0] == WF_MSG_GAIT && out[ack].n[1] == seq && out[ack].n[2] == 0);
    CHECK(count(out, n, WF_MSG_ERROR) == 0);
    wf_host_gait_snapshot_t g = gait_snap();
    CHECK(g.gait_mode && g.gait_id == 7 && g.cpg_steps == 0 && g.cpg_time_ms == 5);
    CHECK(g.target[0] == 0.0f && g.target[1] == 0.0f); /* from rest */
    CHECK((snap().status & ~WF_STATUS_FAILSAFE_HEARTBEAT) == WF_STATUS_GAIT_MODE);
    /* The same steps as a lone CPG from rest with the same parameters: bit for bit. */
    wf_host_cpg_init(&p);
    static float angles[2 * 1000];
    wf_host_cpg_run(1000, angles, NULL);
    for (uint32_t k = 1; k <= 1000; k++) {
        wf_host_board_step(5 + k, NULL, 0, NULL, 0);
        if (k % 97 == 0 || k == 1000) {
            g = gait_snap();
            CHECK(g.cpg_steps == k && g.cpg_time_ms == 5 + k);
            CHECK(g.target[0] == angles[2 * (k - 1)] && g.target[1] == angles[2 * k - 1]);
            const wf_config_t *c = NULL;
            (void)c;
            CHECK(g.compare[0] == (uint32_t)lroundf(1500.0f + 636.619772f * g.target[0]));
        }
    }
    /* The gait id in every telemetry; a heartbeat every 200 ms keeps the link up. */
    n = board_output(out, 4096);
    size_t telemetry = 0;
    for (size_t i = 0; i < n; i++) {
        if (out[i].type == WF_MSG_TELEMETRY) {
            telemetry++;
            CHECK(out[i].n[0] == 7 && (out[i].ref_seq_or_status & WF_STATUS_GAIT_MODE));
        }
    }
    CHECK(telemetry == 100);
}

/* The largest change of either target between polls `apart` ms apart, over a lone CPG's
 * run from rest (angles as wf_host_cpg_run gives them, steps 1..n). */
static float largest_change(const float *angles, uint32_t n, uint32_t apart)
{
    float worst = 0.0f;
    for (uint32_t k = apart; k < n; k++) {
        for (unsigned i = 0; i < 2; i++) {
            const float d = fabsf(angles[2 * k + i] - angles[2 * (k - apart) + i]);
            worst = d > worst ? d : worst;
        }
    }
    return worst;
}

static void test_a_stall_pauses_the_gait_without_a_step(void)
{
    /* A poll loop blocked 157 ms (an emulator descheduled by its loaded host): the next poll
     * takes WF_CPG_MAX_LAG_MS steps and drops the rest, so the output moves no more than
     * 5 ms of the gait's own motion, then 1 ms per poll: the trajectory is the lone CPG's,
     * paused. The same when the clock goes back. */
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t p = table1_gait();
    send_gait(5, 7, &p);
    wf_host_cpg_init(&p);
    static float angles[2 * 3000];
    wf_host_cpg_run(3000, angles, NULL);
    const float per_ms = largest_change(angles, 3000, 1);
    const float per_lag = largest_change(angles, 3000, WF_CPG_MAX_LAG_MS);
    run_until(6, 1005); /* 1000 steps */
    wf_host_gait_snapshot_t before = gait_snap();
    CHECK(before.cpg_steps == 1000 && before.cpg_time_ms == 1005);
    /* A lag of exactly WF_CPG_MAX_LAG_MS is caught up whole. */
    wf_host_board_step(1005 + WF_CPG_MAX_LAG_MS, NULL, 0, NULL, 0);
    wf_host_gait_snapshot_t g = gait_snap();
    CHECK(g.cpg_steps == 1000 + WF_CPG_MAX_LAG_MS && g.cpg_time_ms == 1010);
    /* 157 ms without a poll. */
    before = g;
    wf_host_board_step(1010 + 157, NULL, 0, NULL, 0);
    g = gait_snap();
    uint32_t steps = before.cpg_steps + WF_CPG_MAX_LAG_MS;
    CHECK(g.cpg_steps == steps && g.cpg_time_ms == 1167);
    CHECK(g.target[0] == angles[2 * (steps - 1)] && g.target[1] == angles[2 * steps - 1]);
    const float stall_jump = fmaxf(fabsf(g.target[0] - before.target[0]),
                                   fabsf(g.target[1] - before.target[1]));
    CHECK(stall_jump <= per_lag && per_lag < 0.1f);
    /* Then one step per poll, each within the gait's own 1 ms motion. */
    for (uint32_t t = 1168; t < 1400; t++) {
        before = g;
        wf_host_board_step(t, NULL, 0, NULL, 0);
        g = gait_snap();
        steps++;
        CHECK(g.cpg_steps == steps && g.cpg_time_ms == t);
        CHECK(fabsf(g.target[0] - before.target[0]) <= per_ms &&
              fabsf(g.target[1] - before.target[1]) <= per_ms);
    }
    /* The clock going back 100 ms: the same bounded pause. */
    before = g;
    wf_host_board_step(1299, NULL, 0, NULL, 0);
    g = gait_snap();
    steps += WF_CPG_MAX_LAG_MS;
    CHECK(g.cpg_steps == steps && g.cpg_time_ms == 1299);
    const float back_jump = fmaxf(fabsf(g.target[0] - before.target[0]),
                                  fabsf(g.target[1] - before.target[1]));
    CHECK(back_jump <= per_lag);
    printf("stall of 157 ms: the output moved %.4f rad in the poll after it, %.4f rad after "
           "the clock went back (the gait's largest in %d ms: %.4f rad, in 1 ms: %.4f rad)\n",
           (double)stall_jump, (double)back_jump, WF_CPG_MAX_LAG_MS, (double)per_lag,
           (double)per_ms);
}

static void test_an_invalid_gait_is_refused_with_error_6_and_ack_6(void)
{
    static wf_host_msg_t out[256];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t good = table1_gait();
    send_gait(1, 3, &good);
    run_until(2, 101); /* the refusals below come at 101 too: no step in between */
    const wf_host_gait_snapshot_t before = gait_snap();
    enum { BAD = 15 };
    wf_cpg_params_t bad[BAD];
    for (int i = 0; i < BAD; i++) {
        bad[i] = good;
    }
    bad[0].frequency_hz = 0.0f;
    bad[1].frequency_hz = 10.5f;
    bad[2].amplitude[0] = -0.01f;
    bad[3].amplitude[1] = 1.6f; /* beyond the servo limit */
    bad[4].offset[0] = -1.6f;
    bad[5].alpha = 0.0f;
    bad[6].alpha = 200.5f;
    bad[7] = good; /* gait_id 0 below */
    bad[8].frequency_hz = -1.0f;
    /* Couplings beyond 100/s, phase biases beyond 2 pi (binary32 2 pi is just above it). */
    bad[9].w12 = 100.00001f;
    bad[10].w21 = -1e30f;
    bad[11].phi12 = 6.2831855f;
    bad[12].phi21 = -7.0f;
    bad[13].w12 = -3e38f;
    bad[14].phi12 = 1e30f;
    for (int i = 0; i < BAD; i++) {
        board_output(out, 256);
        const uint16_t seq = send_gait(101, i == 7 ? 0 : 9, &bad[i]);
        const size_t n = board_output(out, 256);
        const size_t e = find(out, n, WF_MSG_ERROR);
        CHECK(e + 1 < n && out[e].version_or_code == WF_ERR_COMMAND_OUT_OF_RANGE &&
              out[e].ref_seq_or_status == seq);
        CHECK(out[e + 1].type == WF_MSG_ACK && out[e + 1].n[1] == seq && out[e + 1].n[2] == 6);
        const wf_host_gait_snapshot_t g = gait_snap();
        CHECK(g.gait_id == 3 && g.params.frequency_hz == 2.0f && g.gaits_refused == (uint32_t)i + 1);
        CHECK(g.cpg_steps == before.cpg_steps && g.phase[0] == before.phase[0]);
    }
    /* A non-finite parameter is the decoder's drop (ERROR 6, ref_seq 0): no ACK. */
    wf_cpg_params_t nan = good;
    nan.w12 = NAN;
    board_output(out, 256);
    send_gait(140, 9, &nan);
    const size_t n = board_output(out, 256);
    CHECK(count(out, n, WF_MSG_ACK) == 0 && count(out, n, WF_MSG_ERROR) == 1);
    CHECK(out[find(out, n, WF_MSG_ERROR)].ref_seq_or_status == 0 && gait_snap().gait_id == 3);
    /* A host of another version: ACK 5, stream mode stays. */
    fresh_board();
    send_heartbeat(0, 1);
    board_output(out, 256);
    send_gait(1, 4, &good);
    const size_t m = board_output(out, 256);
    const size_t a = find(out, m, WF_MSG_ACK);
    CHECK(a < m && out[a].n[2] == WF_ERR_VERSION_MISMATCH && !gait_snap().gait_mode);
}

static float largest_ms_change(uint32_t t0, uint32_t t1, bool with_heartbeats, float *worst);

static void test_couplings_and_biases_at_their_bounds_are_accepted(void)
{
    const float limit = 1.57079625f;
    wf_cpg_params_t p = table1_gait();
    p.w12 = 100.0f;
    p.w21 = -100.0f;
    p.phi12 = WF_CPG_MAX_PHASE_BIAS;
    p.phi21 = -WF_CPG_MAX_PHASE_BIAS;
    CHECK(wf_cpg_params_valid(&p, limit));
    CHECK((double)WF_CPG_MAX_PHASE_BIAS <= 2.0 * 3.14159265358979323846 &&
          (double)nextafterf(WF_CPG_MAX_PHASE_BIAS, 7.0f) > 2.0 * 3.14159265358979323846);
    const float too_far[4] = {nextafterf(100.0f, 101.0f), nextafterf(-100.0f, -101.0f),
                              nextafterf(WF_CPG_MAX_PHASE_BIAS, 7.0f),
                              -nextafterf(WF_CPG_MAX_PHASE_BIAS, 7.0f)};
    for (int i = 0; i < 4; i++) {
        wf_cpg_params_t q = p;
        float *field[4] = {&q.w12, &q.w21, &q.phi12, &q.phi21};
        *field[i] = too_far[i];
        CHECK(!wf_cpg_params_valid(&q, limit));
        const wf_gait_t gait = {.gait_id = 1, .params = q};
        CHECK(!wf_gait_valid(&gait, limit));
    }
    /* The board swims the strongest coupling allowed: finite, the amplitudes reached. */
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_gait(1, 2, &p);
    float worst = 0.0f;
    largest_ms_change(2, 3000, true, &worst);
    const wf_host_gait_snapshot_t g = gait_snap();
    CHECK(g.gait_mode && g.gait_id == 2 && worst <= 1.0f);
    CHECK(fabsf(g.r[0] - 0.38f) < 1e-3f && fabsf(g.r[1] - 0.47f) < 1e-3f);
}

/* Runs the board t0..t1 and returns the largest change of a target over one ms, and in
 * *worst the largest ratio of that change to what the oscillator's own rate allows over the
 * ms (h times the larger |dTheta/dt| of its two ends): above 1 would be a step. */
static float largest_ms_change(uint32_t t0, uint32_t t1, bool with_heartbeats, float *worst)
{
    wf_host_gait_snapshot_t last = gait_snap();
    float largest = 0.0f;
    for (uint32_t t = t0; t <= t1; t++) {
        if (with_heartbeats && t % 200 == 0) {
            send_heartbeat(t, WF_PROTOCOL_VERSION);
        } else {
            wf_host_board_step(t, NULL, 0, NULL, 0);
        }
        const wf_host_gait_snapshot_t g = gait_snap();
        for (int i = 0; i < 2; i++) {
            const float change = fabsf(g.target[i] - last.target[i]);
            const float allowed =
                1e-3f * fmaxf(fabsf(g.rate[i]), fabsf(last.rate[i])) * 1.02f + 1e-6f;
            largest = fmaxf(largest, change);
            if (worst != NULL) {
                *worst = fmaxf(*worst, change / allowed);
            }
        }
        last = g;
    }
    return largest;
}

static void test_a_new_gait_swaps_the_targets_without_a_step(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t slow = table1_gait();
    send_gait(1, 1, &slow);
    float worst = 0.0f;
    const float steady = largest_ms_change(2, 3000, true, &worst);
    const wf_host_gait_snapshot_t before = gait_snap();
    wf_cpg_params_t fast = slow;
    fast.frequency_hz = 3.0f;
    fast.amplitude[0] = 0.2f;
    fast.offset[1] = -0.2f;
    send_gait(3001, 2, &fast);
    const wf_host_gait_snapshot_t at = gait_snap();
    /* The state goes on (no reset, no step of r or b); only the targets changed. */
    CHECK(at.cpg_steps == before.cpg_steps + 1 && at.gait_id == 2);
    CHECK(fabsf(at.r[0] - before.r[0]) < 1e-3f && fabsf(at.b[1] - before.b[1]) < 1e-3f);
    CHECK(at.params.frequency_hz == 3.0f && at.params.offset[1] == -0.2f);
    /* Per ms the output moves no more than the oscillator's own rate allows: r * 2 pi v h at
     * the new frequency (2.95 mrad), within a margin for the coupling and the convergence. */
    const float after = largest_ms_change(3002, 6000, true, &worst);
    CHECK(worst <= 1.0f);
    CHECK(steady < 0.47f * 6.2832f * 2.0f * 1e-3f * 1.3f);
    CHECK(after < 0.47f * 6.2832f * 3.0f * 1e-3f * 1.3f);
    CHECK(fabsf(gait_snap().r[0] - 0.2f) < 1e-3f && fabsf(gait_snap().b[1] + 0.2f) < 1e-3f);
}

static void test_a_link_gap_coasts_then_rests_without_a_step(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t p = table1_gait();
    send_gait(10, 5, &p);
    float worst = 0.0f;
    const float swimming = largest_ms_change(11, 2000, true, &worst);
    /* The last host frame: a heartbeat at 2000. Lost link after 1500 ms: COASTING at 3501. */
    float largest = largest_ms_change(2001, 3500, false, &worst);
    CHECK((snap().status & (WF_STATUS_COASTING | WF_STATUS_RESTING)) == 0);
    wf_host_board_step(3501, NULL, 0, NULL, 0);
    CHECK(snap().status & WF_STATUS_COASTING);
    CHECK(gait_snap().gap == WF_GAP_COASTING && gait_snap().params.amplitude[1] == 0.47f);
    largest = fmaxf(largest, largest_ms_change(3502, 6500, false, &worst));
    CHECK(gait_snap().gap == WF_GAP_COASTING && fabsf(gait_snap().r[1] - 0.47f) < 1e-4f);
    /* 3000 ms of coasting: RESTING at 6501, targets 0 through the oscillator. */
    wf_host_board_step(6501, NULL, 0, NULL, 0);
    wf_host_gait_snapshot_t g = gait_snap();
    CHECK((snap().status & WF_STATUS_RESTING) && !(snap().status & WF_STATUS_COASTING));
    CHECK(g.params.amplitude[0] == 0.0f && g.params.offset[1] == 0.0f &&
          g.params.frequency_hz == 2.0f && g.params.w21 == 0.64f);
    largest = fmaxf(largest, largest_ms_change(6502, 8500, false, &worst));
    g = gait_snap();
    CHECK(fabsf(g.target[0]) < 1e-3f && fabsf(g.target[1]) < 1e-3f); /* at rest */
    /* No step anywhere: each ms within the oscillator's own rate, and never much more than
     * swimming asked for (the offset's convergence adds its rate for a moment). */
    CHECK(worst <= 1.0f && largest <= swimming * 1.1f);
    /* Any valid host frame: the last gait again, converging from rest. */
    send_heartbeat(8501, WF_PROTOCOL_VERSION);
    g = gait_snap();
    CHECK(g.gap == WF_GAP_NONE && g.params.amplitude[0] == 0.38f && g.gait_id == 5);
    CHECK((snap().status & (WF_STATUS_COASTING | WF_STATUS_RESTING)) == 0);
    largest = largest_ms_change(8502, 10500, true, &worst);
    CHECK(worst <= 1.0f && largest <= swimming * 1.1f && fabsf(gait_snap().r[0] - 0.38f) < 1e-3f);
}

static void test_coast_0_rests_at_the_link_timeout(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_link_config(1, 10, WF_TELEMETRY_FULL, 2000, 300, 0);
    const wf_cpg_params_t p = table1_gait();
    send_gait(2, 1, &p);
    run_until(3, 302);
    CHECK(gait_snap().gap == WF_GAP_NONE);
    wf_host_board_step(303, NULL, 0, NULL, 0);
    CHECK(gait_snap().gap == WF_GAP_RESTING && (snap().status & WF_STATUS_RESTING));
}

static void test_servo_cmd_in_gait_mode_returns_to_stream_mode(void)
{
    static wf_host_msg_t out[256];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t p = table1_gait();
    send_gait(1, 5, &p);
    run_until(2, 100);
    send_command(101, 0.3f, -0.3f);
    const wf_host_gait_snapshot_t g = gait_snap();
    CHECK(!g.gait_mode && g.gait_id == 0 && g.target[0] == 0.3f);
    CHECK(snap().status == 0);
    board_output(out, 256);
    run_until(102, 110);
    const size_t n = board_output(out, 256);
    const size_t t = find(out, n, WF_MSG_TELEMETRY);
    CHECK(t < n && out[t].n[0] == 0);
    /* Back to gait mode: from rest again, but for the offsets at the angles held. */
    send_gait(111, 6, &p);
    const wf_host_gait_snapshot_t back = gait_snap();
    CHECK(back.gait_mode && back.cpg_steps == 0 && back.r[0] == 0.0f && back.dr[1] == 0.0f);
    CHECK(back.b[0] == 0.3f && back.b[1] == -0.3f && back.db[0] == 0.0f);
    CHECK(back.target[0] == 0.3f && back.target[1] == -0.3f);
}

/* Gait mode entered while stream mode holds a command, or slews to neutral: the output starts
 * at the angles held (the switch's ms moves nothing), then each ms moves within the
 * oscillator's own rate (h |dTheta/dt| at either end of the ms: no step), and it converges to
 * the gait through alpha. The board runs the steps of a lone CPG started there, bit for bit. */
static void test_gait_mode_starts_from_the_angles_stream_mode_held(void)
{
    const wf_cpg_params_t p = table1_gait();
    /* Holding +0.3 and -0.3 rad (a command every 100 ms: no timeout). */
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    for (uint32_t t = 1; t <= 401; t += 100) {
        send_command(t, 0.3f, -0.3f);
        run_until(t + 1, t + 99);
    }
    CHECK(snap().status == 0 && snap().target[0] == 0.3f && snap().target[1] == -0.3f);
    send_gait(501, 1, &p);
    wf_host_gait_snapshot_t g = gait_snap();
    CHECK(g.gait_mode && g.target[0] == 0.3f && g.target[1] == -0.3f); /* no change at all */
    CHECK(g.rate[0] == 0.0f && g.rate[1] == 0.0f && g.r[0] == 0.0f && g.b[0] == 0.3f);
    wf_cpg_t lone;
    const float held[2] = {0.3f, -0.3f};
    wf_cpg_start(&lone, &p, held);
    float worst = 0.0f;
    float largest = 0.0f;
    for (uint32_t t = 502; t <= 3500; t += 100) {
        largest = fmaxf(largest, largest_ms_change(t, t + 99, true, &worst));
        for (int k = 0; k < 100; k++) {
            wf_cpg_step(&lone);
        }
        float angle[2];
        wf_cpg_output(&lone, angle, NULL);
        g = gait_snap();
        CHECK(g.target[0] == angle[0] && g.target[1] == angle[1]);
    }
    /* Within the oscillator's own rate every ms, never more than swimming itself asks for
     * (r 2 pi v h: 5.9 mrad at 2 Hz), and at the gait after 3 s of alpha = 20. */
    CHECK(worst <= 1.0f);
    CHECK(largest < 0.47f * 6.2832f * 2.0f * 1e-3f * 1.3f);
    CHECK(fabsf(g.b[0]) < 1e-4f && fabsf(g.b[1] - 0.1f) < 1e-4f && fabsf(g.r[1] - 0.47f) < 1e-4f);

    /* Part way through the failsafe's slew to neutral (0.8 rad at 2 rad/s). */
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(1, 0.8f, -0.8f);
    run_until(2, 200);
    send_heartbeat(200, WF_PROTOCOL_VERSION);
    run_until(201, 700);
    const float before = snap().target[0];
    CHECK((snap().status & WF_STATUS_FAILSAFE_COMMAND) && before > 0.3f && before < 0.7f);
    send_gait(701, 2, &p);
    g = gait_snap();
    CHECK(g.gait_mode && g.target[0] == before && g.target[1] == -before);
    CHECK((snap().status & WF_STATUS_FAILSAFE_COMMAND) == 0);
    worst = 0.0f;
    largest = largest_ms_change(702, 3700, true, &worst);
    CHECK(worst <= 1.0f && largest < 0.47f * 6.2832f * 2.0f * 1e-3f * 1.3f);
    CHECK(fabsf(gait_snap().b[0]) < 1e-4f && fabsf(gait_snap().b[1] - 0.1f) < 1e-4f);
}

static void test_another_version_leaves_gait_mode_and_slews_to_neutral(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t p = table1_gait();
    send_gait(1, 5, &p);
    run_until(2, 1000);
    const float at = gait_snap().target[1];
    CHECK(fabsf(at) > 0.05f);
    send_heartbeat(1001, 1);
    const wf_host_gait_snapshot_t g = gait_snap();
    CHECK(!g.gait_mode && (snap().status & WF_STATUS_VERSION_MISMATCH));
    CHECK(fabsf(g.target[1] - at) <= 2.0f * 1e-3f + 1e-6f); /* slewing, not a step */
}

static void test_link_config_is_applied_at_once_and_acked(void)
{
    static wf_host_msg_t out[512];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    board_output(out, 512);
    const uint16_t seq = send_link_config(3, 100, WF_TELEMETRY_COMPACT, 0, 500, 1000);
    size_t n = board_output(out, 512);
    size_t a = find(out, n, WF_MSG_ACK);
    CHECK(a < n && out[a].n[0] == WF_MSG_LINK_CONFIG && out[a].n[1] == seq && out[a].n[2] == 0);
    CHECK(count(out, n, WF_MSG_TELEMETRY) == 0);
    wf_host_gait_snapshot_t g = gait_snap();
    CHECK(g.telemetry_period_ms == 100 && g.telemetry_form == WF_TELEMETRY_COMPACT);
    CHECK(g.health_period_ms == 0 && g.link_timeout_ms == 500 && g.coast_ms == 1000);
    run_until(4, 5003);
    n = board_output(out, 512);
    CHECK(count(out, n, WF_MSG_TELEMETRY) == 0 && count(out, n, WF_MSG_HEALTH) == 0);
    CHECK(count(out, n, WF_MSG_TELEMETRY_COMPACT) == 50); /* 103, 203, ..., 5003 */
    const size_t c = find(out, n, WF_MSG_TELEMETRY_COMPACT);
    CHECK(out[c].n[0] == 103);
    /* Out of range, each field in turn: ACK 6, nothing changes, no ERROR. */
    const uint16_t bad[6][5] = {{9, 0, 2000, 1500, 3000},    {1001, 0, 2000, 1500, 3000},
                                {10, 2, 2000, 1500, 3000},   {10, 0, 199, 1500, 3000},
                                {10, 0, 2000, 99, 3000},     {10, 0, 2000, 1500, 60001}};
    for (int i = 0; i < 6; i++) {
        const uint16_t s = send_link_config(5004 + (uint32_t)i, bad[i][0], (uint8_t)bad[i][1],
                                            bad[i][2], bad[i][3], bad[i][4]);
        n = board_output(out, 512);
        a = find(out, n, WF_MSG_ACK);
        CHECK(a < n && out[a].n[1] == s && out[a].n[2] == WF_ERR_COMMAND_OUT_OF_RANGE);
        CHECK(count(out, n, WF_MSG_ERROR) == 0);
        g = gait_snap();
        CHECK(g.telemetry_period_ms == 100 && g.link_timeout_ms == 500 && g.coast_ms == 1000);
    }
    /* Back to FULL at 10 ms with HEALTH every 200 ms: both at once. */
    send_link_config(6000, 10, WF_TELEMETRY_FULL, 200, 1500, 3000);
    run_until(6001, 6400);
    n = board_output(out, 512);
    CHECK(count(out, n, WF_MSG_TELEMETRY) == 40 && count(out, n, WF_MSG_HEALTH) == 2);
}

static void test_acks_go_out_one_per_poll_from_a_bounded_queue(void)
{
    static wf_host_msg_t out[256];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    board_output(out, 256);
    const wf_cpg_params_t p = table1_gait();
    uint8_t chunk[6 * WF_MAX_WIRE];
    size_t len = 0;
    for (int i = 0; i < 6; i++) {
        wf_msg_t msg = {.type = WF_MSG_GAIT, .seq = (uint16_t)(100 + i)};
        msg.u.gait.gait_id = (uint16_t)(10 + i);
        msg.u.gait.params = p;
        len += frame_of(&msg, chunk + len);
    }
    wf_host_board_step(1, chunk, len, NULL, 0);
    CHECK(gait_snap().gait_id == 15 && gait_snap().acks_dropped == 2);
    for (uint32_t t = 1; t <= 5; t++) {
        if (t > 1) {
            wf_host_board_step(t, NULL, 0, NULL, 0);
        }
        const size_t n = board_output(out, 256);
        const size_t a = find(out, n, WF_MSG_ACK);
        CHECK(count(out, n, WF_MSG_ACK) == (t <= 4 ? 1u : 0u));
        if (t <= 4) {
            CHECK(out[a].n[1] == 99 + t); /* oldest first */
        }
    }
}

static void test_compact_telemetry_rounds_and_saturates(void)
{
    wf_telemetry_t t = {.board_time_ms = 0xDEADBEEFu, .roll = 3.14159f, .pitch = -0.00015f,
                        .yaw = NAN, .gyro = {40.0f, -40.0f, -0.0024999f},
                        .accel = {39.2f, -39.2f, 9.80665f}, .servo = {1.5707963f, -0.000051f},
                        .battery_v = 70.0f, .status = 0x0141, .gait_id = 65535};
    wf_telemetry_compact_t c;
    wf_telemetry_compact(&t, &c);
    CHECK(c.board_time_ms == 0xDEADBEEFu && c.roll == 31416 && c.pitch == -2 && c.yaw == 0);
    CHECK(c.gyro[0] == 32767 && c.gyro[1] == -32768 && c.gyro[2] == -2);
    CHECK(c.accel[0] == 32767 && c.accel[1] == -32768 && c.accel[2] == 9807);
    CHECK(c.servo[0] == 15708 && c.servo[1] == -1); /* -0.51 count: the nearest */
    CHECK(c.battery_mv == 65535 && c.status == 0x0141 && c.gait_id == 65535);
    t.battery_v = -1.0f;
    wf_telemetry_compact(&t, &c);
    CHECK(c.battery_mv == 0);
    /* On the wire and back: 32 bytes of payload, the values as they were. */
    wf_msg_t msg = {.type = WF_MSG_TELEMETRY_COMPACT, .seq = 3};
    msg.u.compact = c;
    uint8_t wire[WF_MAX_WIRE];
    const size_t len = frame_of(&msg, wire);
    wf_host_msg_t back[2];
    CHECK(wf_host_decode_stream(wire, len, back, 2, NULL) == 1);
    CHECK(back[0].n[0] == 0xDEADBEEFu && back[0].n[1] == 31416 && back[0].n[5] == -32768);
    CHECK(back[0].n[12] == 0 && back[0].n[14] == 65535);
}

static void test_health_once_after_boot_and_every_period(void)
{
    static wf_host_msg_t out[1024];
    fresh_board();
    wf_host_set_uart_overruns(7);
    wf_host_board_step(0, NULL, 0, NULL, 0);
    size_t n = board_output(out, 1024);
    size_t h = find(out, n, WF_MSG_HEALTH);
    CHECK(count(out, n, WF_MSG_HEALTH) == 1);
    CHECK(out[h].n[0] == WF_RESET_POWER_ON && out[h].n[1] == WF_CLOCK_EMULATED);
    CHECK(out[h].n[7] == 0 && out[h].n[10] == 7); /* uptime, the port's UART overruns */
    /* Drops of each kind, a transmit queue too small for a frame. */
    const uint8_t garbage[] = {0x00, 0x07, 0x01, 0x00, 0x02, 0x05, 0x00}; /* bad COBS, short */
    wf_host_board_step(1, garbage, sizeof garbage, NULL, 0);
    wf_msg_t bad_crc = {.type = WF_MSG_SERVO_CMD, .seq = 9};
    bad_crc.u.servo_cmd.servo[0] = 0.5f;
    uint8_t wire[WF_MAX_WIRE];
    size_t len = frame_of(&bad_crc, wire);
    wire[3] ^= 0x10; /* one bit of the seq: the CRC fails */
    wf_host_board_step(30, wire, len, NULL, 0);
    wf_msg_t nan_cmd = {.type = WF_MSG_SERVO_CMD};
    nan_cmd.u.servo_cmd.servo[1] = NAN;
    len = frame_of(&nan_cmd, wire);
    wf_host_board_step(60, wire, len, NULL, 0);
    board_output(out, 1024);
    wf_host_set_tx_capacity(20);
    run_until(61, 1999);
    wf_host_take_output((uint8_t[WF_HOST_TX_CAPACITY]){0}, WF_HOST_TX_CAPACITY);
    wf_host_set_tx_capacity(WF_HOST_TX_CAPACITY);
    run_until(2000, 2000);
    n = board_output(out, 1024);
    h = find(out, n, WF_MSG_HEALTH);
    CHECK(h < n && count(out, n, WF_MSG_HEALTH) == 1 && out[h].n[7] == 2000);
    wf_health_t health;
    wf_host_board_health(&health);
    CHECK(out[h].n[11] == health.tx_bytes_dropped && health.tx_bytes_dropped > 10000);
    CHECK(out[h].n[12] == 1 && out[h].n[13] == 2 && out[h].n[14] == 0 && out[h].n[15] == 0);
    CHECK(out[h].n[16] == 1 && out[h].n[17] == 0 && out[h].n[18] == 0);
    run_until(2001, 6000);
    n = board_output(out, 1024);
    CHECK(count(out, n, WF_MSG_HEALTH) == 2); /* 4000, 6000 */
}

static void test_a_frame_goes_out_whole_or_not_at_all(void)
{
    /* A UART that drains 4 bytes a millisecond (40 kbit/s) behind a 100-byte queue: the
     * telemetry (64 bytes every 10 ms), heartbeats and HEALTH do not all fit. What does not
     * fit is dropped whole: the wire holds only whole frames (the receiver drops nothing),
     * the missing frames are seq gaps, and their bytes are tx_bytes_dropped. */
    fresh_board();
    wf_host_set_tx_capacity(100);
    static uint8_t wire[20000];
    size_t len = 0;
    for (uint32_t t = 0; t < 3000; t++) {
        wf_host_board_step(t, NULL, 0, NULL, 0);
        len += wf_host_take_output(wire + len, 4);
    }
    len += wf_host_take_output(wire + len, sizeof wire - len);
    static wf_host_msg_t out[2000];
    uint32_t stats[12];
    const size_t n = wf_host_decode_stream(wire, len, out, 2000, stats);
    const wf_host_snapshot_t s = raw_snap();
    for (unsigned i = 2; i <= 9; i++) {
        CHECK(stats[i] == 0); /* no damaged run: cobs, short, crc, ..., overflow, resync */
    }
    CHECK(stats[0] == len && stats[1] == n && n < 2000);
    const uint32_t missing = s.frames_sent - (uint32_t)n;
    CHECK(stats[10] > 0 && missing > 0);
    /* Each missing frame is 11..69 bytes on the wire, every byte of it counted. */
    CHECK(s.tx_bytes_dropped >= 11u * missing && s.tx_bytes_dropped <= 69u * missing);
    const size_t telemetry = count(out, n, WF_MSG_TELEMETRY);
    CHECK(telemetry > 0 && telemetry < 300);
    printf("tx queue of 100 bytes at 4 bytes/ms: %zu frames whole on the wire (%zu bytes), "
           "%u dropped whole (%u bytes), no damaged run\n",
           n, len, (unsigned)missing, (unsigned)s.tx_bytes_dropped);
    wf_host_set_tx_capacity(WF_HOST_TX_CAPACITY);
}

static void test_the_imu_lost_and_found_is_counted(void)
{
    memset(mpu_regs, 0, sizeof mpu_regs);
    mpu_regs[0x75] = 0x68;
    fresh_board();
    wf_host_set_i2c_device(tiny_mpu, NULL);
    run_until(0, 100);
    wf_host_set_i2c_device(NULL, NULL);
    run_until(101, 110);
    wf_host_set_i2c_device(tiny_mpu, NULL);
    run_until(111, 2100);
    wf_health_t h;
    wf_host_board_health(&h);
    CHECK(h.imu_faults == 1 && h.imu_recoveries == 1);
}

static void test_the_lone_cpg_follows_eq_1(void)
{
    const wf_cpg_params_t p = table1_gait();
    wf_host_cpg_init(&p);
    float state[10];
    wf_host_cpg_state(state);
    for (int i = 0; i < 10; i++) {
        CHECK(state[i] == 0.0f); /* at rest */
    }
    wf_host_cpg_run(3000, NULL, NULL);
    wf_host_cpg_state(state);
    /* alpha 20: critically damped with time constant 2 / alpha = 0.1 s, 30 of them in 3 s. */
    CHECK(fabsf(state[2] - 0.38f) < 1e-5f && fabsf(state[3] - 0.47f) < 1e-5f);
    CHECK(fabsf(state[7] - 0.1f) < 1e-5f && fabsf(state[4]) < 1e-4f);
    /* Locked: the phase difference xi1 - xi2 settles where the coupling terms balance. */
    float a[2], r[2];
    wf_host_cpg_output(a, r);
    CHECK(fabsf(a[0] - (state[2] * cosf(state[0]) + state[6])) < 1e-6f);
    /* The rate: -r (2 pi v + coupling) sin xi, the coupling at most |w12| R2 = 0.19 rad/s. */
    CHECK(fabsf(r[0] + 0.38f * 2.0f * 6.2831853f * sinf(state[0])) < 0.38f * 0.41f * 0.47f);
    float clipped[2] = {2.0f, -0.5f}, rates[2] = {1.0f, 1.0f};
    CHECK(wf_cpg_clamp(clipped, rates, 1.5f) && clipped[0] == 1.5f && rates[0] == 0.0f);
    CHECK(clipped[1] == -0.5f && rates[1] == 1.0f);
    CHECK(!wf_cpg_params_valid(&(wf_cpg_params_t){.frequency_hz = 1.0f, .alpha = INFINITY},
                               1.5f));
}

static void test_degenerate_couplings_keep_the_output_finite(void)
{
    /* GAIT refuses such couplings (|w| > 100/s); a CPG given them unchecked still stays
     * finite: 1e30/s makes the phase rate overflow, the phase restarts, the amplitude law is
     * untouched. */
    wf_cpg_params_t p = table1_gait();
    p.w12 = 1e30f;
    p.w21 = -3e38f;
    p.phi12 = 1e30f;
    wf_host_cpg_init(&p);
    static float angles[2 * 2000];
    wf_host_cpg_run(2000, angles, NULL);
    for (int i = 0; i < 2 * 2000; i++) {
        CHECK(isfinite(angles[i]) && fabsf(angles[i]) <= 0.47f + 0.1f + 1e-3f);
    }
    float state[10];
    wf_host_cpg_state(state);
    CHECK(fabsf(state[2] - 0.38f) < 1e-4f && fabsf(state[0]) <= 3.1416f);
}


/* --- servo calibration from the shore: SERVO_TRIM, SERVO_TRIM_REPORT, the storage --------- */
static const uint8_t TRIM_EXAMPLE[] = {0x00, 0x03, 0x12, 0x0d, 0x04, 0x01, 0x02, 0xff, 0x01, 0x01,
                                       0x03, 0xbe, 0x44, 0x01, 0x05, 0x16, 0x44, 0x09, 0xac, 0x00};
static const uint8_t REPORT_EXAMPLE[] = {
    0x00, 0x03, 0x22, 0x0e, 0x04, 0x01, 0x01, 0xff, 0x01, 0x01, 0x03, 0xbe, 0x44, 0x01,
    0x03, 0x16, 0x44, 0x01, 0x03, 0xfa, 0x43, 0x06, 0x40, 0x1c, 0x45, 0xb6, 0x83, 0x00};
/* Generation 1, servo 1 stored (1520 us, 600 us/rad, direction -1), servo 2 not. */
static const uint8_t RECORD_EXAMPLE[WF_CAL_RECORD_SIZE] = {
    0x57, 0x46, 0x43, 0x4c, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0xbe, 0x44,
    0x00, 0x00, 0x16, 0x44, 0xff, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xa7, 0x83, 0x09, 0xcb};

static wf_msg_t trim_msg(uint8_t servo, uint8_t op, int8_t direction, float neutral_us,
                         float us_per_rad)
{
    wf_msg_t msg = {.type = WF_MSG_SERVO_TRIM};
    msg.u.servo_trim = (wf_servo_trim_t){.servo = servo, .op = op, .direction = direction,
                                         .neutral_us = neutral_us, .us_per_rad = us_per_rad};
    return msg;
}

/* Sends the trim at t, polls once more at t + 1 (one ACK per poll); returns the seq. */
static uint16_t send_trim(uint32_t t, wf_msg_t msg)
{
    send_msg(t, &msg);
    wf_host_board_step(t + 1, NULL, 0, NULL, 0);
    return msg.seq;
}

typedef struct {
    wf_servo_trim_report_t cal[2];
    wf_cal_record_t stored;
    bool have_stored;
    uint8_t bytes[512]; /* the unit's first records */
} cal_state_t;

static cal_state_t cal_state(void)
{
    cal_state_t c;
    memset(&c, 0, sizeof c);
    wf_host_board_calibration(c.cal);
    c.have_stored = wf_cal_store_load(&c.stored);
    wf_host_storage_peek(0, c.bytes, sizeof c.bytes);
    return c;
}

/* Field by field: a struct's padding holds no value. */
static bool same_record(const wf_cal_record_t *a, const wf_cal_record_t *b)
{
    bool same = a->generation == b->generation;
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const wf_cal_entry_t *x = &a->servo[i], *y = &b->servo[i];
        same = same && x->neutral_us == y->neutral_us && x->us_per_rad == y->us_per_rad &&
               x->direction == y->direction && x->valid == y->valid;
    }
    return same;
}

static bool same_cal_state(const cal_state_t *a, const cal_state_t *b)
{
    return memcmp(a->cal, b->cal, sizeof a->cal) == 0 && same_record(&a->stored, &b->stored) &&
           a->have_stored == b->have_stored && memcmp(a->bytes, b->bytes, sizeof a->bytes) == 0;
}

/* The ACK of seq among out[0..n): its index, or n. */
static size_t find_ack(const wf_host_msg_t *out, size_t n, uint16_t seq)
{
    for (size_t i = 0; i < n; i++) {
        if (out[i].type == WF_MSG_ACK && out[i].n[0] == WF_MSG_SERVO_TRIM && out[i].n[1] == seq) {
            return i;
        }
    }
    return n;
}

static void test_servo_trim_and_report_examples_byte_for_byte(void)
{
    CHECK(wf_payload_size(WF_MSG_SERVO_TRIM) == 12);
    CHECK(wf_payload_size(WF_MSG_SERVO_TRIM_REPORT) == 20);
    wf_msg_t trim = trim_msg(1, WF_TRIM_SAVE, -1, 1520.0f, 600.0f);
    trim.seq = 13;
    wf_msg_t report = {.type = WF_MSG_SERVO_TRIM_REPORT, .seq = 14};
    report.u.servo_trim_report = (wf_servo_trim_report_t){
        .servo = 1, .source = WF_CAL_STORED, .direction = -1, .neutral_us = 1520.0f,
        .us_per_rad = 600.0f, .min_us = 500.0f, .max_us = 2500.0f};
    uint8_t wire[WF_MAX_WIRE];
    CHECK(frame_of(&trim, wire) == sizeof TRIM_EXAMPLE &&
          !memcmp(wire, TRIM_EXAMPLE, sizeof TRIM_EXAMPLE));
    CHECK(frame_of(&report, wire) == sizeof REPORT_EXAMPLE &&
          !memcmp(wire, REPORT_EXAMPLE, sizeof REPORT_EXAMPLE));
    wf_host_msg_t back[2];
    CHECK(wf_host_decode_stream(TRIM_EXAMPLE, sizeof TRIM_EXAMPLE, back, 2, NULL) == 1);
    CHECK(back[0].type == WF_MSG_SERVO_TRIM && back[0].seq == 13 && back[0].n[0] == 1 &&
          back[0].n[1] == 2 && back[0].n[2] == -1 && back[0].n[3] == 0);
    CHECK(back[0].f[0] == 1520.0f && back[0].f[1] == 600.0f);
    CHECK(wf_host_decode_stream(REPORT_EXAMPLE, sizeof REPORT_EXAMPLE, back, 2, NULL) == 1);
    CHECK(back[0].type == WF_MSG_SERVO_TRIM_REPORT && back[0].n[1] == WF_CAL_STORED &&
          back[0].f[2] == 500.0f && back[0].f[3] == 2500.0f);
}

static void test_a_non_finite_servo_trim_is_dropped_with_error_6(void)
{
    static wf_host_msg_t out[64];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    run_until(1, 5);
    board_output(out, 64);
    const cal_state_t before = cal_state();
    send_trim(10, trim_msg(1, WF_TRIM_SET, 1, 1500.0f, INFINITY));
    const size_t n = board_output(out, 64);
    const size_t e = find(out, n, WF_MSG_ERROR);
    CHECK(e < n && out[e].version_or_code == WF_ERR_COMMAND_OUT_OF_RANGE &&
          out[e].ref_seq_or_status == 0);
    CHECK(count(out, n, WF_MSG_ACK) == 0 && count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 0);
    const cal_state_t after = cal_state();
    CHECK(same_cal_state(&before, &after));
}

static void test_each_out_of_range_servo_trim_gets_ack_6_and_changes_nothing(void)
{
    static wf_host_msg_t out[64];
    const wf_msg_t refused[] = {
        trim_msg(0, WF_TRIM_READ, 0, 0.0f, 0.0f),        /* servo 0 */
        trim_msg(3, WF_TRIM_SET, 1, 1500.0f, 600.0f),    /* servo 3 */
        trim_msg(1, 4, 1, 1500.0f, 600.0f),              /* op 4 */
        trim_msg(1, WF_TRIM_SET, 0, 1500.0f, 600.0f),    /* direction 0 */
        trim_msg(1, WF_TRIM_SAVE, 2, 1500.0f, 600.0f),   /* direction 2 */
        trim_msg(2, WF_TRIM_SET, 1, 1500.0f, 0.0f),      /* no gain */
        trim_msg(2, WF_TRIM_SAVE, 1, 1500.0f, -600.0f),  /* negative gain */
        trim_msg(1, WF_TRIM_SET, 1, 1000.0f, 600.0f),    /* 1000 - 942 us: below min_us */
        trim_msg(2, WF_TRIM_SAVE, -1, 1600.0f, 636.62f), /* 1600 + 1000 us: above max_us */
    };
    for (size_t i = 0; i < sizeof refused / sizeof refused[0] + 1; i++) {
        fresh_board();
        send_heartbeat(0, WF_PROTOCOL_VERSION);
        run_until(1, 5);
        board_output(out, 64);
        const cal_state_t before = cal_state();
        wf_msg_t msg = i < sizeof refused / sizeof refused[0]
                           ? refused[i]
                           : trim_msg(1, WF_TRIM_FACTORY, 0, 0.0f, 0.0f);
        if (i == sizeof refused / sizeof refused[0]) {
            msg.u.servo_trim.reserved = 1;
        }
        const uint16_t seq = send_trim(10, msg);
        const size_t n = board_output(out, 64);
        const size_t a = find_ack(out, n, seq);
        CHECK(a < n && out[a].n[2] == WF_ERR_COMMAND_OUT_OF_RANGE);
        CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 0 && count(out, n, WF_MSG_ERROR) == 0);
        const cal_state_t after = cal_state();
        CHECK(same_cal_state(&before, &after) && wf_host_storage_programs() == 0);
    }
}

static void test_read_reports_the_defaults_after_its_ack(void)
{
    static wf_host_msg_t out[64];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    run_until(1, 5);
    board_output(out, 64);
    const uint16_t seq = send_trim(10, trim_msg(2, WF_TRIM_READ, 0, 0.0f, 0.0f));
    const size_t n = board_output(out, 64);
    const size_t a = find_ack(out, n, seq);
    CHECK(a + 1 < n && out[a].n[2] == 0 && out[a + 1].type == WF_MSG_SERVO_TRIM_REPORT);
    const wf_host_msg_t *r = &out[a + 1];
    CHECK(r->n[0] == 2 && r->n[1] == WF_CAL_DEFAULTS && r->n[2] == 1 && r->n[3] == 0);
    CHECK(r->f[0] == 1500.0f && r->f[1] == 636.619772f && r->f[2] == 500.0f &&
          r->f[3] == 2500.0f);
    CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 1);
}

static void test_set_is_live_at_the_next_pwm_write_and_not_stored(void)
{
    static wf_host_msg_t out[64];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    run_until(1, 5);
    board_output(out, 64);
    CHECK(wf_host_compare(0) == 1500);
    const uint16_t seq = send_trim(10, trim_msg(1, WF_TRIM_SET, -1, 1520.0f, 600.0f));
    CHECK(wf_host_compare(0) == 1520 && wf_host_compare(1) == 1500);
    const size_t n = board_output(out, 64);
    const size_t a = find_ack(out, n, seq);
    CHECK(a + 1 < n && out[a].n[2] == 0 && out[a + 1].type == WF_MSG_SERVO_TRIM_REPORT);
    CHECK(out[a + 1].n[0] == 1 && out[a + 1].n[1] == WF_CAL_LIVE && out[a + 1].n[2] == -1 &&
          out[a + 1].f[0] == 1520.0f && out[a + 1].f[1] == 600.0f);
    /* -1: a positive angle shortens the pulse; the fault path's neutral is the new one. */
    send_command(20, 0.5f, 0.0f);
    CHECK(wf_host_compare(0) == 1220);
    wf_host_fault(0x08001234u, 0, 0, 0);
    CHECK(wf_host_compare(0) == 1520);
    CHECK(wf_host_storage_programs() == 0);
    reboot_board();
    wf_servo_trim_report_t cal[2];
    wf_host_board_calibration(cal);
    CHECK(cal[0].source == WF_CAL_DEFAULTS && cal[0].neutral_us == 1500.0f);
}

static void test_gait_mode_refuses_changes_with_ack_7_but_reads(void)
{
    static wf_host_msg_t out[256];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    const wf_cpg_params_t p = table1_gait();
    send_gait(1, 7, &p);
    run_until(2, 5);
    board_output(out, 256);
    const cal_state_t before = cal_state();
    const uint8_t ops[3] = {WF_TRIM_SET, WF_TRIM_SAVE, WF_TRIM_FACTORY};
    for (unsigned i = 0; i < 3; i++) {
        const uint16_t seq = send_trim(10 + 2 * i, trim_msg(1, ops[i], 1, 1520.0f, 600.0f));
        const size_t n = board_output(out, 256);
        const size_t a = find_ack(out, n, seq);
        CHECK(a < n && out[a].n[2] == WF_ERR_NOT_NOW);
        CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 0 && count(out, n, WF_MSG_ERROR) == 0);
    }
    const cal_state_t after = cal_state();
    CHECK(same_cal_state(&before, &after) && wf_host_storage_programs() == 0);
    CHECK(gait_snap().gait_mode);
    const uint16_t seq = send_trim(20, trim_msg(2, WF_TRIM_READ, 0, 0.0f, 0.0f));
    const size_t n = board_output(out, 256);
    const size_t a = find_ack(out, n, seq);
    CHECK(a + 1 < n && out[a].n[2] == 0 && out[a + 1].type == WF_MSG_SERVO_TRIM_REPORT &&
          out[a + 1].n[0] == 2);
}

static void test_another_hosts_version_gets_ack_5(void)
{
    static wf_host_msg_t out[64];
    fresh_board();
    send_heartbeat(0, 1);
    run_until(1, 5);
    board_output(out, 64);
    const cal_state_t before = cal_state();
    const uint16_t seq = send_trim(10, trim_msg(1, WF_TRIM_READ, 0, 0.0f, 0.0f));
    const size_t n = board_output(out, 64);
    const size_t a = find_ack(out, n, seq);
    CHECK(a < n && out[a].n[2] == WF_ERR_VERSION_MISMATCH);
    CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 0);
    const cal_state_t after = cal_state();
    CHECK(same_cal_state(&before, &after));
}

static void test_save_is_stored_and_a_reboot_runs_on_it(void)
{
    static wf_host_msg_t out[64];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    run_until(1, 5);
    board_output(out, 64);
    const uint16_t seq = send_trim(10, trim_msg(1, WF_TRIM_SAVE, -1, 1520.0f, 600.0f));
    size_t n = board_output(out, 64);
    size_t a = find_ack(out, n, seq);
    CHECK(a + 1 < n && out[a].n[2] == 0 && out[a + 1].n[1] == WF_CAL_STORED);
    uint8_t bytes[2 * WF_CAL_RECORD_SIZE];
    wf_host_storage_peek(0, bytes, sizeof bytes);
    CHECK(!memcmp(bytes, RECORD_EXAMPLE, WF_CAL_RECORD_SIZE)); /* the documented record */
    CHECK(bytes[WF_CAL_RECORD_SIZE] == 0xFF && wf_host_storage_programs() == 1);
    reboot_board();
    wf_host_board_step(0, NULL, 0, NULL, 0);
    n = board_output(out, 64);
    const size_t h = find(out, n, WF_MSG_HEALTH);
    CHECK(h + 2 == n && out[h + 1].type == WF_MSG_SERVO_TRIM_REPORT); /* servo 1, last */
    CHECK(out[h + 1].n[0] == 1 && out[h + 1].n[1] == WF_CAL_STORED && out[h + 1].n[2] == -1 &&
          out[h + 1].f[0] == 1520.0f && out[h + 1].f[1] == 600.0f);
    wf_host_board_step(1, NULL, 0, NULL, 0);
    n = board_output(out, 64);
    CHECK(n >= 1 && out[n - 1].type == WF_MSG_SERVO_TRIM_REPORT); /* servo 2, the next poll */
    CHECK(out[n - 1].n[0] == 2 && out[n - 1].n[1] == WF_CAL_DEFAULTS);
    CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 1);
    run_until(2, 50);
    n = board_output(out, 64);
    CHECK(n > 0 && count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 0);
    CHECK(wf_host_compare(0) == 1520); /* the stored neutral from the first pulse */
}

/* A SERVO_TRIM that reaches the board before its first poll: its ACK and report go out in the
 * boot poll, so the boot reports are put off a poll each (one SERVO_TRIM_REPORT a poll). */
static void test_an_acks_report_puts_the_boot_reports_off_by_a_poll(void)
{
    static wf_host_msg_t out[64];
    uint8_t reports[8] = {0};
    uint32_t at[8] = {0};
    size_t k = 0;
    fresh_board();
    wf_msg_t read = trim_msg(2, WF_TRIM_READ, 0, 0.0f, 0.0f);
    send_msg(0, &read);
    for (uint32_t t = 0; t < 5; t++) {
        if (t > 0) {
            wf_host_board_step(t, NULL, 0, NULL, 0);
        }
        const size_t n = board_output(out, 64);
        CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) <= 1);
        for (size_t i = 0; i < n && k < 8; i++) {
            if (out[i].type == WF_MSG_SERVO_TRIM_REPORT) {
                reports[k] = (uint8_t)out[i].n[0];
                at[k++] = t;
            }
        }
    }
    /* The READ's report of servo 2 at 0 (after its ACK), then the boot's servo 1, servo 2. */
    CHECK(k == 3 && reports[0] == 2 && reports[1] == 1 && reports[2] == 2);
    CHECK(at[0] == 0 && at[1] == 1 && at[2] == 2);
}

static void test_the_newest_record_wins_and_a_damaged_one_is_skipped(void)
{
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_trim(10, trim_msg(1, WF_TRIM_SAVE, 1, 1520.0f, 600.0f));
    send_trim(12, trim_msg(1, WF_TRIM_SAVE, 1, 1480.0f, 600.0f));
    wf_cal_record_t r;
    CHECK(wf_cal_store_load(&r) && r.generation == 2 && r.servo[0].neutral_us == 1480.0f);
    reboot_board();
    wf_servo_trim_report_t cal[2];
    wf_host_board_calibration(cal);
    CHECK(cal[0].source == WF_CAL_STORED && cal[0].neutral_us == 1480.0f);
    /* A write cut short: the second record's last word never programmed. */
    const uint8_t erased[4] = {0xFF, 0xFF, 0xFF, 0xFF};
    wf_host_storage_poke(2 * WF_CAL_RECORD_SIZE - 4, erased, 4);
    reboot_board();
    wf_host_board_calibration(cal);
    CHECK(cal[0].source == WF_CAL_STORED && cal[0].neutral_us == 1520.0f);
    /* The next record goes after the damaged one, one generation past the winner. */
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_trim(10, trim_msg(2, WF_TRIM_SAVE, 1, 1490.0f, 600.0f));
    CHECK(wf_cal_store_load(&r) && r.generation == 2 && r.servo[0].neutral_us == 1520.0f &&
          r.servo[1].neutral_us == 1490.0f && r.servo[1].valid == 1);
    uint8_t bytes[WF_CAL_RECORD_SIZE];
    wf_host_storage_peek(2 * WF_CAL_RECORD_SIZE, bytes, sizeof bytes);
    wf_cal_record_t third;
    CHECK(wf_cal_record_decode(bytes, &third) && third.generation == 2);
}

static void test_a_full_unit_is_erased_and_the_record_written_at_0(void)
{
    fresh_board();
    const uint32_t slots = WF_HOST_STORAGE_SIZE / WF_CAL_RECORD_SIZE; /* 455 */
    wf_cal_record_t r = {.servo = {{1510.0f, 600.0f, 1, 1}, {0.0f, 0.0f, 0, 0}}};
    for (uint32_t i = 0; i < slots; i++) {
        CHECK(wf_cal_store_append(&r) && r.generation == i + 1);
    }
    CHECK(wf_host_storage_erases() == 0);
    reboot_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_trim(10, trim_msg(2, WF_TRIM_SAVE, 1, 1490.0f, 600.0f));
    CHECK(wf_host_storage_erases() == 1);
    uint8_t bytes[2 * WF_CAL_RECORD_SIZE];
    wf_host_storage_peek(0, bytes, sizeof bytes);
    CHECK(wf_cal_record_decode(bytes, &r) && r.generation == slots + 1);
    CHECK(r.servo[0].valid == 1 && r.servo[0].neutral_us == 1510.0f); /* servo 1 kept */
    CHECK(r.servo[1].valid == 1 && r.servo[1].neutral_us == 1490.0f);
    CHECK(bytes[WF_CAL_RECORD_SIZE] == 0xFF);
    reboot_board();
    wf_servo_trim_report_t cal[2];
    wf_host_board_calibration(cal);
    CHECK(cal[0].source == WF_CAL_STORED && cal[1].source == WF_CAL_STORED &&
          cal[1].neutral_us == 1490.0f);
}

static void test_factory_gives_the_defaults_now_and_after_a_reboot(void)
{
    static wf_host_msg_t out[64];
    fresh_board();
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_trim(10, trim_msg(1, WF_TRIM_SAVE, -1, 1520.0f, 600.0f));
    send_trim(12, trim_msg(2, WF_TRIM_SAVE, 1, 1480.0f, 600.0f));
    board_output(out, 64);
    const uint16_t seq = send_trim(14, trim_msg(1, WF_TRIM_FACTORY, 0, 0.0f, 0.0f));
    const size_t n = board_output(out, 64);
    const size_t a = find_ack(out, n, seq);
    CHECK(a + 1 < n && out[a].n[2] == 0 && out[a + 1].n[0] == 1 &&
          out[a + 1].n[1] == WF_CAL_DEFAULTS && out[a + 1].f[0] == 1500.0f &&
          out[a + 1].n[2] == 1);
    CHECK(wf_host_compare(0) == 1500);
    wf_cal_record_t r;
    CHECK(wf_cal_store_load(&r) && r.generation == 3 && r.servo[0].valid == 0 &&
          r.servo[0].neutral_us == 0.0f && r.servo[1].valid == 1);
    reboot_board();
    wf_servo_trim_report_t cal[2];
    wf_host_board_calibration(cal);
    CHECK(cal[0].source == WF_CAL_DEFAULTS && cal[0].neutral_us == 1500.0f &&
          cal[0].direction == 1);
    CHECK(cal[1].source == WF_CAL_STORED && cal[1].neutral_us == 1480.0f);
}

static void test_a_failed_storage_write_gets_ack_8_and_changes_nothing(void)
{
    static wf_host_msg_t out[64];
    const int faults[] = {WF_HOST_STORAGE_FAIL_PROGRAM, WF_HOST_STORAGE_CUT_PROGRAM,
                          WF_HOST_STORAGE_STUCK_BITS, WF_HOST_STORAGE_FAIL_ERASE};
    for (unsigned i = 0; i < 4; i++) {
        fresh_board();
        send_heartbeat(0, WF_PROTOCOL_VERSION);
        send_trim(2, trim_msg(1, WF_TRIM_SAVE, 1, 1510.0f, 600.0f));
        send_trim(4, trim_msg(1, WF_TRIM_SET, 1, 1530.0f, 600.0f)); /* live over stored */
        if (faults[i] == WF_HOST_STORAGE_FAIL_ERASE) {
            wf_cal_record_t fill = {.servo = {{1510.0f, 600.0f, 1, 1}}};
            while (wf_host_storage_programs() < WF_HOST_STORAGE_SIZE / WF_CAL_RECORD_SIZE) {
                CHECK(wf_cal_store_append(&fill));
            }
        }
        board_output(out, 64);
        const cal_state_t before = cal_state();
        wf_host_storage_set_fault(faults[i]);
        const uint8_t ops[2] = {WF_TRIM_SAVE, WF_TRIM_FACTORY};
        for (unsigned k = 0; k < 2; k++) {
            const uint16_t seq = send_trim(10 + 2 * k, trim_msg(1, ops[k], -1, 1490.0f, 600.0f));
            const size_t n = board_output(out, 64);
            const size_t a = find_ack(out, n, seq);
            CHECK(a < n && out[a].n[2] == WF_ERR_STORAGE_FAILED);
            CHECK(count(out, n, WF_MSG_SERVO_TRIM_REPORT) == 0);
            wf_servo_trim_report_t cal[2];
            wf_host_board_calibration(cal);
            CHECK(!memcmp(cal, before.cal, sizeof cal) && cal[0].source == WF_CAL_LIVE &&
                  cal[0].neutral_us == 1530.0f && wf_host_compare(0) == 1530);
        }
        wf_host_storage_set_fault(WF_HOST_STORAGE_OK);
        reboot_board();
        wf_servo_trim_report_t cal[2];
        wf_host_board_calibration(cal);
        CHECK(cal[0].source == WF_CAL_STORED && cal[0].neutral_us == 1510.0f);
    }
}

static void test_a_stored_calibration_that_does_not_fit_boots_on_the_defaults(void)
{
    fresh_board();
    wf_cal_record_t r = {.servo = {{1000.0f, 600.0f, 1, 1}, {1490.0f, 600.0f, 1, 1}}};
    CHECK(wf_cal_store_append(&r));
    reboot_board();
    wf_servo_trim_report_t cal[2];
    wf_host_board_calibration(cal);
    CHECK(cal[0].source == WF_CAL_DEFAULTS && cal[0].neutral_us == 1500.0f);
    CHECK(cal[1].source == WF_CAL_STORED && cal[1].neutral_us == 1490.0f);
}

static void test_the_record_codec_and_its_crc(void)
{
    CHECK(wf_crc32((const uint8_t *)"123456789", 9) == 0xCBF43926u);
    wf_cal_record_t r = {.generation = 1, .servo = {{1520.0f, 600.0f, -1, 1}}};
    uint8_t bytes[WF_CAL_RECORD_SIZE];
    wf_cal_record_encode(&r, bytes);
    CHECK(!memcmp(bytes, RECORD_EXAMPLE, sizeof bytes));
    wf_cal_record_t back;
    CHECK(wf_cal_record_decode(bytes, &back) && same_record(&back, &r));
    for (unsigned i = 0; i < WF_CAL_RECORD_SIZE; i++) {
        bytes[i] ^= 0x01u; /* any one bit: magic or CRC fails */
        CHECK(!wf_cal_record_decode(bytes, &back));
        bytes[i] ^= 0x01u;
    }
}

int main(void)
{
    test_crc_check_value();
    test_cobs_round_trip_of_every_zero_pattern();
    test_cobs_rejects_a_code_past_the_end();
    test_decoder_drops_an_over_long_run_and_resyncs();
    test_decoder_rejects_a_non_finite_command();
    test_fish_heartbeats_from_power_up_at_2_hz();
    test_telemetry_every_10_ms_with_consecutive_seq();
    test_hello_with_our_version_lets_commands_through();
    test_other_version_answers_error_5_and_stays_neutral();
    test_bad_crc_answers_one_error_and_applies_nothing();
    test_unknown_type_answers_error_3();
    test_a_flood_of_garbage_leaves_room_for_the_telemetry();
    test_command_timeout_slews_to_neutral_after_500_ms();
    test_heartbeat_timeout_slews_to_neutral_after_1500_ms();
    test_slew_rate_is_configurable();
    test_failsafe_holds_across_the_clock_wrap();
    test_beyond_the_limit_is_clamped_and_flagged();
    test_calibration_neutral_gain_and_direction();
    test_invalid_config_falls_back_to_defaults();
    test_a_pulse_never_outlasts_its_frame();
    test_imu_absent_sets_imu_fault();
    test_battery_below_threshold_sets_low_battery();
    test_imu_sample_reaches_the_telemetry();
    test_gait_is_acked_and_the_board_runs_eq_1_at_1_khz();
    test_a_stall_pauses_the_gait_without_a_step();
    test_an_invalid_gait_is_refused_with_error_6_and_ack_6();
    test_couplings_and_biases_at_their_bounds_are_accepted();
    test_a_new_gait_swaps_the_targets_without_a_step();
    test_a_link_gap_coasts_then_rests_without_a_step();
    test_coast_0_rests_at_the_link_timeout();
    test_servo_cmd_in_gait_mode_returns_to_stream_mode();
    test_gait_mode_starts_from_the_angles_stream_mode_held();
    test_another_version_leaves_gait_mode_and_slews_to_neutral();
    test_link_config_is_applied_at_once_and_acked();
    test_acks_go_out_one_per_poll_from_a_bounded_queue();
    test_compact_telemetry_rounds_and_saturates();
    test_health_once_after_boot_and_every_period();
    test_a_frame_goes_out_whole_or_not_at_all();
    test_the_imu_lost_and_found_is_counted();
    test_the_lone_cpg_follows_eq_1();
    test_degenerate_couplings_keep_the_output_finite();
    test_servo_trim_and_report_examples_byte_for_byte();
    test_a_non_finite_servo_trim_is_dropped_with_error_6();
    test_each_out_of_range_servo_trim_gets_ack_6_and_changes_nothing();
    test_read_reports_the_defaults_after_its_ack();
    test_set_is_live_at_the_next_pwm_write_and_not_stored();
    test_gait_mode_refuses_changes_with_ack_7_but_reads();
    test_another_hosts_version_gets_ack_5();
    test_save_is_stored_and_a_reboot_runs_on_it();
    test_the_newest_record_wins_and_a_damaged_one_is_skipped();
    test_a_full_unit_is_erased_and_the_record_written_at_0();
    test_factory_gives_the_defaults_now_and_after_a_reboot();
    test_a_failed_storage_write_gets_ack_8_and_changes_nothing();
    test_a_stored_calibration_that_does_not_fit_boots_on_the_defaults();
    test_an_acks_report_puts_the_boot_reports_off_by_a_poll();
    test_the_record_codec_and_its_crc();
    printf("test_core: 56 tests, %d checks passed\n", checks);
    return 0;
}
