/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The servos' calibration in storage (PROTOCOL.md, "Calibration storage"): one 36-byte record
 * per save in an append-only log over one erase unit (wf/hal.h's wf_hal_storage_*).
 *
 *   record: magic u32 "WFCL" | generation u32 | servo 1, servo 2: neutral_us f32,
 *           us_per_rad f32, direction i8, valid u8, 2 B zero | CRC-32 of the first 32 B
 *
 * Records lie at offsets 0, 36, 72, ... in the order they were written; erased space reads
 * 0xFF. The valid record (magic and CRC right) of the highest generation wins; one with a bad
 * magic or CRC (a write cut by a reset or a power loss) is skipped, so such a cut costs that
 * save only. When the next record does not fit, the unit is erased and the record goes to
 * offset 0. No heap, no state of its own: every call reads what it needs from the storage.
 */
#ifndef WF_CALIBRATION_STORE_H
#define WF_CALIBRATION_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wf/hal.h"

#define WF_CAL_RECORD_SIZE 36u
#define WF_CAL_MAGIC 0x4C434657u /* 'W', 'F', 'C', 'L' as little-endian bytes */

/* One servo's stored values; valid 0: nothing stored for it (the build's defaults). */
typedef struct {
    float neutral_us;
    float us_per_rad;
    int8_t direction;
    uint8_t valid;
} wf_cal_entry_t;

typedef struct {
    uint32_t generation; /* one more than the record it follows; 1 for the first */
    wf_cal_entry_t servo[WF_SERVO_COUNT];
} wf_cal_record_t;

/* CRC-32 (IEEE 802.3, reflected, init and xorout 0xFFFFFFFF: zlib.crc32). */
uint32_t wf_crc32(const uint8_t *data, size_t len);

/* The 36 bytes of a record, magic and CRC included. */
void wf_cal_record_encode(const wf_cal_record_t *record, uint8_t out[WF_CAL_RECORD_SIZE]);

/* True when the bytes are a record (magic and CRC right); then fills *record. */
bool wf_cal_record_decode(const uint8_t in[WF_CAL_RECORD_SIZE], wf_cal_record_t *record);

/* The winning record of the unit: true and *record filled when there is one; false (and
 * *record all zero: generation 0, nothing valid) when the unit holds none or cannot be read. */
bool wf_cal_store_load(wf_cal_record_t *record);

/* Appends record with the next generation (the winner's plus one, 1 on an empty unit), which
 * it writes into record->generation; erases the unit first when the record no longer fits.
 * The words are read back and compared. False when the storage has no room for one record or
 * an erase, program, or read-back fails or differs; record->generation is then unchanged. */
bool wf_cal_store_append(wf_cal_record_t *record);

#endif /* WF_CALIBRATION_STORE_H */
