/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Servo PWM on TIM3 (RM0090 18): channel 1 = servo 0 on PC6, channel 2 = servo 1 on PC7
 * (AF2). The timer counts at 1 MHz (PSC 83 from the 84 MHz APB1 timer clock; 15 from the
 * 16 MHz of the HSI without PLL), so a compare
 * value is a pulse width in microseconds and the period is 1e6 / frame_hz ticks: 20000 at
 * 50 Hz, 3003 at 333 Hz (a 16-bit ARR holds both). PWM mode 1 with preload: a new compare
 * takes effect at the next period, so a pulse is never cut short.
 */
#include "debug_console.h"
#include "gpio.h"
#include "board.h"
#include "pwm.h"
#include "regs.h"
#include "wf/hal.h"

enum { PWM_TICK_HZ = 1000000, PWM_MIN_HZ = 50, PWM_MAX_HZ = 333 };

static uint32_t period_ticks;
static uint32_t failsafe_compare[2];

void board_pwm_set_failsafe(const uint32_t compare[2])
{
    failsafe_compare[0] = compare[0];
    failsafe_compare[1] = compare[1];
}

/* The fault path's write: only registers, nothing that could itself fault on a broken state.
 * The compares are preloaded: the pulse under way finishes and the next one is neutral. The
 * reset that follows stops the timer and leaves the pins without pulses until the next boot
 * writes neutral again, so one neutral pulse is let out first: the wait for the next update
 * and for that pulse's end is at most two frames (40 ms at 50 Hz), inside the watchdog's
 * shortest 102 ms, and counted in microseconds of SysTick (interrupts are masked here). */
void board_pwm_failsafe(void)
{
    if (period_ticks == 0u) {
        return;   /* the timer never started: its pins are still inputs, no pulse goes out */
    }
    TIM_CCR1(TIM3_BASE) = failsafe_compare[0];
    TIM_CCR2(TIM3_BASE) = failsafe_compare[1];
    const uint32_t longest = failsafe_compare[0] > failsafe_compare[1] ? failsafe_compare[0]
                                                                       : failsafe_compare[1];
    enum { STEP_US = 10 };
    uint32_t steps = 2u * period_ticks / STEP_US + 1u;   /* 1 tick = 1 us */
    TIM_SR(TIM3_BASE) = ~TIM_SR_UIF;   /* rc_w0: writing 0 clears the update flag */
    for (; steps > 0u && !(TIM_SR(TIM3_BASE) & TIM_SR_UIF); steps--) {
        board_delay_us(STEP_US);
    }
    for (; steps > 0u && TIM_CNT(TIM3_BASE) <= longest; steps--) {
        board_delay_us(STEP_US);
    }
}

uint32_t board_pwm_period(void)
{
    return period_ticks;
}

uint32_t wf_hal_pwm_ticks_per_us(void)
{
    return PWM_TICK_HZ / 1000000u;
}

bool wf_hal_pwm_init(uint32_t frame_hz)
{
    if (frame_hz < PWM_MIN_HZ || frame_hz > PWM_MAX_HZ) {
        return false;
    }
    RCC_APB1ENR |= RCC_APB1ENR_TIM3;
    gpio_alternate(GPIOC_BASE, 6u, 2u, 0);
    gpio_alternate(GPIOC_BASE, 7u, 2u, 0);
    period_ticks = PWM_TICK_HZ / frame_hz;
    TIM_CR1(TIM3_BASE) = 0u;
    TIM_PSC(TIM3_BASE) = board_clocks.apb1_timer_hz / PWM_TICK_HZ - 1u;
    TIM_ARR(TIM3_BASE) = period_ticks - 1u;
    TIM_CCMR1(TIM3_BASE) = TIM_CCMR1_OC1M_PWM1 | TIM_CCMR1_OC1PE | TIM_CCMR1_OC2M_PWM1
                           | TIM_CCMR1_OC2PE;
    TIM_CCER(TIM3_BASE) = TIM_CCER_CC1E | TIM_CCER_CC2E;
    TIM_EGR(TIM3_BASE) = TIM_EGR_UG;   /* load PSC and ARR now */
    TIM_CR1(TIM3_BASE) = TIM_CR1_ARPE | TIM_CR1_CEN;
    return true;
}

void wf_hal_pwm_set_compare(unsigned servo, uint32_t compare_ticks)
{
    volatile uint32_t *ccr = servo == 0u ? &TIM_CCR1(TIM3_BASE) : &TIM_CCR2(TIM3_BASE);
    if (servo >= WF_SERVO_COUNT) {
        return;
    }
    if (compare_ticks > period_ticks) {
        compare_ticks = period_ticks;   /* a compare beyond the period is a constant high */
    }
    *ccr = compare_ticks;
    trace_compare(servo);   /* the QEMU build: a "P" line when the register changed */
}
