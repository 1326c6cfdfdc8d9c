/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The board's main: the reset cause and the stack guard, the brown-out level, the watchdog,
 * the clocks, the millisecond clock, the link UART, I2C1 and the ADC; then the portable core
 * (wf/app.h), polled for ever with the watchdog fed once per complete poll. The core starts
 * the servo timer itself (wf_hal_pwm_init with its configured frame rate) and writes the
 * neutral compares of the calibration in force (stored, or the build's), which the fault
 * path then reuses: handed over again after each poll, as a SERVO_TRIM may change them.
 */
#include "board.h"
#include "debug_console.h"
#include "wf/app.h"

static wf_app_t app;
static wf_config_t config;

int main(void)
{
    board_boot();
    board_bor_init();        /* before the watchdog: an option-byte write takes a while, once */
    board_watchdog_start();  /* from here every wait below is bounded well inside it */
    board_clock_init();
    board_systick_init();
    board_uart_init();
    board_i2c_init();
    board_adc_init();
    wf_config_defaults(&config);
#if WF_PORT_QEMU
    /* QEMU models no I2C: the core's synthetic IMU (a level fish at rest, IMU_FAULT set) keeps
     * the driver from probing a bus that is not there, and says so in every status. */
    config.imu_mode = WF_IMU_SYNTHETIC;
#endif
    debug_console_init(&app.config);   /* its "K" lines: the calibration in force */
    wf_app_init(&app, &config);
    board_pwm_set_failsafe(app.neutral_compare);   /* the neutral pulses wf_app_init wrote */
    for (;;) {
        wf_app_poll(&app);
        board_pwm_set_failsafe(app.neutral_compare);   /* a SERVO_TRIM may have moved them */
        trace_poll(&app);   /* the QEMU build: "G" and "J" lines */
        debug_console_poll();
        board_watchdog_feed();   /* here only: a poll that never ends is never fed */
        /* Sleep until the next interrupt: SysTick (1 ms) or a received byte. A byte that came
         * during the poll was queued by its interrupt and is read at the next tick. The core
         * needs nothing faster (its schedule is in ms); an emulator then idles too. */
        __asm volatile("wfi");
    }
}
