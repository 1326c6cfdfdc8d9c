/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The hardware interface: everything the portable core asks of a board.
 *
 * Two ports implement it: port/host (POSIX: a pty or stdin/stdout, a simulated clock for
 * tests) and port/stm32f4 (registers of RM0090, interrupt-driven USART, TIM PWM, I2C1, ADC,
 * SysTick, flash sector 2 for the calibration). The core never touches a register and never
 * allocates: every buffer it uses is a fixed array inside its own state structures.
 *
 * Calls come from one context (the main loop, or one RTOS task); the ports make the UART
 * queues safe against their own interrupt handlers.
 */
#ifndef WF_HAL_H
#define WF_HAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wf/health.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { WF_SERVO_COUNT = 2 };

/* Milliseconds since power-up; wraps at 2^32 (every comparison in the core is modular). */
uint32_t wf_hal_millis(void);

/* Moves up to max received bytes into buf without blocking; returns how many. */
size_t wf_hal_uart_read(uint8_t *buf, size_t max);

/* Queues len bytes for transmission without blocking, all or nothing: returns len, or 0 (and
 * queues nothing) when the transmit queue has less room than len. The core writes one whole
 * frame per call, so a frame goes out whole or not at all, never cut: a cut frame would reach
 * the receiver as a damaged run that also costs it the next frame's leading delimiter. */
size_t wf_hal_uart_write(const uint8_t *buf, size_t len);

/* Timer ticks per microsecond of the servo PWM timer, and the compare register's full period
 * in ticks (set by wf_hal_pwm_init). */
uint32_t wf_hal_pwm_ticks_per_us(void);

/* Starts PWM on both servo channels at frame_hz (50..333 Hz); returns false if the rate is out
 * of range, and then changes nothing. */
bool wf_hal_pwm_init(uint32_t frame_hz);

/* Writes a compare value (pulse width in timer ticks) to servo channel 0 or 1. */
void wf_hal_pwm_set_compare(unsigned servo, uint32_t compare_ticks);

/* One I2C transaction with the 7-bit address: writes tx_len bytes, then (repeated start) reads
 * rx_len bytes. Returns false on NACK, bus error or timeout; rx is then unspecified. Bounded: a
 * stuck or absent device costs at most a few ms. After a failure, and when it finds the bus
 * busy, the port runs the bus recovery (wf/i2c_bus.h) itself, so the next call starts from an
 * idle bus: the core only retries. */
bool wf_hal_i2c_transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                         size_t rx_len);

/* The battery voltage divider's ADC reading, 12-bit (0..4095), or a negative value when no
 * conversion is available. */
int32_t wf_hal_adc_battery_raw(void);

/* Fills the fields of *health that only the port knows and leaves every other one as it is:
 * reset_cause and the fault record (fault_pc, fault_lr, fault_cfsr, fault_hfsr and
 * WF_HEALTH_FAULT_RECORD: read once at boot, then the same every call), clock_source, the
 * flags WF_HEALTH_BOR_LEVEL3, WF_HEALTH_CSS_ON and WF_HEALTH_STACK_GUARD, stack_free_min and
 * stack_size (bytes; 0, 0 when the port cannot tell), uart_rx_overruns, i2c_bus_recoveries.
 * The core calls it before it packs each HEALTH message, and at wf_app_init: the clock source
 * does not change without a reset, so WF_STATUS_CLOCK_FALLBACK (clock_source HSI_PLL or HSI)
 * can be taken from that first call. Cheap enough for every poll (no bus transfer; the stack
 * scan reads at most the stack's 2 KB once), never called from an interrupt. */
void wf_hal_health_port(wf_health_t *health);

/* The calibration's storage (wf/calibration_store.h): one erase unit of wf_hal_storage_size
 * bytes (a multiple of 4; 0 when the board has none), read as bytes, erased whole (every byte
 * 0xFF) and programmed in 32-bit words at word-aligned offsets, words in memory order (the
 * bytes of a little-endian CPU). Programming only clears bits (flash): the core programs
 * erased words only and reads each record back. Each call is bounded and returns false when
 * it failed or the range is outside the unit; a port calls the slow ones (erase: up to
 * 0.5 s on an STM32F4 sector) only for a SERVO_TRIM SAVE or FACTORY, which the core takes in
 * stream mode only. */
size_t wf_hal_storage_size(void);
bool wf_hal_storage_read(uint32_t offset, uint8_t *buf, size_t len);
bool wf_hal_storage_erase(void);
bool wf_hal_storage_program(uint32_t offset, const uint32_t *words, size_t count);

#ifdef __cplusplus
}
#endif

#endif /* WF_HAL_H */
