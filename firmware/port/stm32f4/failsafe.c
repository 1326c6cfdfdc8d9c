/* SPDX-License-Identifier: Apache-2.0 */
/*
 * What the board does when the firmware fails, and what it tells the host about it afterwards.
 *
 * - The independent watchdog (IWDG): prescaler 4, reload 1200 on the ~32 kHz LSI: 150 ms
 *   nominal, 102 ms at the LSI's fastest (47 kHz) and 282 ms at its slowest (17 kHz,
 *   datasheet). The longest legitimate poll is a few ms (512 bytes decoded, the IMU's transfers
 *   bounded at 2 ms each, one bus recovery ~0.3 ms), so 100 ms is ample margin; and a hung board
 *   is back at neutral long before the host's link timeout (500 ms without commands) would have
 *   ended a gait. main feeds it once per complete poll, never an interrupt: a hung loop with
 *   live interrupts still resets.
 * - The fault path (board_fail): both compares to the neutral pulses, the record (cause, PC,
 *   LR, CFSR, HFSR) into .noinit, a system reset. The next boot (board_boot) reads RCC_CSR and
 *   the record (wf/fault_record.h) and keeps the outcome for the HEALTH report.
 * - The stack sits at the start of RAM (stm32f4.ld) with an MPU guard region on its lowest 32
 *   bytes: an overflow faults (MemManage, stacking error) instead of running into .data and
 *   .bss. The rest is painted at boot (startup.c); the words still painted are the high-water
 *   mark.
 * - Brown-out reset at level 3 (2.7 V): the 5 flash wait states at 168 MHz need 2.7 V or more
 *   (RM0090 table 10); below that the chip must be held in reset, not run wrong.
 *
 * QEMU 7.2 models none of RCC_CSR, the IWDG and the flash interface: its build reads no reset
 * flags (the record alone tells a fault), reports no BOR_LEVEL3, and stands in for the IWDG
 * with a count of SysTick interrupts since the last feed (board_watchdog_tick), which takes the
 * same fault path with the cause IWDG. The MPU, the fault status registers and the system
 * reset are modelled.
 */
#include "board.h"
#include "debug_console.h"
#include "regs.h"
#include "wf/hal.h"

extern uint32_t _sstack, _estack;

/* Survives a reset (no start-up code touches .noinit); checked before use. */
__attribute__((section(".noinit"))) static wf_fault_record_t fault_record;

static wf_health_t boot_health;   /* the port's fields, decided at boot */

#define STACK_PAINT 0xA5A5A5A5u
enum { STACK_GUARD_BYTES = 32 };

/* --- boot ------------------------------------------------------------------------------- */
static void stack_guard_init(void)
{
    if (((MPU_TYPE >> 8) & 0xFFu) == 0u) {
        return;   /* no MPU: the placement alone (a fault below RAM's start) guards */
    }
    MPU_RNR = 0u;
    MPU_RBAR = (uint32_t)(uintptr_t)&_sstack;   /* 32-byte aligned (stm32f4.ld) */
    MPU_RASR = MPU_RASR_XN | MPU_RASR_SIZE_32B | MPU_RASR_ENABLE;   /* AP 0: no access */
    MPU_CTRL = MPU_CTRL_PRIVDEFENA | MPU_CTRL_ENABLE;
    SCB_SHCSR |= SCB_SHCSR_MEMFAULTENA;   /* an overflow is a MemManage fault of its own */
    __asm volatile("dsb\n isb" ::: "memory");
    boot_health.flags = (uint8_t)(boot_health.flags | WF_HEALTH_STACK_GUARD);
}

void board_boot(void)
{
    const uint32_t flags = RCC_CSR & RCC_CSR_FLAGS;
    RCC_CSR |= RCC_CSR_RMVF;   /* the next reset sets only its own flags */
    wf_reset_cause_decide(flags, &fault_record, &boot_health);
    stack_guard_init();
}

void board_bor_init(void)
{
#if !WF_PORT_QEMU
    enum { OPTION_WRITE_LOOPS = 4000000 };   /* > 0.5 s at 16 MHz: a sector erase is ~ms */
    if ((FLASH_OPTCR & FLASH_OPTCR_BOR_LEV_MASK) != FLASH_OPTCR_BOR_LEV3) {
        /* Only BOR_LEV changes: read protection and write protection keep their values. Done
         * once in a board's life; the option bytes are loaded at reset, so the level holds
         * from the next one (the check below reads the programmed register). */
        FLASH_OPTKEYR = FLASH_OPTKEY1;
        FLASH_OPTKEYR = FLASH_OPTKEY2;
        for (uint32_t i = 0u; i < OPTION_WRITE_LOOPS && (FLASH_SR & FLASH_SR_BSY); i++) {
        }
        FLASH_OPTCR = (FLASH_OPTCR & ~FLASH_OPTCR_BOR_LEV_MASK) | FLASH_OPTCR_BOR_LEV3;
        FLASH_OPTCR |= FLASH_OPTCR_OPTSTRT;
        for (uint32_t i = 0u; i < OPTION_WRITE_LOOPS && (FLASH_SR & FLASH_SR_BSY); i++) {
        }
        FLASH_OPTCR |= FLASH_OPTCR_OPTLOCK;
    }
    if ((FLASH_OPTCR & FLASH_OPTCR_BOR_LEV_MASK) == FLASH_OPTCR_BOR_LEV3 &&
        !(FLASH_SR & (FLASH_SR_BSY | FLASH_SR_ERRORS))) {
        boot_health.flags = (uint8_t)(boot_health.flags | WF_HEALTH_BOR_LEVEL3);
    }
#endif
}

