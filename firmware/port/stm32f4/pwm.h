/* SPDX-License-Identifier: Apache-2.0 */
/* The servo PWM timer's period in ticks (0 before wf_hal_pwm_init succeeded). */
#ifndef WF_STM32F4_PWM_H
#define WF_STM32F4_PWM_H

#include <stdint.h>

uint32_t board_pwm_period(void);

#endif /* WF_STM32F4_PWM_H */
