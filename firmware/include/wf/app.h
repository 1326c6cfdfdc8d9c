/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The firmware application: the one entry point a port's main loop (or an RTOS task) calls.
 *
 *   static wf_app_t app;              -- all state, no heap
 *   wf_app_init(&app, &config);       -- once, after the port's clocks, UART, PWM, I2C, ADC
 *   for (;;) wf_app_poll(&app);       -- as often as possible (at least once a millisecond)
 *
 * wf_app_poll steps the board's CPG (gait mode), reads the UART, decodes and acts on frames,
 * answers GAIT, LINK_CONFIG and SERVO_TRIM with an ACK (an accepted SERVO_TRIM's followed by
 * its servo's SERVO_TRIM_REPORT), runs the gap rules or the failsafe, updates the servos,
 * samples the IMU and sends telemetry (100 Hz by default, FULL or COMPACT), heartbeats (2 Hz)
 * and HEALTH (at boot, then every 2 s by default) when they are due; from the boot HEALTH's
 * poll on, each servo's SERVO_TRIM_REPORT once, servo 1 first, one a poll. wf_app_init loads the stored calibration (wf/calibration_store.h)
 * before the first pulse.
 * The full definition of wf_app_t and wf_config_t lives in wf/app_state.h (owned by the core).
 */
#ifndef WF_APP_H
#define WF_APP_H

#include "wf/app_state.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The defaults of PROTOCOL.md: 0.5 s command timeout, 1.5 s heartbeat timeout, 100 Hz FULL
 * telemetry, 2 Hz heartbeat, HEALTH every 2 s, gait mode's 1.5 s link timeout and 3 s coast,
 * the failsafe's 2 rad/s slew, 50 Hz servo frames, the virtual fish's servo limit. */
void wf_config_defaults(wf_config_t *config);

void wf_app_init(wf_app_t *app, const wf_config_t *config);

void wf_app_poll(wf_app_t *app);

#ifdef __cplusplus
}
#endif

#endif /* WF_APP_H */
