/* SPDX-License-Identifier: Apache-2.0 */
/* Consistent Overhead Byte Stuffing: removes every 0x00 from a body so 0x00 delimits frames. */
#ifndef WF_COBS_H
#define WF_COBS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The encoded size of len bytes: one code byte per started block of 254, plus one. */
#define WF_COBS_MAX_ENCODED(len) ((len) + (len) / 254u + 1u)

/* Encodes len bytes into out (capacity cap); returns the encoded length, 0 if cap is short. */
size_t wf_cobs_encode(const uint8_t *in, size_t len, uint8_t *out, size_t cap);

/* Decodes len bytes (a run between delimiters) into out (capacity cap >= len suffices).
 * Returns false when the run is not valid COBS: a 0x00 inside it, or a code byte that
 * promises more bytes than the run holds. Empty input decodes to empty output. */
bool wf_cobs_decode(const uint8_t *in, size_t len, uint8_t *out, size_t cap, size_t *out_len);

#endif /* WF_COBS_H */
