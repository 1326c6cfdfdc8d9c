/* SPDX-License-Identifier: Apache-2.0 */
/*
 * I2C1 master for the MPU6050 (RM0090 27), 400 kHz fast mode, polled with a deadline: PB8 SCL,
 * PB9 SDA (AF4, open drain; the MPU6050 breakout boards carry the pull-ups, the internal ones
 * are on as a fallback). Every wait ends after I2C_TIMEOUT_MS: a missing or stuck device costs
 * the main loop at most that, and the transfer reports failure (the core flags IMU_FAULT).
 *
 * Bus recovery (wf/i2c_bus.h) runs at init, when BUSY stays set past the timeout (a device
 * holding SDA, or the F4's analog-filter BUSY lock-up, errata ES0182 2.4.6), and after every
 * failed transfer: pins to open-drain GPIO, SCL clocked until SDA is released, a STOP, the
 * alternate function back, a software reset of I2C1 and its registers set up again.
 *
 * Reads end as RM0090 27.3.3 describes for a polling master (its "method 2", for drivers that
 * do not run at the highest interrupt priority): N = 1 (ACK cleared before ADDR is cleared,
 * STOP right after, with interrupts masked between the two), N = 2 (POS and ACK cleared before
 * ADDR is cleared, STOP once BTF says both bytes are in), N > 2 (the last three bytes through
 * BTF: ACK cleared with N-2 in DR and N-1 in the shift register, STOP with N-1 and N). The
 * clock stretching of BTF keeps the bus waiting while an interrupt delays the driver.
 *
 * QEMU models no I2C: the QEMU build reports the bus empty at once.
 */
#include "board.h"
#include "gpio.h"
#include "regs.h"
#include "wf/hal.h"
#include "wf/i2c_bus.h"

enum {
    I2C_TIMEOUT_MS = 2,
    I2C_SPEED_HZ = 400000,
    I2C_TRISE_MAX_NS = 300,   /* fast mode (I2C specification, table 10) */
    SCL_PIN = 8,
    SDA_PIN = 9,
};

static uint16_t bus_recoveries;

uint16_t board_i2c_bus_recoveries(void)
{
    return bus_recoveries;
}

#if WF_PORT_QEMU
void board_i2c_init(void) {}

bool wf_hal_i2c_transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                         size_t rx_len)
{
    (void)address7, (void)tx, (void)tx_len, (void)rx, (void)rx_len;
    return false;
}
#else
/* --- the registers ---------------------------------------------------------------------- */
/* Fast mode, duty 2:1 (DUTY 0): SCL = APB1 / (3 CCR): 42 MHz / 105 = 400 kHz exactly (CCR 35);
 * on the HSI's 16 MHz CCR 14 (381 kHz). TRISE = 300 ns in APB1 periods + 1 (RM0090 27.6.9):
 * 13 at 42 MHz. */
static void peripheral_init(void)
{
    const uint32_t apb1 = board_clocks.apb1_hz;
    const uint32_t ccr = (apb1 + 3u * I2C_SPEED_HZ - 1u) / (3u * I2C_SPEED_HZ);
    I2C_CR1(I2C1_BASE) = I2C_CR1_SWRST;
    I2C_CR1(I2C1_BASE) = 0u;
    I2C_CR2(I2C1_BASE) = apb1 / 1000000u;   /* FREQ in MHz */
    I2C_CCR(I2C1_BASE) = I2C_CCR_FS | (ccr < 1u ? 1u : ccr);
    I2C_TRISE(I2C1_BASE) = (apb1 / 1000000u) * I2C_TRISE_MAX_NS / 1000u + 1u;
    I2C_CR1(I2C1_BASE) = I2C_CR1_PE;
}

/* --- bus recovery: the two pins as open-drain outputs ----------------------------------- */
static void pin_level(unsigned pin, bool high)
{
    GPIO_BSRR(GPIOB_BASE) = high ? 1u << pin : 1u << (pin + 16u);
}

static bool pin_high(unsigned pin)
{
    return (GPIO_IDR(GPIOB_BASE) >> pin) & 1u;
}

static void scl(void *context, bool high)
{
    (void)context;
    pin_level(SCL_PIN, high);
}

static void sda(void *context, bool high)
{
    (void)context;
    pin_level(SDA_PIN, high);
}

static bool scl_high(void *context)
{
    (void)context;
    return pin_high(SCL_PIN);
}

static bool sda_high(void *context)
{
    (void)context;
    return pin_high(SDA_PIN);
}

static void half_bit(void *context)
{
    (void)context;
    board_delay_us(5u);   /* 100 kHz: slow enough for any device on the bus */
}

static void pin_output(unsigned pin)
{
    GPIO_MODER(GPIOB_BASE) = (GPIO_MODER(GPIOB_BASE) & ~(3u << (2u * pin))) |
                             (GPIO_MODE_OUTPUT << (2u * pin));
}

/* Counted when it was needed: a line held low, or BUSY stuck past the timeout (the analog
 * filter's lock-up, both lines high). A recovery after a plain NACK (an absent sensor, probed
 * every 100 ms) finds the bus idle and is not counted. */
