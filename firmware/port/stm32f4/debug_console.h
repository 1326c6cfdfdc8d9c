/*
 * The QEMU build's debug console on USART2 (QEMU's second -serial): one text line per event,
 * read by the in-the-loop tests, unseen by the core.
 *   "Z <ms>"              a 0x00 byte (frame delimiter) arrived on USART1, board time
 *   "P <ms> <ch> <ticks>" servo channel ch's compare register changed; the value read back
 *   "C <ticks_per_us> <period_ticks>" the PWM timer's set-up, once a second
 * Every build but the QEMU one compiles the calls away.
 */
#ifndef WF_STM32F4_DEBUG_CONSOLE_H
#define WF_STM32F4_DEBUG_CONSOLE_H

#include <stdint.h>

#if WF_PORT_QEMU
void debug_console_init(void);
void debug_console_event(char tag, uint32_t a, int32_t b, int32_t c, int fields);
void debug_console_poll(void);
#else
static inline void debug_console_init(void) {}
static inline void debug_console_event(char tag, uint32_t a, int32_t b, int32_t c, int fields)
{
    (void)tag, (void)a, (void)b, (void)c, (void)fields;
}
static inline void debug_console_poll(void) {}
#endif

#endif /* WF_STM32F4_DEBUG_CONSOLE_H */
