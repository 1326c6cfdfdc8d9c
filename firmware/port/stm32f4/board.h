/*
 * The stm32f4 port's own set-up calls (what main runs before the core starts) and its clock
 * tree: HSE 8 MHz -> PLL -> SYSCLK 168 MHz, APB1 42 MHz (timers 84 MHz), APB2 84 MHz.
 */
#ifndef WF_STM32F4_BOARD_H
#define WF_STM32F4_BOARD_H

#include <stdbool.h>
#include <stdint.h>

enum {
    BOARD_SYSCLK_HZ = 168000000,
    BOARD_APB1_HZ = 42000000,
    BOARD_APB1_TIMER_HZ = 84000000,   /* APB1 prescaler != 1: the timers run at twice APB1 */
    BOARD_APB2_HZ = 84000000,
    BOARD_UART_BAUD = 115200,
};

/* HSE + PLL to 168 MHz, flash wait states; the QEMU build skips the ready-flag waits (QEMU
 * does not model the RCC: every flag reads 0). */
void board_clock_init(void);
void board_systick_init(void);
/* The QEMU build: QEMU's virtual clock in ns (TIM2's counter, wraps every 4.3 s). */
uint32_t board_virtual_ns(void);
void board_uart_init(void);
/* USART1 overruns: bytes lost because the receive ring stayed full too long. */
uint32_t board_uart_rx_overflows(void);
void board_i2c_init(void);
void board_adc_init(void);

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
