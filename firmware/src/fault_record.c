/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/fault_record.h"

enum { RECORD_MAGIC = 0x57464654u }; /* "WFFT" */

static uint32_t check_of(const wf_fault_record_t *r)
{
    return ~(r->magic ^ r->cause ^ r->pc ^ (r->lr << 1) ^ (r->cfsr << 2) ^ (r->hfsr << 3));
}

void wf_fault_record_save(wf_fault_record_t *record, uint8_t cause, uint32_t pc, uint32_t lr,
                          uint32_t cfsr, uint32_t hfsr)
{
    record->magic = RECORD_MAGIC;
    record->cause = cause;
    record->pc = pc;
    record->lr = lr;
    record->cfsr = cfsr;
    record->hfsr = hfsr;
    record->check = check_of(record);
}

bool wf_fault_record_valid(const wf_fault_record_t *record)
{
    return record->magic == RECORD_MAGIC && record->check == check_of(record) &&
           (record->cause == WF_RESET_FAULT || record->cause == WF_RESET_SOFTWARE ||
            record->cause == WF_RESET_IWDG);
}

void wf_reset_cause_decide(uint32_t flags, wf_fault_record_t *record, wf_health_t *health)
{
    const bool recorded = wf_fault_record_valid(record);
    uint8_t cause = WF_RESET_UNKNOWN;
    if (flags & WF_RESET_FLAG_LOW_POWER) {
        cause = WF_RESET_LOW_POWER;
    } else if (flags & WF_RESET_FLAG_WWDG) {
        cause = WF_RESET_WWDG;
    } else if (flags & WF_RESET_FLAG_IWDG) {
        cause = WF_RESET_IWDG;
    } else if (flags & WF_RESET_FLAG_POR) {
        cause = WF_RESET_POWER_ON;
    } else if (flags & WF_RESET_FLAG_BOR) {
        cause = WF_RESET_BROWN_OUT;
    } else if (recorded) {
        cause = (uint8_t)record->cause;
    } else if (flags & WF_RESET_FLAG_SOFTWARE) {
        cause = WF_RESET_SOFTWARE;
    } else if (flags & WF_RESET_FLAG_PIN) {
        cause = WF_RESET_PIN;
    }
    health->reset_cause = cause;
    if (recorded && cause == WF_RESET_FAULT) {
        health->fault_pc = record->pc;
        health->fault_lr = record->lr;
        health->fault_cfsr = record->cfsr;
        health->fault_hfsr = record->hfsr;
        health->flags = (uint8_t)(health->flags | WF_HEALTH_FAULT_RECORD);
    }
    record->magic = 0u;
    record->check = 0u;
}
