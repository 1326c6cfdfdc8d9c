/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The ARM figure of one CPG step (make cpg-arm-count): a bare image for QEMU's netduinoplus2
 * (Cortex-M4F, the firmware's compiler flags) that takes STEPS steps of eq 1 from rest with
 * Table 1 at 2 Hz and exits through semihosting. Run with one instruction per translation
 * block and every executed block logged, the count of two images (0 and 1000 steps) differs
 * by the instructions of 1000 steps. QEMU models no cycle timing: on the M4 most of these
 * instructions take one cycle (FPU arithmetic, ALU) and loads, stores and taken branches two
 * to four, so the cycles are about 1.2 to 1.5 times the count.
 */
#include <stdint.h>

#include "wf/cpg.h"

#ifndef STEPS
#define STEPS 0
#endif

extern uint32_t _estack;
void reset(void);

typedef void (*vector_t)(void);
/* The initial stack pointer is a data address in a table of handlers (the port's startup.c
 * does the same): the GCC extension marks that one conversion. */
__extension__ __attribute__((section(".vectors"), used)) static const vector_t vectors[2] = {
    (vector_t)(uintptr_t)&_estack, reset};

static wf_cpg_t cpg;
volatile float sink;

static void semihosting_exit(void)
{
    register uint32_t op __asm("r0") = 0x18u;       /* SYS_EXIT */
    register uint32_t reason __asm("r1") = 0x20026u; /* ADP_Stopped_ApplicationExit */
    __asm volatile("bkpt 0xAB" : : "r"(op), "r"(reason) : "memory");
}

void reset(void)
{
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20; /* CPACR: the FPU on */
    __asm volatile("dsb\n\tisb");
    const wf_cpg_params_t table1 = {.frequency_hz = 2.0f, .amplitude = {0.38f, 0.47f},
                                    .w12 = -0.41f, .w21 = 0.64f, .phi12 = 1.76f,
                                    .phi21 = 1.06f, .alpha = 20.0f};
    wf_cpg_init(&cpg, &table1);
    /* i + 1 <= STEPS: with STEPS 0, i < STEPS would be a compare GCC flags as always false. */
    for (unsigned long i = 0; i + 1 <= (unsigned long)STEPS; i++) {
        wf_cpg_step(&cpg);
    }
    float angle[2];
    wf_cpg_output(&cpg, angle, 0);
    sink = angle[0];
    semihosting_exit();
    for (;;) {
    }
}