/* --- watchdog --------------------------------------------------------------------------- */
enum { IWDG_PRESCALER_DIV4 = 0u, IWDG_RELOAD = 1199u, IWDG_UPDATE_LOOPS = 100000 };

#if WF_PORT_QEMU
/* The stand-in: SysTick interrupts since the last feed. Interrupts, not board time: QEMU drops
 * SysTick periods when the host is busy, and then the main loop did not run either. */
enum { STAND_IN_TICKS = 150 };
static volatile uint32_t ticks_unfed;
static volatile bool watchdog_running;

void board_watchdog_tick(void);
void board_watchdog_tick(void)
{
    if (watchdog_running && ++ticks_unfed > STAND_IN_TICKS) {
        board_fail(WF_RESET_IWDG, 0u, 0u);
    }
}
#endif

void board_watchdog_start(void)
{
    IWDG_KR = IWDG_KEY_START;
    IWDG_KR = IWDG_KEY_UNLOCK;
    IWDG_PR = IWDG_PRESCALER_DIV4;
    IWDG_RLR = IWDG_RELOAD;
    for (uint32_t i = 0u; i < IWDG_UPDATE_LOOPS && IWDG_SR != 0u; i++) {
    }
    IWDG_KR = IWDG_KEY_RELOAD;
#if WF_PORT_QEMU
    ticks_unfed = 0u;
    watchdog_running = true;
#endif
}

void board_watchdog_feed(void)
{
    IWDG_KR = IWDG_KEY_RELOAD;
#if WF_PORT_QEMU
    ticks_unfed = 0u;
#endif
}

/* The one wait that may hold the CPU beyond the watchdog's period: a flash sector erase
 * (storage.c: up to 0.5 s, every fetch from flash stalled, this loop's too). For its length
 * the prescaler is 64 (2.4 s nominal, 1.6 s at the LSI's fastest), then 4 again; each change
 * waits (bounded) for the IWDG to take it, and the count restarts from the reload. */
enum { IWDG_PRESCALER_DIV64 = 4u };

void board_watchdog_slow(bool slow)
{
    IWDG_KR = IWDG_KEY_RELOAD;
    IWDG_KR = IWDG_KEY_UNLOCK;
    IWDG_PR = slow ? IWDG_PRESCALER_DIV64 : IWDG_PRESCALER_DIV4;
    for (uint32_t i = 0u; i < IWDG_UPDATE_LOOPS && IWDG_SR != 0u; i++) {
    }
    IWDG_KR = IWDG_KEY_RELOAD;
}

/* --- the fault path --------------------------------------------------------------------- */
__attribute__((noreturn)) void board_fail(uint8_t cause, uint32_t pc, uint32_t lr)
{
    __asm volatile("cpsid i" ::: "memory");
    board_pwm_failsafe();
    wf_fault_record_save(&fault_record, cause, pc, lr, SCB_CFSR, SCB_HFSR);
    trace_fault(cause, pc);   /* the QEMU build: its console line */
    __asm volatile("dsb" ::: "memory");
    SCB_AIRCR = SCB_AIRCR_SYSRESETREQ;
    __asm volatile("dsb" ::: "memory");
    for (;;) {
    }
}

/* --- stack and health ------------------------------------------------------------------- */
uint32_t board_stack_size(void)
{
    return (uint32_t)((uintptr_t)&_estack - (uintptr_t)&_sstack) - STACK_GUARD_BYTES;
}

uint32_t board_stack_free(void)
{
    const uintptr_t low = (uintptr_t)&_sstack + STACK_GUARD_BYTES;
    uintptr_t at = low;
    while (at < (uintptr_t)&_estack && *(const volatile uint32_t *)at == STACK_PAINT) {
        at += 4u;
    }
    return (uint32_t)(at - low);
}

void wf_hal_health_port(wf_health_t *health)
{
    const uint8_t port_flags = WF_HEALTH_FAULT_RECORD | WF_HEALTH_BOR_LEVEL3 | WF_HEALTH_CSS_ON |
                               WF_HEALTH_STACK_GUARD;
    uint8_t flags = boot_health.flags;
    if (board_clocks.css_on) {
        flags = (uint8_t)(flags | WF_HEALTH_CSS_ON);
    }
    health->reset_cause = boot_health.reset_cause;
    health->clock_source = board_clocks.source;
    health->flags = (uint8_t)((health->flags & ~port_flags) | flags);
    health->fault_pc = boot_health.fault_pc;
    health->fault_lr = boot_health.fault_lr;
    health->fault_cfsr = boot_health.fault_cfsr;
    health->fault_hfsr = boot_health.fault_hfsr;
    health->stack_free_min = (uint16_t)board_stack_free();
    health->stack_size = (uint16_t)board_stack_size();
    health->uart_rx_overruns = board_uart_rx_overflows();
    health->i2c_bus_recoveries = board_i2c_bus_recoveries();
}
