/* SPDX-License-Identifier: Apache-2.0 */
/*
 * What the board knows about its own health, reported to the host in a HEALTH message (see
 * PROTOCOL.md). The port fills what only it can know (reset cause, fault record, clock source,
 * stack high-water mark, UART overruns, I2C bus recoveries); the core fills the rest (decoder
 * drops, transmit drops, IMU faults) and packs the message.
 */
#ifndef WF_HEALTH_H
#define WF_HEALTH_H

#include <stdint.h>

typedef enum {
    WF_RESET_UNKNOWN = 0,
    WF_RESET_POWER_ON = 1,
    WF_RESET_PIN = 2,
    WF_RESET_BROWN_OUT = 3,
    WF_RESET_IWDG = 4,
    WF_RESET_WWDG = 5,
    WF_RESET_SOFTWARE = 6,
    WF_RESET_FAULT = 7, /* the fault handler's own reset: the fault_* fields are valid */
    WF_RESET_LOW_POWER = 8,
} wf_reset_cause_t;

typedef enum {
    WF_CLOCK_HSE_PLL = 0, /* 168 MHz from the crystal */
    WF_CLOCK_HSI_PLL = 1, /* the crystal did not start (or the CSS tripped): PLL from HSI */
    WF_CLOCK_HSI = 2,     /* 16 MHz, no PLL */
    WF_CLOCK_EMULATED = 3 /* the emulator build: no RCC to set up */
} wf_clock_source_t;

enum {
    WF_HEALTH_FAULT_RECORD = 0x01, /* fault_pc, fault_lr, fault_cfsr, fault_hfsr are valid */
    WF_HEALTH_BOR_LEVEL3 = 0x02,   /* brown-out reset at 2.7 V confirmed in the option bytes */
    WF_HEALTH_CSS_ON = 0x04,       /* the clock security system is armed */
    WF_HEALTH_STACK_GUARD = 0x08,  /* an overflow faults instead of overwriting data */
};

typedef struct {
    uint8_t reset_cause;  /* wf_reset_cause_t */
    uint8_t clock_source; /* wf_clock_source_t */
    uint8_t flags;        /* WF_HEALTH_ */
    uint32_t fault_pc, fault_lr, fault_cfsr, fault_hfsr;
    uint32_t uptime_ms;
    uint16_t stack_free_min; /* bytes of the stack never written since boot */
    uint16_t stack_size;
    uint32_t uart_rx_overruns;
    uint32_t tx_bytes_dropped;
    uint32_t rx_crc, rx_frame, rx_unknown_type, rx_length, rx_invalid;
    uint16_t imu_faults, imu_recoveries, i2c_bus_recoveries;
} wf_health_t;

#endif /* WF_HEALTH_H */
