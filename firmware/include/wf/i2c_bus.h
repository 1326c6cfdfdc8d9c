/* SPDX-License-Identifier: Apache-2.0 */
/*
 * I2C bus recovery, portable: the ports drive the two lines as open-drain GPIO through these
 * callbacks (the stm32f4 port its PB8/PB9 registers, the host port the register-level sensor
 * model of test/support/mpu6050_model.py), so the sequence a board runs is the one the host
 * tests run.
 *
 * Why it is needed: a reset (of the board, or of the I2C peripheral) in the middle of a read
 * leaves the sensor half-way through a byte, holding SDA low for its next 0 bit while it waits
 * for clocks that never come; the master then sees a busy bus for ever. Up to nine SCL pulses
 * let it shift out the rest of its byte and take the master's released SDA as a NACK, after
 * which it lets go; a STOP then returns both sides to idle (NXP UM10204 3.1.16 "Bus clear").
 */
#ifndef WF_I2C_BUS_H
#define WF_I2C_BUS_H

#include <stdbool.h>

typedef struct {
    void *context;
    void (*scl)(void *context, bool high);  /* drive SCL low, or release it (high: pull-up) */
    void (*sda)(void *context, bool high);  /* drive SDA low, or release it */
    bool (*scl_high)(void *context);        /* the line's level (a stretching slave holds it) */
    bool (*sda_high)(void *context);
    void (*half_bit)(void *context);        /* wait half an SCL period: 5 us (100 kHz) */
} wf_i2c_lines_t;

/* The most SCL pulses a device holding SDA can need: 8 bits of its byte and the ACK slot. */
enum { WF_I2C_RECOVERY_PULSES = 9, WF_I2C_STRETCH_HALF_BITS = 200 };

/* Releases both lines, clocks SCL (waiting out clock stretching for at most
 * WF_I2C_STRETCH_HALF_BITS half periods) until SDA reads high or WF_I2C_RECOVERY_PULSES pulses
 * were given, then sends a STOP. Returns the pulses it took (0: SDA was free), or -1 when SDA
 * or SCL stays low (a short, or a device that holds the bus for ever: the caller reports the
 * IMU absent and tries again later). The port then restores the peripheral's alternate function
 * and resets it. */
int wf_i2c_bus_recover(const wf_i2c_lines_t *lines);

#endif /* WF_I2C_BUS_H */
