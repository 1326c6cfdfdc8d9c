/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/cobs.h"

size_t wf_cobs_encode(const uint8_t *in, size_t len, uint8_t *out, size_t cap)
{
    if (cap < WF_COBS_MAX_ENCODED(len)) {
        return 0;
    }
    size_t code_at = 0;
    size_t o = 1;
    uint8_t code = 1;
    for (size_t i = 0; i < len; i++) {
        if (in[i] == 0) {
            out[code_at] = code;
            code_at = o++;
            code = 1;
            continue;
        }
        out[o++] = in[i];
        code++;
        if (code == 0xFF) {
            /* A full block of 254 non-zero bytes: its code says "no zero follows". A block
             * may only be opened when more input follows, as the reference encoder does. */
            out[code_at] = code;
            code = 1;
            if (i + 1 < len) {
                code_at = o++;
            } else {
                return o;
            }
        }
    }
    out[code_at] = code;
    return o;
}

bool wf_cobs_decode(const uint8_t *in, size_t len, uint8_t *out, size_t cap, size_t *out_len)
{
    size_t i = 0;
    size_t o = 0;
    while (i < len) {
        const uint8_t code = in[i++];
        if (code == 0) {
            return false;
        }
        const size_t end = i + code - 1u;
        if (end > len) {
            return false; /* the code promises more bytes than the run holds */
        }
        for (; i < end; i++) {
            if (in[i] == 0 || o >= cap) {
                return false;
            }
            out[o++] = in[i];
        }
        if (i < len && code < 0xFFu) {
            if (o >= cap) {
                return false;
            }
            out[o++] = 0;
        }
    }
    *out_len = o;
    return true;
}
