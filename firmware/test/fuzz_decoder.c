/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The differential fuzz driver (built with AddressSanitizer and UBSan, every report fatal).
 *
 *   fuzz_decoder CORPUS OUT
 *
 * CORPUS: records, each a u32 LE length and that many bytes. Each record goes to one decoder
 * that lives for the whole corpus, framed as 0x00 record 0x00 (so every record's runs end),
 * and to a board (the whole application, the record at time = its index) so the sanitizers
 * see the link logic too. OUT: per record a u16 LE count of the frames the decoder accepted, then
 * each one's canonical body (u8 length, bytes); at the end the decoder's 12 counters (u32 LE).
 * test/firmware/test_fw_fuzz.py writes the same from the Python decoder and compares.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wf_host.h"

static void put_u32(FILE *out, uint32_t v)
{
    const uint8_t b[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    fwrite(b, 1, 4, out);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: fuzz_decoder CORPUS OUT\n");
        return 2;
    }
    FILE *in = fopen(argv[1], "rb");
    FILE *out = fopen(argv[2], "wb");
    if (in == NULL || out == NULL) {
        perror("fuzz_decoder");
        return 2;
    }
    static wf_decoder_t decoder;
    wf_decoder_init(&decoder);
    wf_host_reset();
    wf_host_board_init(NULL);
    static uint8_t record[1 << 16];
    static uint8_t sink[WF_HOST_TX_CAPACITY];
    /* Each accepted frame takes >= 7 record bytes and writes <= WF_MAX_BODY + 1 (67): room for
     * any record. */
    static uint8_t bodies[(sizeof record / 7 + 2) * (WF_MAX_BODY + 1)];
    uint32_t index = 0;
    uint8_t header[4];
    while (fread(header, 1, 4, in) == 4) {
        const uint32_t len = (uint32_t)header[0] | ((uint32_t)header[1] << 8) |
                             ((uint32_t)header[2] << 16) | ((uint32_t)header[3] << 24);
        if (len > sizeof record || fread(record, 1, len, in) != len) {
            fprintf(stderr, "fuzz_decoder: truncated corpus at record %u\n", index);
            return 2;
        }
        size_t used = 0;
        unsigned accepted = 0;
        for (uint32_t i = 0; i <= len + 1; i++) {
            const uint8_t byte = (i == 0 || i == len + 1) ? 0 : record[i - 1];
            wf_msg_t msg;
            if (wf_decoder_push(&decoder, byte, &msg) == WF_RX_FRAME) {
                const size_t n = wf_encode_body(&msg, bodies + used + 1);
                bodies[used] = (uint8_t)n;
                used += n + 1;
                accepted++;
            }
        }
        fputc((int)(accepted & 0xFFu), out);
        fputc((int)(accepted >> 8), out);
        fwrite(bodies, 1, used, out);
        wf_host_board_step(index, record, len, sink, sizeof sink);
        index++;
    }
    const wf_decoder_stats_t *s = &decoder.stats;
    const uint32_t counters[12] = {s->bytes_in,      s->frames_ok,       s->cobs_errors,
                                   s->short_frames,  s->crc_errors,      s->unknown_type,
                                   s->length_errors, s->invalid_payload, s->overflows,
                                   s->resyncs,       s->seq_gaps,        s->seq_resets};
    for (int i = 0; i < 12; i++) {
        put_u32(out, counters[i]);
    }
    fclose(out);
    fclose(in);
    return 0;
}
