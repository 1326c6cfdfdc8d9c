/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Cycles per received frame, per telemetry frame and per CPG step, host build (make cycles).
 *
 * Each figure but the last two is one wf_app_poll: one that finds one frame in the UART
 * (nothing else due), and one that sends the telemetry (with the IMU sample, failsafe and servo
 * update of that poll). "cpg_step" is one wf_cpg_step (eq 1, one RK4 step of 1 ms) alone;
 * "gait_poll" one poll in gait mode with nothing else due (a CPG step, its output, the compares).
 * All timed with the x86 time-stamp counter (TSC ticks: cycles at the nominal clock; other CPUs:
 * nanoseconds from clock_gettime). The board's run is deterministic (same clock, same bytes),
 * so it is repeated REPEATS times from reset and each poll keeps its fastest repeat: what the
 * code costs, without the interrupts and preemption of a shared machine, which would have to
 * hit the same poll in every repeat. "worst" is the largest of those over the runs, the
 * worst-case input; "raw_max" the slowest single poll seen (the scheduler's figure). Prints
 * one JSON object.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "wf_host.h"

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#define COUNTER "tsc"
static uint64_t counter_now(void)
{
    unsigned aux;
    return __rdtscp(&aux);
}
#else
#define COUNTER "ns"
static uint64_t counter_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}
#endif

enum { RUNS = 20000, REPEATS = 5 };

