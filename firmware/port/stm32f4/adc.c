/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The battery divider on ADC1 channel 1 = PA1 (RM0090 13), 12 bits, 480-cycle sampling (the
 * divider's source impedance is high). Never blocks: each call takes the conversion that has
 * finished, if any, and starts the next. ADON is set and the ADC's power-up time passed
 * (tSTAB, 3 us at most: datasheet) before the first SWSTART: a start during power-up is lost,
 * and the battery would read "no conversion" for ever. A conversion that never ends (an
 * overrun, a lost start) is started again after RESTART_MS. QEMU's ADC model returns a made-up
 * ramp, not a voltage: the QEMU build reports no conversion (-1).
 */
#include "board.h"
#include "gpio.h"
#include "regs.h"
#include "wf/hal.h"

enum { ADC_STAB_US = 3, RESTART_MS = 10 };

static int32_t last_raw = -1;
#if !WF_PORT_QEMU
static uint32_t started_ms;
#endif

void board_adc_init(void)
{
#if !WF_PORT_QEMU
    RCC_APB2ENR |= RCC_APB2ENR_ADC1;
    gpio_analog(GPIOA_BASE, 1u);
    ADC_CCR = ADC_CCR_ADCPRE_DIV4;        /* 84 MHz / 4 = 21 MHz, within the 36 MHz limit */
    ADC_SMPR2(ADC1_BASE) = 7u << 3;      /* channel 1: 480 cycles */
    ADC_SQR1(ADC1_BASE) = 0u;            /* one conversion per sequence */
    ADC_SQR3(ADC1_BASE) = 1u;            /* ... of channel 1 */
    ADC_CR2(ADC1_BASE) = ADC_CR2_ADON;
    board_delay_us(ADC_STAB_US);
    ADC_CR2(ADC1_BASE) |= ADC_CR2_SWSTART;
    started_ms = wf_hal_millis();
#endif
}

int32_t wf_hal_adc_battery_raw(void)
{
#if !WF_PORT_QEMU
    const uint32_t now = wf_hal_millis();
    if (ADC_SR(ADC1_BASE) & ADC_SR_EOC) {
        last_raw = (int32_t)(ADC_DR(ADC1_BASE) & 0x0FFFu);   /* the read clears EOC */
        ADC_CR2(ADC1_BASE) |= ADC_CR2_SWSTART;
        started_ms = now;
    } else if (now - started_ms > RESTART_MS) {
        ADC_SR(ADC1_BASE) = 0u;   /* clears OVR and a stale STRT */
        ADC_CR2(ADC1_BASE) |= ADC_CR2_SWSTART;
        started_ms = now;
    }
#endif
    return last_raw;
}
