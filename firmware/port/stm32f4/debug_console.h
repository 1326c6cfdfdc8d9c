/*
 * The QEMU build's debug console on USART2 (QEMU's second -serial): one text line per event,
 * read by the in-the-loop tests, unseen by the core.
 *   "Z <ms>"              a 0x00 byte that ends a frame (follows a non-zero byte) arrived on
 *                         USART1, board time
 *   "P <ms> <ch> <ticks>" servo channel ch's compare register changed; the value read back
 *   "C <ticks_per_us> <period_ticks> <dropped> <rx_lost>" the PWM timer's set-up, the
 *                         count of "Z" lines lost for want of room and of USART1 bytes
 *                         lost to a full receive ring, once a second
 *   "K <servo> <neutral_ns> <ns_per_rad> <direction> <limit_urad>" the servo calibration
 *                         (pulse widths in ns, the limit in microradians), once a second
 * Every build but the QEMU one compiles the calls away.
 */
#ifndef WF_STM32F4_DEBUG_CONSOLE_H
#define WF_STM32F4_DEBUG_CONSOLE_H

#include <stdint.h>

#include "wf/app_state.h"

#if WF_PORT_QEMU
void debug_console_init(const wf_config_t *config);
void debug_console_line(char tag, const int32_t *values, unsigned count);
void debug_console_poll(void);
#else
static inline void debug_console_init(const wf_config_t *config)
{
    (void)config;
}
static inline void debug_console_line(char tag, const int32_t *values, unsigned count)
{
    (void)tag, (void)values, (void)count;
}
static inline void debug_console_poll(void) {}
#endif

#endif /* WF_STM32F4_DEBUG_CONSOLE_H */
