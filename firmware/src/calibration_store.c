/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/calibration_store.h"

#include <assert.h>
#include <string.h>

enum { ENTRY_SIZE = 4 + 4 + 1 + 1 + 2, CRC_OFFSET = 32, RECORD_WORDS = WF_CAL_RECORD_SIZE / 4 };

static_assert(WF_CAL_RECORD_SIZE == 4 + 4 + WF_SERVO_COUNT * ENTRY_SIZE + 4,
              "record: magic, generation, two 12-byte servo entries, CRC-32");
static_assert(CRC_OFFSET == WF_CAL_RECORD_SIZE - 4, "the CRC covers everything before it");
static_assert(WF_CAL_RECORD_SIZE % 4 == 0, "a record is whole words: programmed x32");
static_assert(sizeof(float) == 4, "binary32 in the record");

uint32_t wf_crc32(const uint8_t *data, size_t len)
{
    /* Bitwise: no 1 KB table in flash, and it runs over 36 bytes per record read. */
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < len; i++) {
        crc ^= data[i];
        for (unsigned bit = 0; bit < 8; bit++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return crc ^ 0xFFFFFFFFu;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, sizeof v);
    put_u32(p, v);
}

static float get_f32(const uint8_t *p)
{
    const uint32_t v = get_u32(p);
    float f;
    memcpy(&f, &v, sizeof f);
    return f;
}

void wf_cal_record_encode(const wf_cal_record_t *record, uint8_t out[WF_CAL_RECORD_SIZE])
{
    memset(out, 0, WF_CAL_RECORD_SIZE);
    put_u32(out, WF_CAL_MAGIC);
    put_u32(out + 4, record->generation);
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        uint8_t *p = out + 8 + ENTRY_SIZE * i;
        const wf_cal_entry_t *e = &record->servo[i];
        put_f32(p, e->neutral_us);
        put_f32(p + 4, e->us_per_rad);
        p[8] = (uint8_t)e->direction;
        p[9] = e->valid;
    }
    put_u32(out + CRC_OFFSET, wf_crc32(out, CRC_OFFSET));
}

bool wf_cal_record_decode(const uint8_t in[WF_CAL_RECORD_SIZE], wf_cal_record_t *record)
{
    if (get_u32(in) != WF_CAL_MAGIC || get_u32(in + CRC_OFFSET) != wf_crc32(in, CRC_OFFSET)) {
        return false;
    }
    record->generation = get_u32(in + 4);
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        const uint8_t *p = in + 8 + ENTRY_SIZE * i;
        wf_cal_entry_t *e = &record->servo[i];
        e->neutral_us = get_f32(p);
        e->us_per_rad = get_f32(p + 4);
        e->direction = (int8_t)p[8];
        e->valid = p[9];
    }
    return true;
}

/* What a pass over the unit finds: the winner, and the first slot after the last one that
 * is not erased (where the next record goes). */
typedef struct {
    bool found;
    bool readable;
    wf_cal_record_t newest;
    uint32_t next_slot;
    uint32_t slots;
} scan_t;

static bool erased(const uint8_t *bytes)
{
    for (unsigned i = 0; i < WF_CAL_RECORD_SIZE; i++) {
        if (bytes[i] != 0xFFu) {
            return false;
        }
    }
    return true;
}

static void scan(scan_t *s)
{
    memset(s, 0, sizeof *s);
    s->slots = (uint32_t)(wf_hal_storage_size() / WF_CAL_RECORD_SIZE);
    s->readable = true;
    for (uint32_t slot = 0; slot < s->slots; slot++) {
        uint8_t bytes[WF_CAL_RECORD_SIZE];
        if (!wf_hal_storage_read(slot * WF_CAL_RECORD_SIZE, bytes, sizeof bytes)) {
            s->readable = false;
            return;
        }
        if (erased(bytes)) {
            continue;
        }
        s->next_slot = slot + 1u;
        wf_cal_record_t record;
        /* Ties (which no writer makes) go to the later record, as a later write would. */
        if (wf_cal_record_decode(bytes, &record) &&
            (!s->found || record.generation >= s->newest.generation)) {
            s->newest = record;
            s->found = true;
        }
    }
}

bool wf_cal_store_load(wf_cal_record_t *record)
{
    scan_t s;
    scan(&s);
    if (!s.readable || !s.found) {
        memset(record, 0, sizeof *record);
        return false;
    }
    *record = s.newest;
    return true;
}

bool wf_cal_store_append(wf_cal_record_t *record)
{
    scan_t s;
    scan(&s);
    if (!s.readable || s.slots == 0) {
        return false;
    }
    uint32_t slot = s.next_slot;
    if (slot >= s.slots) {
        if (!wf_hal_storage_erase()) {
            return false;
        }
        slot = 0;
    }
    wf_cal_record_t next = *record;
    next.generation = (s.found ? s.newest.generation : 0u) + 1u;
    uint8_t bytes[WF_CAL_RECORD_SIZE];
    uint32_t words[RECORD_WORDS];
    wf_cal_record_encode(&next, bytes);
    memcpy(words, bytes, sizeof words); /* the storage holds the bytes in order: little-endian */
    const uint32_t offset = slot * WF_CAL_RECORD_SIZE;
    uint8_t back[WF_CAL_RECORD_SIZE];
    if (!wf_hal_storage_program(offset, words, RECORD_WORDS) ||
        !wf_hal_storage_read(offset, back, sizeof back) || memcmp(back, bytes, sizeof back) != 0) {
        return false;
    }
    record->generation = next.generation;
    return true;
}