static int by_value(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static void print_figure(const char *name, const uint64_t *best, uint64_t raw_max,
                         const char *tail)
{
    static uint64_t sorted[RUNS];
    memcpy(sorted, best, sizeof sorted);
    qsort(sorted, RUNS, sizeof *sorted, by_value);
    printf("\"%s\": {\"median\": %llu, \"worst\": %llu, \"raw_max\": %llu, \"runs\": %d}%s",
           name, (unsigned long long)sorted[RUNS / 2], (unsigned long long)sorted[RUNS - 1],
           (unsigned long long)raw_max, RUNS, tail);
}

static void keep(uint64_t *best, uint64_t *raw_max, size_t i, uint64_t ticks, int repeat)
{
    if (repeat == 0 || ticks < best[i]) {
        best[i] = ticks;
    }
    if (ticks > *raw_max) {
        *raw_max = ticks;
    }
}

static size_t frame(uint8_t type, uint16_t seq, uint8_t *wire)
{
    wf_msg_t msg;
    memset(&msg, 0, sizeof msg);
    msg.type = type;
    msg.seq = seq;
    if (type == WF_MSG_HEARTBEAT) {
        msg.u.heartbeat.version = WF_PROTOCOL_VERSION;
    } else if (type == WF_MSG_SERVO_CMD) {
        msg.u.servo_cmd.servo[0] = 0.3f + 1e-5f * (float)seq;
        msg.u.servo_cmd.servo[1] = -0.7f;
    } else if (type == WF_MSG_GAIT) {
        const wf_cpg_params_t p = {.frequency_hz = 2.0f, .amplitude = {0.38f, 0.47f},
                                   .w12 = -0.41f, .w21 = 0.64f, .phi12 = 1.76f,
                                   .phi21 = 1.06f, .alpha = 20.0f};
        msg.u.gait.gait_id = 1;
        msg.u.gait.params = p;
    } else {
        msg.u.health.uptime_ms = 0x01020304u; /* no zero bytes: the longest COBS run */
        msg.u.health.reset_cause = 1;
    }
    return wf_encode_frame(&msg, wire, WF_MAX_WIRE);
}

static uint64_t timed_poll(wf_app_t *app, uint32_t t, const uint8_t *in, size_t len)
{
    static uint8_t sink[4096];
    wf_host_set_millis(t);
    wf_host_feed(in, len);
    const uint64_t start = counter_now();
    wf_app_poll(app);
    const uint64_t ticks = counter_now() - start;
    wf_host_take_output(sink, sizeof sink);
    return ticks;
}

int main(void)
{
    static uint64_t command[RUNS], frame_in[RUNS], telemetry_out[RUNS], cpg_step[RUNS],
        gait_poll[RUNS];
    uint64_t command_max = 0, frame_in_max = 0, telemetry_max = 0, cpg_max = 0, gait_max = 0;
    static wf_app_t app;
    wf_config_t config;
    wf_config_defaults(&config);
    config.imu_mode = WF_IMU_SYNTHETIC;
    config.heartbeat_timeout_ms = 0x7FFFFFFF;
    config.command_timeout_ms = 0x7FFFFFFF;
    uint8_t wire[WF_MAX_WIRE];
    for (int repeat = 0; repeat < REPEATS; repeat++) {
        wf_host_reset();
        wf_app_init(&app, &config);
        uint16_t seq = 0;
        timed_poll(&app, 0, wire, frame(WF_MSG_HEARTBEAT, seq++, wire));
        uint32_t t = 1;
        for (size_t i = 0; i < RUNS; i++) {
            /* t % 10 == 1 and 3: no telemetry, heartbeat or IMU sample is due. */
            keep(command, &command_max, i,
                 timed_poll(&app, t, wire, frame(WF_MSG_SERVO_CMD, seq++, wire)), repeat);
            /* The longest frame the decoder takes whole (a HEALTH, 69 bytes; the fish then
             * ignores it). */
            keep(frame_in, &frame_in_max, i,
                 timed_poll(&app, t + 2, wire, frame(WF_MSG_HEALTH, seq++, wire)), repeat);
            t += 9; /* a poll that sends the telemetry (and the IMU sample of its 5 ms) */
            keep(telemetry_out, &telemetry_max, i, timed_poll(&app, t, NULL, 0), repeat);
            t += 1;
        }
    }
    const uint32_t applied = app.commands_applied;
    /* Eq 1 alone: RUNS consecutive steps of Table 1 at 2 Hz from rest, each its fastest of
     * REPEATS runs from the same start. */
    static wf_cpg_t cpg;
    const wf_cpg_params_t table1 = {.frequency_hz = 2.0f, .amplitude = {0.38f, 0.47f},
                                    .w12 = -0.41f, .w21 = 0.64f, .phi12 = 1.76f,
                                    .phi21 = 1.06f, .alpha = 20.0f};
    float sink_angle[2] = {0};
    for (int repeat = 0; repeat < REPEATS; repeat++) {
        wf_cpg_init(&cpg, &table1);
        for (size_t i = 0; i < RUNS; i++) {
            const uint64_t start = counter_now();
            wf_cpg_step(&cpg);
            keep(cpg_step, &cpg_max, i, counter_now() - start, repeat);
        }
        wf_cpg_output(&cpg, sink_angle, NULL);
    }
    /* Gait mode: a GAIT at 1, then one poll per ms with nothing else due (no telemetry, IMU
     * sample or heartbeat: those ms are skipped, unmeasured). */
    uint32_t gaits = 0;
    for (int repeat = 0; repeat < REPEATS; repeat++) {
        wf_host_reset();
        wf_app_init(&app, &config);
        uint16_t seq = 0;
        timed_poll(&app, 0, wire, frame(WF_MSG_HEARTBEAT, seq++, wire));
        timed_poll(&app, 1, wire, frame(WF_MSG_GAIT, seq++, wire));
        uint32_t t = 2;
        for (size_t i = 0; i < RUNS; i++) {
            while (t % 5 == 0 || t % 10 == 0 || t % 500 == 0 || t % 2000 == 0) {
                timed_poll(&app, t++, NULL, 0);
            }
            keep(gait_poll, &gait_max, i, timed_poll(&app, t++, NULL, 0), repeat);
        }
        gaits += app.gait_mode && app.cpg.steps == t - 2;
    }
    printf("{\"counter\": \"%s\", \"repeats\": %d, ", COUNTER, REPEATS);
    print_figure("servo_cmd_received", command, command_max, ", ");
    print_figure("longest_frame_received", frame_in, frame_in_max, ", ");
    print_figure("telemetry_sent", telemetry_out, telemetry_max, ", ");
    print_figure("cpg_step", cpg_step, cpg_max, ", ");
    print_figure("gait_poll", gait_poll, gait_max, "");
    printf(", \"commands_applied\": %u, \"cpg_angle\": [%.6f, %.6f]}\n", applied,
           (double)sink_angle[0], (double)sink_angle[1]);
    return applied == RUNS && gaits == REPEATS ? 0 : 1;
}
