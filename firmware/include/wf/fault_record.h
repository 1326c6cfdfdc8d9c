/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The record a port's fault handler leaves for the next boot, and the reset cause read from it
 * and from the reset flags. Portable: the stm32f4 port keeps the record in RAM that no start-up
 * code clears (.noinit) and passes RCC_CSR; the host port models both, so the decision rules
 * are tested on the host (QEMU 7.2 models neither RCC_CSR nor the IWDG).
 */
#ifndef WF_FAULT_RECORD_H
#define WF_FAULT_RECORD_H

#include <stdbool.h>
#include <stdint.h>

#include "wf/health.h"

/* The reset flags, at their RCC_CSR bit positions (RM0090 7.3.21): a port without RCC_CSR
 * passes the same bits from its own model. BOR is also set by a power-on reset, and PIN by
 * every internal reset (the chip drives NRST low): the decision below takes the most specific
 * flag first. */
#define WF_RESET_FLAG_BOR (1u << 25)
#define WF_RESET_FLAG_PIN (1u << 26)
#define WF_RESET_FLAG_POR (1u << 27)
#define WF_RESET_FLAG_SOFTWARE (1u << 28)
#define WF_RESET_FLAG_IWDG (1u << 29)
#define WF_RESET_FLAG_WWDG (1u << 30)
#define WF_RESET_FLAG_LOW_POWER (1u << 31)

/* What the handler that reset the board saw. `cause` is a wf_reset_cause_t: FAULT (a
 * HardFault, MemManage, BusFault or UsageFault: the registers are valid), SOFTWARE (the clock
 * security system tripped: the next boot finds the crystal dead and falls back to the HSI), or
 * IWDG (an emulator's stand-in for the watchdog it does not model). Valid only while `check`
 * matches: RAM after a power loss holds anything. */
typedef struct {
    uint32_t magic;
    uint32_t cause;
    uint32_t pc, lr, cfsr, hfsr;
    uint32_t check;
} wf_fault_record_t;

void wf_fault_record_save(wf_fault_record_t *record, uint8_t cause, uint32_t pc, uint32_t lr,
                          uint32_t cfsr, uint32_t hfsr);

bool wf_fault_record_valid(const wf_fault_record_t *record);

/* Decides why the board reset from the reset flags and the record, in this order: low-power,
 * window watchdog, independent watchdog, power-on, brown-out (BOR without POR), then a valid
 * record's own cause, then software, then pin; UNKNOWN when nothing says. Sets
 * health->reset_cause, and for a fault the fault_* fields and WF_HEALTH_FAULT_RECORD (other
 * fields untouched). The record is consumed: invalidated, so the next reset is read afresh. */
void wf_reset_cause_decide(uint32_t flags, wf_fault_record_t *record, wf_health_t *health);

#endif /* WF_FAULT_RECORD_H */
