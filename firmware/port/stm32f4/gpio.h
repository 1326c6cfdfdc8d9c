/* SPDX-License-Identifier: Apache-2.0 */
/* Pin set-up of the real board (QEMU models no GPIO: the writes are harmless there). */
#ifndef WF_STM32F4_GPIO_H
#define WF_STM32F4_GPIO_H

#include <stdint.h>

#include "regs.h"

/* Puts pin `pin` of port `base` in alternate function `af` (push-pull, or open drain for
 * I2C, with the pull-up), at high speed. */
static inline void gpio_alternate(uint32_t base, unsigned pin, unsigned af, int open_drain)
{
    GPIO_MODER(base) = (GPIO_MODER(base) & ~(3u << (2u * pin))) | (GPIO_MODE_AF << (2u * pin));
    GPIO_OSPEEDR(base) |= 2u << (2u * pin);
    if (open_drain) {
        GPIO_OTYPER(base) |= 1u << pin;
        GPIO_PUPDR(base) = (GPIO_PUPDR(base) & ~(3u << (2u * pin))) | (1u << (2u * pin));
    }
    if (pin < 8u) {
        GPIO_AFRL(base) = (GPIO_AFRL(base) & ~(0xFu << (4u * pin))) | (af << (4u * pin));
    } else {
        unsigned high = pin - 8u;
        GPIO_AFRH(base) = (GPIO_AFRH(base) & ~(0xFu << (4u * high))) | (af << (4u * high));
    }
}

static inline void gpio_analog(uint32_t base, unsigned pin)
{
    GPIO_MODER(base) |= GPIO_MODE_ANALOG << (2u * pin);
}

#endif /* WF_STM32F4_GPIO_H */
