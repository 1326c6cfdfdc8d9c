/*
 * Clock tree and the millisecond clock. HSE 8 MHz (the crystal of the STM32F4DISCOVERY and of
 * most F407 boards) -> PLL (M 8, N 336, P 2, Q 7) -> SYSCLK 168 MHz, USB/SDIO 48 MHz;
 * AHB 168 MHz, APB1 42 MHz, APB2 84 MHz; flash 5 wait states (RM0090 table 10, 2.7-3.6 V).
 */
#include "board.h"
#include "regs.h"
#include "wf/hal.h"

static volatile uint32_t millis;

#if WF_PORT_QEMU
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

#if WF_PORT_QEMU
/* QEMU does not model the RCC: its ready flags read 0 and a wait for one never ends. The
 * emulated core runs at the 168 MHz the SysTick reload below assumes whatever RCC says. */
#define WAIT_FOR(condition) ((void)0)
#else
#define WAIT_FOR(condition) \
    do {                    \
    } while (!(condition))
#endif

void board_clock_init(void)
{
    RCC_CR |= RCC_CR_HSEON;
    WAIT_FOR(RCC_CR & RCC_CR_HSERDY);
    /* PLLSRC HSE (bit 22); Q 7 (27:24); P 2 is field value 0 (17:16); N 336 (14:6); M 8. */
    RCC_PLLCFGR = (1u << 22) | (7u << 24) | (0u << 16) | (336u << 6) | 8u;
    RCC_CR |= RCC_CR_PLLON;
    WAIT_FOR(RCC_CR & RCC_CR_PLLRDY);
    FLASH_ACR = FLASH_ACR_LATENCY_5WS | FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
    RCC_CFGR = RCC_CFGR_HPRE_DIV1 | RCC_CFGR_PPRE1_DIV4 | RCC_CFGR_PPRE2_DIV2 | RCC_CFGR_SW_PLL;
    WAIT_FOR((RCC_CFGR & RCC_CFGR_SWS_MASK) == RCC_CFGR_SWS_PLL);
    RCC_AHB1ENR |= RCC_AHB1ENR_GPIOA | RCC_AHB1ENR_GPIOB | RCC_AHB1ENR_GPIOC;
}

void board_systick_init(void)
{
    virtual_clock_init();
    SYST_RVR = BOARD_SYSCLK_HZ / 1000u - 1u;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_CLKSOURCE | SYST_CSR_TICKINT | SYST_CSR_ENABLE;
}
