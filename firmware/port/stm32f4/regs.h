/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The STM32F405/407 registers this port uses, from RM0090 (Rev 19) and the Cortex-M4 generic
 * user guide: nothing else. Addresses are the memory map of RM0090 section 2.3.
 */
#ifndef WF_STM32F4_REGS_H
#define WF_STM32F4_REGS_H

#include <stdint.h>

#define WF_REG(address) (*(volatile uint32_t *)(address))

/* --- Cortex-M4 core --------------------------------------------------------------------- */
#define SCB_CPACR WF_REG(0xE000ED88u)   /* CP10/CP11 full access: bits 23:20 */
#define SYST_CSR WF_REG(0xE000E010u)
#define SYST_RVR WF_REG(0xE000E014u)
#define SYST_CVR WF_REG(0xE000E018u)
#define SYST_CSR_ENABLE (1u << 0)
#define SYST_CSR_TICKINT (1u << 1)
#define SYST_CSR_CLKSOURCE (1u << 2)  /* processor clock */
#define NVIC_ISER(n) WF_REG(0xE000E100u + 4u * (n))
#define SCB_AIRCR WF_REG(0xE000ED0Cu)
#define SCB_AIRCR_SYSRESETREQ (0x05FAu << 16 | 1u << 2)   /* VECTKEY and the request */
#define SCB_SHCSR WF_REG(0xE000ED24u)
#define SCB_SHCSR_MEMFAULTENA (1u << 16)
#define SCB_CFSR WF_REG(0xE000ED28u)   /* MMFSR | BFSR << 8 | UFSR << 16 */
#define SCB_HFSR WF_REG(0xE000ED2Cu)
#define MPU_TYPE WF_REG(0xE000ED90u)
#define MPU_CTRL WF_REG(0xE000ED94u)
#define MPU_RNR WF_REG(0xE000ED98u)
#define MPU_RBAR WF_REG(0xE000ED9Cu)
#define MPU_RASR WF_REG(0xE000EDA0u)
#define MPU_CTRL_ENABLE (1u << 0)
#define MPU_CTRL_PRIVDEFENA (1u << 2)   /* the default map wherever no region says otherwise */
#define MPU_RASR_ENABLE (1u << 0)
#define MPU_RASR_XN (1u << 28)
#define MPU_RASR_SIZE_32B (4u << 1)     /* 2^(SIZE + 1) bytes */

/* --- RCC (RM0090 7.3) ------------------------------------------------------------------- */
#define RCC_BASE 0x40023800u
#define RCC_CR WF_REG(RCC_BASE + 0x00u)
#define RCC_PLLCFGR WF_REG(RCC_BASE + 0x04u)
#define RCC_CFGR WF_REG(RCC_BASE + 0x08u)
#define RCC_AHB1ENR WF_REG(RCC_BASE + 0x30u)
#define RCC_APB1ENR WF_REG(RCC_BASE + 0x40u)
#define RCC_APB2ENR WF_REG(RCC_BASE + 0x44u)
#define RCC_CIR WF_REG(RCC_BASE + 0x0Cu)
#define RCC_CSR WF_REG(RCC_BASE + 0x74u)
#define RCC_CR_HSION (1u << 0)
#define RCC_CR_HSIRDY (1u << 1)
#define RCC_CR_CSSON (1u << 19)
#define RCC_CIR_CSSF (1u << 7)
#define RCC_CIR_CSSC (1u << 23)
#define RCC_CSR_RMVF (1u << 24)
#define RCC_CSR_FLAGS (0x7Fu << 25)   /* BORRSTF .. LPWRRSTF: wf/fault_record.h's positions */
#define RCC_PLLCFGR_SRC_HSE (1u << 22)
#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)
#define RCC_CFGR_SW_MASK 3u
#define RCC_CFGR_SW_PLL 2u
#define RCC_CFGR_SWS_HSI (0u << 2)
#define RCC_CFGR_SWS_MASK (3u << 2)
#define RCC_CFGR_SWS_PLL (2u << 2)
#define RCC_CFGR_HPRE_DIV1 (0u << 4)
#define RCC_CFGR_PPRE1_DIV4 (5u << 10)
#define RCC_CFGR_PPRE2_DIV2 (4u << 13)
#define RCC_AHB1ENR_GPIOA (1u << 0)
#define RCC_AHB1ENR_GPIOB (1u << 1)
#define RCC_AHB1ENR_GPIOC (1u << 2)
#define RCC_APB1ENR_TIM2 (1u << 0)
#define RCC_APB1ENR_TIM3 (1u << 1)
#define RCC_APB1ENR_USART2 (1u << 17)
#define RCC_APB1ENR_I2C1 (1u << 21)
#define RCC_APB2ENR_USART1 (1u << 4)
#define RCC_APB2ENR_ADC1 (1u << 8)