static void recover(bool busy_stuck)
{
    static const wf_i2c_lines_t lines = {NULL, scl, sda, scl_high, sda_high, half_bit};
    const bool held = busy_stuck || !pin_high(SDA_PIN) || !pin_high(SCL_PIN);
    I2C_CR1(I2C1_BASE) = 0u;   /* PE off: the pins are the GPIO's */
    pin_level(SCL_PIN, true);
    pin_level(SDA_PIN, true);
    pin_output(SCL_PIN);       /* open drain and pull-up stay from gpio_alternate */
    pin_output(SDA_PIN);
    (void)wf_i2c_bus_recover(&lines);
    gpio_alternate(GPIOB_BASE, SCL_PIN, 4u, 1);
    gpio_alternate(GPIOB_BASE, SDA_PIN, 4u, 1);
    peripheral_init();         /* SWRST clears a BUSY flag the analog filter locked */
    if (held && bus_recoveries < UINT16_MAX) {
        bus_recoveries++;
    }
}

void board_i2c_init(void)
{
    RCC_APB1ENR |= RCC_APB1ENR_I2C1;
    gpio_alternate(GPIOB_BASE, SCL_PIN, 4u, 1);
    gpio_alternate(GPIOB_BASE, SDA_PIN, 4u, 1);
    recover(false);   /* a reset in the middle of a read leaves the sensor holding SDA */
}

/* --- transfers -------------------------------------------------------------------------- */
static bool late(uint32_t started)
{
    return wf_hal_millis() - started > I2C_TIMEOUT_MS;
}

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
        if (late(started)) {
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
    return wait_sr1(I2C_SR1_ADDR, started);   /* SR1 read with ADDR set: SR2 next clears it */
}

static bool write_bytes(uint8_t address7, const uint8_t *tx, size_t n, uint32_t started)
{
    if (!start_and_address((uint8_t)(address7 << 1), started)) {
        return false;
    }
    (void)I2C_SR2(I2C1_BASE);
    for (size_t i = 0u; i < n; i++) {
        if (!wait_sr1(I2C_SR1_TXE, started)) {
            return false;
        }
        I2C_DR(I2C1_BASE) = tx[i];
    }
    return wait_sr1(I2C_SR1_BTF, started);
}

static bool read_bytes(uint8_t address7, uint8_t *rx, size_t n, uint32_t started)
{
    I2C_CR1(I2C1_BASE) = (I2C_CR1(I2C1_BASE) | I2C_CR1_ACK) & ~I2C_CR1_POS;
    if (!start_and_address((uint8_t)((address7 << 1) | 1u), started)) {
        return false;
    }
    if (n == 1u) {
        I2C_CR1(I2C1_BASE) &= ~I2C_CR1_ACK;
        const uint32_t primask = board_irq_save();   /* ADDR cleared, then STOP at once */
        (void)I2C_SR2(I2C1_BASE);
        I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;
        board_irq_restore(primask);
        if (!wait_sr1(I2C_SR1_RXNE, started)) {
            return false;
        }
        rx[0] = (uint8_t)I2C_DR(I2C1_BASE);
        return true;
    }
    if (n == 2u) {
        I2C_CR1(I2C1_BASE) = (I2C_CR1(I2C1_BASE) | I2C_CR1_POS) & ~I2C_CR1_ACK;
        (void)I2C_SR2(I2C1_BASE);
        const bool ok = wait_sr1(I2C_SR1_BTF, started);   /* byte 1 in DR, byte 2 shifted */
        if (ok) {
            I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;
            rx[0] = (uint8_t)I2C_DR(I2C1_BASE);
            rx[1] = (uint8_t)I2C_DR(I2C1_BASE);
        }
        I2C_CR1(I2C1_BASE) &= ~I2C_CR1_POS;
        return ok;
    }
    (void)I2C_SR2(I2C1_BASE);
    size_t i = 0u;
    for (; n - i > 3u; i++) {
        if (!wait_sr1(I2C_SR1_RXNE, started)) {
            return false;
        }
        rx[i] = (uint8_t)I2C_DR(I2C1_BASE);
    }
    if (!wait_sr1(I2C_SR1_BTF, started)) {   /* N-2 in DR, N-1 in the shift register */
        return false;
    }
    I2C_CR1(I2C1_BASE) &= ~I2C_CR1_ACK;      /* N will be NACKed */
    rx[i++] = (uint8_t)I2C_DR(I2C1_BASE);
    if (!wait_sr1(I2C_SR1_BTF, started)) {   /* N-1 in DR, N in the shift register */
        return false;
    }
    const uint32_t primask = board_irq_save();
    I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;
    rx[i++] = (uint8_t)I2C_DR(I2C1_BASE);
    board_irq_restore(primask);
    if (!wait_sr1(I2C_SR1_RXNE, started)) {
        return false;
    }
    rx[i] = (uint8_t)I2C_DR(I2C1_BASE);
    return true;
}

static bool bus_idle(uint32_t started)
{
    while (I2C_SR2(I2C1_BASE) & I2C_SR2_BUSY) {
        if (late(started)) {
            return false;
        }
    }
    return true;
}

bool wf_hal_i2c_transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                         size_t rx_len)
{
    uint32_t started = wf_hal_millis();
    if (!bus_idle(started)) {
        recover(true);
        started = wf_hal_millis();
        if (!bus_idle(started)) {
            return false;
        }
    }
    bool ok = true;
    if (tx_len > 0u) {
        ok = write_bytes(address7, tx, tx_len, started);
    }
    if (ok && rx_len > 0u) {
        ok = read_bytes(address7, rx, rx_len, started);   /* a repeated start after a write */
    } else if (ok) {
        I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;
    }
    if (!ok) {
        I2C_CR1(I2C1_BASE) |= I2C_CR1_STOP;
        recover(false);
    }
    return ok;
}
#endif
