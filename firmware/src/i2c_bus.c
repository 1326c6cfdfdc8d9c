/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/i2c_bus.h"

/* Releases SCL and waits for it to read high (a slave may stretch it); false if it never does. */
static bool release_scl(const wf_i2c_lines_t *l)
{
    l->scl(l->context, true);
    for (unsigned i = 0; i < WF_I2C_STRETCH_HALF_BITS; i++) {
        l->half_bit(l->context);
        if (l->scl_high(l->context)) {
            return true;
        }
    }
    return false;
}

int wf_i2c_bus_recover(const wf_i2c_lines_t *l)
{
    l->sda(l->context, true);
    if (!release_scl(l)) {
        return -1;
    }
    int pulses = 0;
    while (!l->sda_high(l->context) && pulses < WF_I2C_RECOVERY_PULSES) {
        l->scl(l->context, false);
        l->half_bit(l->context);
        if (!release_scl(l)) {
            return -1;
        }
        pulses++;
    }
    /* STOP: SDA low -> high while SCL is high; SCL goes low first so that pulling SDA low is
     * not itself a START. */
    l->scl(l->context, false);
    l->half_bit(l->context);
    l->sda(l->context, false);
    l->half_bit(l->context);
    if (!release_scl(l)) {
        return -1;
    }
    l->sda(l->context, true);
    l->half_bit(l->context);
    return l->sda_high(l->context) ? pulses : -1;
}
