/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The stm32f4 port's own set-up calls (what main runs before the core starts), its clock tree
 * and its fail-safe parts: HSE 8 MHz -> PLL -> SYSCLK 168 MHz, APB1 42 MHz (timers 84 MHz),
 * APB2 84 MHz; with a dead crystal the same from the HSI, and without a PLL 16 MHz throughout.
 */
#ifndef WF_STM32F4_BOARD_H
#define WF_STM32F4_BOARD_H

#include <stdbool.h>
#include <stdint.h>

#include "wf/fault_record.h"
#include "wf/health.h"

enum { BOARD_UART_BAUD = 115200 };

/* The clocks the set-up reached (board_clock_init): every divider the drivers compute
 * (baud rate, I2C timing, PWM prescaler, SysTick reload) comes from here, not from constants,
 * so a fallback clock keeps the link's baud rate and the servo pulse widths right. */
typedef struct {
    uint32_t sysclk_hz, apb1_hz, apb1_timer_hz, apb2_hz;
    uint8_t source; /* wf_clock_source_t */
    bool css_on;
} board_clocks_t;

extern board_clocks_t board_clocks;

/* Start-up, in main's order. board_boot: the reset cause (RCC_CSR and the .noinit record, then
 * RMVF), the stack guard (MPU) and MemManage on. board_bor_init: brown-out reset at level 3
 * (2.7 V) in the option bytes, programmed if it is not, and checked. board_watchdog_start: the
 * IWDG (board_watchdog.c says why 150 ms). board_clock_init: HSE and PLL with bounded waits,
 * the HSI fallback, the CSS; the QEMU build skips the RCC (not modelled). */
void board_boot(void);
void board_bor_init(void);
void board_watchdog_start(void);
void board_watchdog_feed(void);
/* true: the watchdog's period stretched to ~2.4 s for a flash sector erase (storage.c); false:
 * back to 150 ms. Both restart the count. */
void board_watchdog_slow(bool slow);
void board_clock_init(void);
void board_systick_init(void);
/* Busy-waits at least `us` microseconds on SysTick's counter (no interrupt needed). */
void board_delay_us(uint32_t us);
/* The QEMU build: QEMU's virtual clock in ns (TIM2's counter, wraps every 4.3 s). */
uint32_t board_virtual_ns(void);
void board_uart_init(void);
/* USART1 overruns: bytes lost because the receive ring stayed full too long. */
uint32_t board_uart_rx_overflows(void);
void board_i2c_init(void);
uint16_t board_i2c_bus_recoveries(void);
void board_adc_init(void);

/* The compares a fault handler writes (the neutral pulses the core set at wf_app_init), and
 * the write itself: straight to TIM3, no call into the core. */
void board_pwm_set_failsafe(const uint32_t compare[2]);
void board_pwm_failsafe(void);

/* The fault path: servos neutral, the record saved for the next boot, a system reset. Called
 * by the fault handlers (startup.c), the CSS's NMI and the QEMU build's watchdog stand-in. */
__attribute__((noreturn)) void board_fail(uint8_t cause, uint32_t pc, uint32_t lr);

/* Bytes of the stack never written since boot (the painted words left), and its size. */
uint32_t board_stack_free(void);
uint32_t board_stack_size(void);

/* Masks interrupts and returns the previous PRIMASK; board_irq_restore puts it back. */
static inline uint32_t board_irq_save(void)
{
    uint32_t primask;
    __asm volatile("mrs %0, primask\n cpsid i" : "=r"(primask)::"memory");
    return primask;
}

static inline void board_irq_restore(uint32_t primask)
{
    __asm volatile("msr primask, %0" ::"r"(primask) : "memory");
}

#endif /* WF_STM32F4_BOARD_H */
