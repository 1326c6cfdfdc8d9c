/* SPDX-License-Identifier: Apache-2.0 */
/* CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, no reflection, xorout 0 (PROTOCOL.md). */
#ifndef WF_CRC16_H
#define WF_CRC16_H

#include <stddef.h>
#include <stdint.h>

#define WF_CRC16_INIT 0xFFFFu

/* Returns the CRC of len bytes continued from crc (start with WF_CRC16_INIT). */
uint16_t wf_crc16_update(uint16_t crc, const uint8_t *data, size_t len);

static inline uint16_t wf_crc16(const uint8_t *data, size_t len)
{
    return wf_crc16_update(WF_CRC16_INIT, data, len);
}

#endif /* WF_CRC16_H */