/* --- Flash interface (RM0090 3.9) -------------------------------------------------------- */
#define FLASH_ACR WF_REG(0x40023C00u)
#define FLASH_KEYR WF_REG(0x40023C04u)
#define FLASH_OPTKEYR WF_REG(0x40023C08u)
#define FLASH_SR WF_REG(0x40023C0Cu)
#define FLASH_CR WF_REG(0x40023C10u)
#define FLASH_OPTCR WF_REG(0x40023C14u)
#define FLASH_KEY1 0x45670123u
#define FLASH_KEY2 0xCDEF89ABu
#define FLASH_OPTKEY1 0x08192A3Bu
#define FLASH_OPTKEY2 0x4C5D6E7Fu
#define FLASH_SR_EOP (1u << 0)
#define FLASH_SR_BSY (1u << 16)
#define FLASH_SR_ERRORS 0xF2u          /* OPERR, WRPERR, PGAERR, PGPERR, PGSERR */
#define FLASH_CR_PG (1u << 0)
#define FLASH_CR_SER (1u << 1)
#define FLASH_CR_SNB(n) ((uint32_t)(n) << 3)
#define FLASH_CR_SNB_MASK (0x1Fu << 3)
#define FLASH_CR_PSIZE_X32 (2u << 8)   /* 32-bit parallelism: VDD 2.7-3.6 V */
#define FLASH_CR_PSIZE_MASK (3u << 8)
#define FLASH_CR_STRT (1u << 16)
#define FLASH_CR_LOCK (1u << 31)
#define FLASH_ACR_ICRST (1u << 11)
#define FLASH_ACR_DCRST (1u << 12)
#define FLASH_OPTCR_OPTLOCK (1u << 0)
#define FLASH_OPTCR_OPTSTRT (1u << 1)
#define FLASH_OPTCR_BOR_LEV_MASK (3u << 2)
#define FLASH_OPTCR_BOR_LEV3 (0u << 2)  /* 2.70-3.60 V (RM0090 3.7.1) */
#define FLASH_ACR_LATENCY_5WS 5u
#define FLASH_ACR_PRFTEN (1u << 8)
#define FLASH_ACR_ICEN (1u << 9)
#define FLASH_ACR_DCEN (1u << 10)

/* --- GPIO (RM0090 8.4) ------------------------------------------------------------------ */
#define GPIOA_BASE 0x40020000u
#define GPIOB_BASE 0x40020400u
#define GPIOC_BASE 0x40020800u
#define GPIO_MODER(base) WF_REG((base) + 0x00u)
#define GPIO_OTYPER(base) WF_REG((base) + 0x04u)
#define GPIO_OSPEEDR(base) WF_REG((base) + 0x08u)
#define GPIO_PUPDR(base) WF_REG((base) + 0x0Cu)
#define GPIO_IDR(base) WF_REG((base) + 0x10u)
#define GPIO_BSRR(base) WF_REG((base) + 0x18u)   /* bits 0-15 set, 16-31 reset */
#define GPIO_AFRL(base) WF_REG((base) + 0x20u)
#define GPIO_AFRH(base) WF_REG((base) + 0x24u)
#define GPIO_MODE_ANALOG 3u
#define GPIO_MODE_OUTPUT 1u
#define GPIO_MODE_AF 2u

/* --- USART (RM0090 30.6) ---------------------------------------------------------------- */
#define USART1_BASE 0x40011000u
#define USART2_BASE 0x40004400u
#define USART_SR(base) WF_REG((base) + 0x00u)
#define USART_DR(base) WF_REG((base) + 0x04u)
#define USART_BRR(base) WF_REG((base) + 0x08u)
#define USART_CR1(base) WF_REG((base) + 0x0Cu)
#define USART_CR2(base) WF_REG((base) + 0x10u)
#define USART_CR3(base) WF_REG((base) + 0x14u)
#define USART_SR_ORE (1u << 3)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TXE (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_TXEIE (1u << 7)
#define USART_CR1_UE (1u << 13)
#define USART1_IRQN 37u
#define USART2_IRQN 38u

