/*
 * C unit tests of the core on the host port: CRC, COBS, the link logic, the failsafe and the
 * servo output. Each test is one claim; the program exits 1 at the first failed check.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

static void fresh_board(void)
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
    run_until(0, 0);
    wf_host_msg_t out[64];
    board_output(out, 64);
    send_heartbeat(1, 1); /* a version-1 host */
    send_command(2, 0.25f, 0.25f);
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
    wf_msg_t msg = {.type = WF_MSG_SERVO_CMD, .seq = 9};
    msg.u.servo_cmd.servo[0] = 0.5f;
    uint8_t wire[WF_MAX_WIRE];
    const size_t len = frame_of(&msg, wire);
    wire[3] ^= 0x10; /* one bit of the seq: COBS still decodes, the CRC fails */
    wf_host_msg_t out[64];
    board_output(out, 64);
    wf_host_board_step(2, wire, len, NULL, 0);
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
    run_until(0, 0); /* the power-up heartbeat */
    board_output(out, 64);
    wf_host_board_step(1, wire, n + 2, NULL, 0);
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
    c.servo_cal[0].us_per_rad = 20000.0f;
    wf_host_reset();
    wf_host_board_init(&c);
    host_seq = 0;
    send_heartbeat(0, WF_PROTOCOL_VERSION);
    send_command(1, 1.5f, -1.5f);
    CHECK(wf_host_compare(0) == 3003 && wf_host_compare(1) == 545);
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
    for (size_t i = 0; i < rx_len; i++) {
        rx[i] = mpu_regs[reg];
        reg = (uint8_t)((reg + 1) & 0x7F);
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
    printf("test_core: 22 tests, %d checks passed\n", checks);
    return 0;
}
