/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Clock tree and the millisecond clock. HSE 8 MHz (the crystal of the STM32F4DISCOVERY and of
 * most F407 boards) -> PLL (M 8, N 336, P 2, Q 7) -> SYSCLK 168 MHz, USB/SDIO 48 MHz;
 * AHB 168 MHz, APB1 42 MHz, APB2 84 MHz; flash 5 wait states (RM0090 table 10, 2.7-3.6 V: the
 * brown-out reset at level 3 keeps the supply there).
 *
 * Every wait is bounded, on SysTick's counter (running from reset at the HSI's 16 MHz): a
 * crystal that does not start within HSE_START_US gives the same 168 MHz from the HSI (M 16:
 * clock source HSI_PLL, the CLOCK_FALLBACK status bit); a PLL that does not lock leaves the
 * board on the HSI at 16 MHz with every bus at 16 MHz (source HSI). With the crystal running
 * the clock security system is armed: if the crystal stops later, the hardware switches to the
 * HSI and raises the NMI (startup.c), whose handler resets the board through the fault path;
 * the next boot then finds the crystal dead and takes the fallback.
 */
#include "board.h"
#include "regs.h"
#include "wf/hal.h"

static volatile uint32_t millis;

board_clocks_t board_clocks = {16000000u, 16000000u, 16000000u, 16000000u, WF_CLOCK_HSI,
                               false};

#if WF_PORT_QEMU
void board_watchdog_tick(void);

/* QEMU's SysTick loses periods when the host runs its timer late (a loaded machine): counting
 * interrupts, the board clock fell 25-40 % behind the wall. Its TIM2 counter is computed from
 * QEMU's virtual clock instead (1 ns per count with PSC 0, 32 bits: wraps every 4.3 s), so the
 * SysTick handler adds the nanoseconds that really passed: late ticks lose no time. */
static uint32_t last_count;
static uint32_t leftover_ns;

static void virtual_clock_init(void)
{
    RCC_APB1ENR |= RCC_APB1ENR_TIM2;
    TIM_PSC(TIM2_BASE) = 0u;
    TIM_ARR(TIM2_BASE) = 0xFFFFFFFFu;
    TIM_CR1(TIM2_BASE) = TIM_CR1_CEN;
    last_count = TIM_CNT(TIM2_BASE);
}

void wf_systick_handler(void)
{
    const uint32_t count = TIM_CNT(TIM2_BASE);
    const uint64_t ns = (uint64_t)leftover_ns + (uint32_t)(count - last_count);
    last_count = count;
    millis = millis + (uint32_t)(ns / 1000000u);   /* the only writer */
    leftover_ns = (uint32_t)(ns % 1000000u);
    board_watchdog_tick();
}

uint32_t board_virtual_ns(void)
{
    return TIM_CNT(TIM2_BASE);
}
#else
static void virtual_clock_init(void) {}

void wf_systick_handler(void)
{
    millis = millis + 1u;   /* the only writer; a 32-bit load elsewhere is atomic */
}
#endif

uint32_t wf_hal_millis(void)
{
    return millis;
}

/* SysTick's 24-bit counter counts down at SYSCLK whether or not its interrupt is on. */
enum { SYSTICK_MASK = 0x00FFFFFFu };

void board_delay_us(uint32_t us)
{
    const uint32_t reload = SYST_RVR & SYSTICK_MASK;
    uint32_t left = us * (board_clocks.sysclk_hz / 1000000u) + 1u;
    uint32_t before = SYST_CVR & SYSTICK_MASK;
    if (!(SYST_CSR & SYST_CSR_ENABLE)) {
        return;   /* not running: nothing to count on (never after board_clock_init) */
    }
    while (left > 0u) {
        const uint32_t now = SYST_CVR & SYSTICK_MASK;
        const uint32_t passed = now <= before ? before - now : before + reload + 1u - now;
        before = now;
        left = passed >= left ? 0u : left - passed;
    }
}

#if !WF_PORT_QEMU
enum {
    HSE_START_US = 50000,   /* a crystal starts in ~2 ms; 25x that is a dead one */
    PLL_LOCK_US = 2000,     /* lock time is 100-300 us (datasheet: tLOCK) */
    SWITCH_US = 100,
    HSI_HZ = 16000000,
};

