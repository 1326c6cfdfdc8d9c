/*
 * Vector table and reset handler of the STM32F405/407: copy .data from flash, zero .bss,
 * give the FPU (CP10, CP11) full access, then main. The table lists the 16 core exceptions
 * and the 82 interrupts of the F407 (RM0090 table 61); the port handles SysTick and USART1.
 * Every other source lands in a handler that stops in a loop, where a debugger shows which
 * one (IPSR).
 */
#include <stdint.h>

#include "regs.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void wf_systick_handler(void);
void wf_usart1_handler(void);

void wf_reset_handler(void);
void wf_default_handler(void);

void wf_default_handler(void)
{
    for (;;) {
    }
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
    SCB_CPACR |= 0xFu << 20;   /* CP10 and CP11: full access, before any FPU instruction */
    __asm volatile("dsb\n isb" ::: "memory");
    (void)main();
    for (;;) {
    }
}

enum { CORE_VECTORS = 16, IRQ_VECTORS = 82 };
typedef void (*vector_t)(void);

/* __extension__: the range designators ([a ... b]) are GCC's. */
__extension__ __attribute__((section(".isr_vector"), used))
static const vector_t vectors[CORE_VECTORS + IRQ_VECTORS] = {
    [0] = (vector_t)(uintptr_t)&_estack,
    [1] = wf_reset_handler,
    [2] = wf_default_handler,    /* NMI */
    [3] = wf_default_handler,    /* HardFault */
    [4] = wf_default_handler,    /* MemManage */
    [5] = wf_default_handler,    /* BusFault */
    [6] = wf_default_handler,    /* UsageFault */
    [11] = wf_default_handler,   /* SVCall */
    [12] = wf_default_handler,   /* DebugMonitor */
    [14] = wf_default_handler,   /* PendSV */
    [15] = wf_systick_handler,
    [CORE_VECTORS + 0 ... CORE_VECTORS + USART1_IRQN - 1] = wf_default_handler,
    [CORE_VECTORS + USART1_IRQN] = wf_usart1_handler,
    [CORE_VECTORS + USART1_IRQN + 1 ... CORE_VECTORS + IRQ_VECTORS - 1] = wf_default_handler,
};
