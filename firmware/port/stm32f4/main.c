/*
 * The board's main: set up the clocks, the millisecond clock, the link UART, I2C1 and the
 * ADC, then hand over to the portable core (wf/app.h) and poll it for ever. The servo timer
 * is started by the core (wf_hal_pwm_init with its configured frame rate). WF_PORT_BRINGUP
 * builds the port's own heartbeat-only app instead (bring-up before the core existed).
 */
#include "board.h"
#include "debug_console.h"

#if WF_PORT_BRINGUP
void bringup_app_run(void);
#else
#include "wf/app.h"
static wf_app_t app;
#endif

int main(void)
{
    board_clock_init();
    board_systick_init();
    board_uart_init();
    debug_console_init();
    board_i2c_init();
    board_adc_init();
#if WF_PORT_BRINGUP
    bringup_app_run();
#else
    static wf_config_t config;
    wf_config_defaults(&config);
    wf_app_init(&app, &config);
    for (;;) {
        wf_app_poll(&app);
        debug_console_poll();
    }
#endif
    return 0;
}
