/*
 * I2C1 master for the MPU6050 (RM0090 27), 100 kHz standard mode, polled with a deadline:
 * PB8 SCL, PB9 SDA (AF4, open drain; the MPU6050 breakout boards carry the pull-ups, the
 * internal ones are on as a fallback). Every wait ends after I2C_TIMEOUT_MS: a missing or
 * stuck device costs the main loop at most that, and the transfer reports failure (the core
 * flags IMU_FAULT). QEMU models no I2C: the QEMU build reports the bus empty at once.
 */
#include "board.h"
#include "gpio.h"
#include "regs.h"
#include "wf/hal.h"

enum { I2C_TIMEOUT_MS = 2, I2C_SPEED_HZ = 100000 };

void board_i2c_init(void)
{
#if !WF_PORT_QEMU
    RCC_APB1ENR |= RCC_APB1ENR_I2C1;
    gpio_alternate(GPIOB_BASE, 8u, 4u, 1);
    gpio_alternate(GPIOB_BASE, 9u, 4u, 1);
    I2C_CR1(I2C1_BASE) = I2C_CR1_SWRST;
    I2C_CR1(I2C1_BASE) = 0u;
    I2C_CR2(I2C1_BASE) = BOARD_APB1_HZ / 1000000u;                  /* FREQ in MHz */
    I2C_CCR(I2C1_BASE) = BOARD_APB1_HZ / (2u * I2C_SPEED_HZ);       /* Thigh = Tlow */
    I2C_TRISE(I2C1_BASE) = BOARD_APB1_HZ / 1000000u + 1u;           /* 1000 ns max rise */
    I2C_CR1(I2C1_BASE) = I2C_CR1_PE;
#endif
}

#if WF_PORT_QEMU
bool wf_hal_i2c_transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                         size_t rx_len)
{
    (void)address7, (void)tx, (void)tx_len, (void)rx, (void)rx_len;
    return false;
}
#else
/* Waits until SR1 has any of `bits`; false on a deadline, a NACK or a bus error. */
static bool wait_sr1(uint32_t bits, uint32_t started)
{
    for (;;) {
        uint32_t sr1 = I2C_SR1(I2C1_BASE);
        if (sr1 & (I2C_SR1_AF | I2C_SR1_BERR | I2C_SR1_ARLO)) {
            I2C_SR1(I2C1_BASE) = 0u;   /* clear the error flags */
            return false;
        }
        if (sr1 & bits) {
            return true;
        }
        if (wf_hal_millis() - started > I2C_TIMEOUT_MS) {
            return false;
        }
    }
}

static bool start_and_address(uint8_t address_byte, uint32_t started)
{
    I2C_CR1(I2C1_BASE) |= I2C_CR1_START;
    if (!wait_sr1(I2C_SR1_SB, started)) {
        return false;
    }
    I2C_DR(I2C1_BASE) = address_byte;
    return wait_sr1(I2C_SR1_ADDR, started);
}

static bool transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                     size_t rx_len, uint32_t started)
{
    while (I2C_SR2(I2C1_BASE) & I2C_SR2_BUSY) {
        if (wf_hal_millis() - started > I2C_TIMEOUT_MS) {
            return false;
        }
    }
    if (tx_len > 0u) {
        if (!start_and_address((uint8_t)(address7 << 1), started)) {
            return false;
        }
        (void)I2C_SR2(I2C1_BASE);   /* SR1 then SR2 read: ADDR cleared */
        for (size_t i = 0u; i < tx_len; i++) {
            if (!wait_sr1(I2C_SR1_TXE, started)) {
                return false;
            }
            I2C_DR(I2C1_BASE) = tx[i];
        }
        if (!wait_sr1(I2C_SR1_BTF, started)) {
            return false;
        }
    }
    if (rx_len == 0u) {
        return true;
    }
    I2C_CR1(I2C1_BASE) |= I2C_CR1_ACK;
    if (!start_and_address((uint8_t)((address7 << 1) | 1u), started)) {   /* repeated start */
        return false;
    }
    if (rx_len == 1u) {
        I2C_CR1(I2C1_BASE) &= ~I2C_CR1_ACK;   /* NACK the only byte: before ADDR is cleared */
    }
    (void)I2C_SR2(I2C1_BASE);
    for (size_t i = 0u; i < rx_len; i++) {
        if (i + 1u == rx_len) {
            I2C_CR1(I2C1_BASE) &= ~I2C_CR1_ACK;   /* the last byte is NACKed, then STOP */
            I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;
        }
        if (!wait_sr1(I2C_SR1_RXNE, started)) {
            return false;
        }
        rx[i] = (uint8_t)I2C_DR(I2C1_BASE);
    }
    return true;
}

bool wf_hal_i2c_transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                         size_t rx_len)
{
    bool ok = transfer(address7, tx, tx_len, rx, rx_len, wf_hal_millis());
    if (!ok || rx_len == 0u) {
        I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;   /* release the bus after a write or a failure */
    }
    return ok;
}
#endif