/* Waits until (RCC register & mask) == want, at most us microseconds of the current clock. */
static bool wait_rcc(volatile uint32_t *reg, uint32_t mask, uint32_t want, uint32_t us)
{
    uint32_t before = SYST_CVR & SYSTICK_MASK;
    uint32_t left = us * (board_clocks.sysclk_hz / 1000000u);
    while ((*reg & mask) != want) {
        const uint32_t now = SYST_CVR & SYSTICK_MASK;
        const uint32_t passed = now <= before ? before - now : before + SYSTICK_MASK + 1u - now;
        before = now;
        if (passed >= left) {
            return (*reg & mask) == want;
        }
        left -= passed;
    }
    return true;
}
#endif

void board_clock_init(void)
{
#if WF_PORT_QEMU
    /* QEMU does not model the RCC: its ready flags read 0. The emulated core runs at the
     * 168 MHz the SysTick reload assumes whatever RCC says. */
    board_clocks = (board_clocks_t){168000000u, 42000000u, 84000000u, 84000000u,
                                    WF_CLOCK_EMULATED, false};
#else
    /* SysTick free-running at the HSI's 16 MHz: the clock of the bounded waits below. */
    SYST_RVR = SYSTICK_MASK;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_CLKSOURCE | SYST_CSR_ENABLE;
    board_clocks = (board_clocks_t){HSI_HZ, HSI_HZ, HSI_HZ, HSI_HZ, WF_CLOCK_HSI, false};
    RCC_CR |= RCC_CR_HSEON;
    const bool hse = wait_rcc(&RCC_CR, RCC_CR_HSERDY, RCC_CR_HSERDY, HSE_START_US);
    if (!hse) {
        RCC_CR &= ~RCC_CR_HSEON;
    }
    /* Q 7 (27:24); P 2 is field value 0 (17:16); N 336 (14:6); M 8 from the 8 MHz crystal, M 16
     * from the 16 MHz HSI: 2 MHz into the VCO either way, 336 MHz out, 168 MHz SYSCLK. */
    RCC_PLLCFGR = (hse ? RCC_PLLCFGR_SRC_HSE | 8u : 16u) | (7u << 24) | (0u << 16) | (336u << 6);
    RCC_CR |= RCC_CR_PLLON;
    if (!wait_rcc(&RCC_CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY, PLL_LOCK_US)) {
        RCC_CR &= ~(RCC_CR_PLLON | RCC_CR_HSEON);   /* 16 MHz on the HSI, every bus undivided */
        RCC_AHB1ENR |= RCC_AHB1ENR_GPIOA | RCC_AHB1ENR_GPIOB | RCC_AHB1ENR_GPIOC;
        return;
    }
    /* Wait states before the faster clock (RM0090 3.5.1). */
    FLASH_ACR = FLASH_ACR_LATENCY_5WS | FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
    RCC_CFGR = RCC_CFGR_HPRE_DIV1 | RCC_CFGR_PPRE1_DIV4 | RCC_CFGR_PPRE2_DIV2 | RCC_CFGR_SW_PLL;
    if (!wait_rcc(&RCC_CFGR, RCC_CFGR_SWS_MASK, RCC_CFGR_SWS_PLL, SWITCH_US)) {
        RCC_CFGR = 0u;   /* back to the HSI, undivided */
        RCC_CR &= ~(RCC_CR_PLLON | RCC_CR_HSEON);
        RCC_AHB1ENR |= RCC_AHB1ENR_GPIOA | RCC_AHB1ENR_GPIOB | RCC_AHB1ENR_GPIOC;
        return;
    }
    board_clocks = (board_clocks_t){168000000u, 42000000u, 84000000u, 84000000u,
                                    hse ? WF_CLOCK_HSE_PLL : WF_CLOCK_HSI_PLL, false};
    if (hse) {
        RCC_CR |= RCC_CR_CSSON;
        board_clocks.css_on = true;
    }
#endif
    RCC_AHB1ENR |= RCC_AHB1ENR_GPIOA | RCC_AHB1ENR_GPIOB | RCC_AHB1ENR_GPIOC;
}

void board_systick_init(void)
{
    virtual_clock_init();
    SYST_RVR = board_clocks.sysclk_hz / 1000u - 1u;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_CLKSOURCE | SYST_CSR_TICKINT | SYST_CSR_ENABLE;
}
