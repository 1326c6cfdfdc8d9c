/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The QEMU build's debug console on USART2 (QEMU's second -serial): one text line per event,
 * read by the in-the-loop tests, unseen by the core.
 *   "Z <ms>"              a 0x00 byte that ends a frame (follows a non-zero byte) arrived on
 *                         USART1, board time
 *   "P <ms> <ch> <ticks>" servo channel ch's compare register changed; the value read back
 *   "C <ticks_per_us> <period_ticks> <dropped> <rx_lost> <virtual_ns>" the PWM timer's
 *                         set-up, the count of "Z" lines lost for want of room and of USART1
 *                         bytes lost to a full receive ring, once a second
 *   "K <servo> <neutral_ns> <ns_per_rad> <direction> <limit_urad>" the servo calibration
 *                         (pulse widths in ns, the limit in microradians), once a second
 *   "R <cause> <pc> <lr> <cfsr> <hfsr> <flags> <stack_free> <stack_size> <clock>" what
 *                         wf_hal_health_port reports (wf/health.h's values), once a second
 *   "F <cause> <pc> <ticks_0> <ticks_1>" the fault path ran: its cause, the faulting PC and
 *                         both compare registers read back after it set them neutral, written
 *                         at once, just before the reset
 *   "G <ms> <gait_id> <accepted>" a poll accepted a GAIT (the core's count of accepted gaits
 *                         grew): the poll's time, which is the board time the gait's targets
 *                         took over from (the CPG had been stepped up to it with the old ones)
 *   "J <ms_before> <ms>"  gait mode, two polls in a row more than 1 ms apart (QEMU descheduled,
 *                         or a late SysTick): the input of the core's CPG backlog rule
 *   "T <kind> <ms>"       a poll took a HEARTBEAT (kind 0) or a SERVO_CMD (kind 1): the poll's
 *                         time, from which the core's timeout of that kind runs (a frame's
 *                         "Z" says when it arrived; the core reads at most 512 bytes a poll,
 *                         so behind a backlog it takes the frame some polls later)
 * It takes one-letter commands on its input, to make the firmware fail on purpose:
 *   "H" a HardFault (an undefined instruction with UsageFault not enabled: escalated),
 *   "W" the poll loop hangs (the watchdog resets), "S" a stack overflow (unbounded recursion).
 *
 * The port calls the hooks below (trace_*) at the events; in every build but the QEMU one they
 * are empty inline functions and debug_console.c is not linked: the hardware image holds none
 * of this (`nm build/arm/wirefish.elf` lists no debug_console_ or trace_ symbol).
 */
#ifndef WF_STM32F4_DEBUG_CONSOLE_H
#define WF_STM32F4_DEBUG_CONSOLE_H

#include <stdint.h>

#include "wf/app_state.h"

#if WF_PORT_QEMU
void debug_console_init(const wf_config_t *config);
void debug_console_poll(void);
void trace_rx_byte(uint8_t byte);
void trace_compare(unsigned servo);
void trace_fault(uint8_t cause, uint32_t pc);
void trace_poll(const wf_app_t *app);
#else
static inline void debug_console_init(const wf_config_t *config)
{
    (void)config;
}
static inline void debug_console_poll(void) {}
static inline void trace_rx_byte(uint8_t byte)
{
    (void)byte;
}
static inline void trace_compare(unsigned servo)
{
    (void)servo;
}
static inline void trace_fault(uint8_t cause, uint32_t pc)
{
    (void)cause, (void)pc;
}
static inline void trace_poll(const wf_app_t *app)
{
    (void)app;
}
#endif

#endif /* WF_STM32F4_DEBUG_CONSOLE_H */
