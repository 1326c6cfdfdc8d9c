/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Vector table and reset handler of the STM32F405/407: copy .data from flash, zero .bss, paint
 * the stack, give the FPU (CP10, CP11) full access, then main. The table lists the 16 core
 * exceptions and the 82 interrupts of the F407 (RM0090 table 61); the port handles SysTick and
 * USART1. Every fault, the NMI (the clock security system's) and every stray interrupt take
 * the fault path (failsafe.c): servos neutral, a record for the next boot, a reset.
 */
#include <stdint.h>

#include "board.h"
#include "regs.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sstack, _estack;
int main(void);
void wf_systick_handler(void);
void wf_usart1_handler(void);

void wf_reset_handler(void);
void wf_fault_handler(void);
void wf_nmi_handler(void);
void wf_default_handler(void);
__attribute__((noreturn, used)) void wf_fault_from(const uint32_t *frame, uint32_t exc_return);

#define STACK_PAINT 0xA5A5A5A5u
enum { STACK_GUARD_WORDS = 8, EXCEPTION_FRAME_WORDS = 8 };

/* Takes the stacked frame (MSP or PSP, by EXC_RETURN bit 2) and moves to a fresh stack at its
 * top before any C code runs: the fault may be the stack's own overflow, and the fault path
 * never returns. */
__attribute__((naked)) void wf_fault_handler(void)
{
    __asm volatile(
        "tst lr, #4\n"
        "ite eq\n"
        "mrseq r0, msp\n"
        "mrsne r0, psp\n"
        "mov r1, lr\n"
        "ldr r2, =_estack\n"
        "mov sp, r2\n"
        "b wf_fault_from\n");
}

/* The PC and LR of the faulting code, from its exception frame (r0-r3, r12, lr, pc, xpsr) when
 * the frame lies inside the stack; 0 when it does not (an overflow whose stacking failed). */
void wf_fault_from(const uint32_t *frame, uint32_t exc_return)
{
    (void)exc_return;
    const uintptr_t at = (uintptr_t)frame;
    const bool readable = at >= (uintptr_t)&_sstack + 4u * STACK_GUARD_WORDS &&
                          at + 4u * EXCEPTION_FRAME_WORDS <= (uintptr_t)&_estack;
    board_fail(WF_RESET_FAULT, readable ? frame[6] : 0u, readable ? frame[5] : 0u);
}

/* The NMI's one source here is the clock security system: the crystal stopped and the
 * hardware moved SYSCLK to the HSI (every bus now runs at a fraction of its rate). Clear the
 * flag and reset; the next boot finds the crystal dead and sets up the HSI PLL. */
void wf_nmi_handler(void)
{
    if (RCC_CIR & RCC_CIR_CSSF) {
        RCC_CIR = RCC_CIR_CSSC;
    }
    board_fail(WF_RESET_SOFTWARE, 0u, 0u);
}

/* An interrupt enabled without a handler: a firmware error, taken as a fault. */
void wf_default_handler(void)
{
    board_fail(WF_RESET_FAULT, 0u, 0u);
}

void wf_reset_handler(void)
{
    const uint32_t *from = &_sidata;
    for (uint32_t *to = &_sdata; to < &_edata;) {
        *to++ = *from++;
    }
    for (uint32_t *to = &_sbss; to < &_ebss;) {
        *to++ = 0u;
    }
    /* Paint the stack up to 64 bytes below where this function runs: what stays painted was
     * never used (board_stack_free). */
    uint32_t sp;
    __asm volatile("mov %0, sp" : "=r"(sp));
    for (uintptr_t at = (uintptr_t)&_sstack + 4u * STACK_GUARD_WORDS; at < sp - 64u; at += 4u) {
        *(volatile uint32_t *)at = STACK_PAINT;
    }
    SCB_CPACR |= 0xFu << 20;   /* CP10 and CP11: full access, before any FPU instruction */
    __asm volatile("dsb\n isb" ::: "memory");
    (void)main();
    board_fail(WF_RESET_FAULT, 0u, 0u);
}

enum { CORE_VECTORS = 16, IRQ_VECTORS = 82 };
typedef void (*vector_t)(void);

/* __extension__: the range designators ([a ... b]) are GCC's. */
__extension__ __attribute__((section(".isr_vector"), used))
static const vector_t vectors[CORE_VECTORS + IRQ_VECTORS] = {
    [0] = (vector_t)(uintptr_t)&_estack,
    [1] = wf_reset_handler,
    [2] = wf_nmi_handler,
    [3] = wf_fault_handler,      /* HardFault */
    [4] = wf_fault_handler,      /* MemManage: the stack guard */
    [5] = wf_fault_handler,      /* BusFault */
    [6] = wf_fault_handler,      /* UsageFault */
    [11] = wf_default_handler,   /* SVCall */
    [12] = wf_default_handler,   /* DebugMonitor */
    [14] = wf_default_handler,   /* PendSV */
    [15] = wf_systick_handler,
    [CORE_VECTORS + 0 ... CORE_VECTORS + USART1_IRQN - 1] = wf_default_handler,
    [CORE_VECTORS + USART1_IRQN] = wf_usart1_handler,
    [CORE_VECTORS + USART1_IRQN + 1 ... CORE_VECTORS + IRQ_VECTORS - 1] = wf_default_handler,
};