/* --- General-purpose timer TIM3 (RM0090 18.4) ------------------------------------------- */
#define TIM2_BASE 0x40000000u
#define TIM3_BASE 0x40000400u
#define TIM_CR1(base) WF_REG((base) + 0x00u)
#define TIM_SR(base) WF_REG((base) + 0x10u)
#define TIM_EGR(base) WF_REG((base) + 0x14u)
#define TIM_CCMR1(base) WF_REG((base) + 0x18u)
#define TIM_CCER(base) WF_REG((base) + 0x20u)
#define TIM_PSC(base) WF_REG((base) + 0x28u)
#define TIM_ARR(base) WF_REG((base) + 0x2Cu)
#define TIM_CCR1(base) WF_REG((base) + 0x34u)
#define TIM_CCR2(base) WF_REG((base) + 0x38u)
#define TIM_CNT(base) WF_REG((base) + 0x24u)
#define TIM_SR_UIF (1u << 0)
#define TIM_CR1_CEN (1u << 0)
#define TIM_CR1_ARPE (1u << 7)
#define TIM_EGR_UG (1u << 0)
#define TIM_CCMR1_OC1PE (1u << 3)
#define TIM_CCMR1_OC1M_PWM1 (6u << 4)
#define TIM_CCMR1_OC2PE (1u << 11)
#define TIM_CCMR1_OC2M_PWM1 (6u << 12)
#define TIM_CCER_CC1E (1u << 0)
#define TIM_CCER_CC2E (1u << 4)

/* --- I2C1 (RM0090 27.6) ----------------------------------------------------------------- */
#define I2C1_BASE 0x40005400u
#define I2C_CR1(base) WF_REG((base) + 0x00u)
#define I2C_CR2(base) WF_REG((base) + 0x04u)
#define I2C_DR(base) WF_REG((base) + 0x10u)
#define I2C_SR1(base) WF_REG((base) + 0x14u)
#define I2C_SR2(base) WF_REG((base) + 0x18u)
#define I2C_CCR(base) WF_REG((base) + 0x1Cu)
#define I2C_TRISE(base) WF_REG((base) + 0x20u)
#define I2C_CR1_PE (1u << 0)
#define I2C_CR1_START (1u << 8)
#define I2C_CR1_STOP (1u << 9)
#define I2C_CR1_ACK (1u << 10)
#define I2C_CR1_POS (1u << 11)
#define I2C_CR1_SWRST (1u << 15)
#define I2C_CCR_FS (1u << 15)
#define I2C_SR1_SB (1u << 0)
#define I2C_SR1_ADDR (1u << 1)
#define I2C_SR1_BTF (1u << 2)
#define I2C_SR1_RXNE (1u << 6)
#define I2C_SR1_TXE (1u << 7)
#define I2C_SR1_BERR (1u << 8)
#define I2C_SR1_ARLO (1u << 9)
#define I2C_SR1_AF (1u << 10)
#define I2C_SR2_BUSY (1u << 1)

/* --- ADC1 (RM0090 13.13) ---------------------------------------------------------------- */
#define ADC1_BASE 0x40012000u
#define ADC_SR(base) WF_REG((base) + 0x00u)
#define ADC_CR2(base) WF_REG((base) + 0x08u)
#define ADC_SMPR2(base) WF_REG((base) + 0x10u)
#define ADC_SQR1(base) WF_REG((base) + 0x2Cu)
#define ADC_SQR3(base) WF_REG((base) + 0x34u)
#define ADC_DR(base) WF_REG((base) + 0x4Cu)
#define ADC_CCR WF_REG(0x40012304u)
#define ADC_SR_EOC (1u << 1)
#define ADC_SR_OVR (1u << 5)
#define ADC_CR2_ADON (1u << 0)
#define ADC_CR2_SWSTART (1u << 30)
#define ADC_CCR_ADCPRE_DIV4 (1u << 16)

/* --- Independent watchdog (RM0090 21.4) ------------------------------------------------ */
#define IWDG_KR WF_REG(0x40003000u)
#define IWDG_PR WF_REG(0x40003004u)
#define IWDG_RLR WF_REG(0x40003008u)
#define IWDG_SR WF_REG(0x4000300Cu)
#define IWDG_KEY_START 0xCCCCu
#define IWDG_KEY_UNLOCK 0x5555u
#define IWDG_KEY_RELOAD 0xAAAAu

#endif /* WF_STM32F4_REGS_H */
