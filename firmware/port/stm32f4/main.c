/*
 * The board's main: set up the clocks, the millisecond clock, the link UART, I2C1 and the
 * ADC, then hand over to the portable core (wf/app.h) and poll it for ever. The core starts
 * the servo timer itself (wf_hal_pwm_init with its configured frame rate).
 */
#include "board.h"
#include "debug_console.h"
#include "wf/app.h"

static wf_app_t app;
static wf_config_t config;

int main(void)
{
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
    debug_console_init(&config);
    wf_app_init(&app, &config);
    for (;;) {
        wf_app_poll(&app);
        debug_console_poll();
        /* Sleep until the next interrupt: SysTick (1 ms) or a received byte. A byte that came
         * during the poll was queued by its interrupt and is read at the next tick. The core
         * needs nothing faster (its schedule is in ms); an emulator then idles too. */
        __asm volatile("wfi");
    }
}
