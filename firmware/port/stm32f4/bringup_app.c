/*
 * Port bring-up without the core: a fish HEARTBEAT (PROTOCOL.md, version 1, role fish) every
 * 500 ms on USART1, servos at 1500 us. Proves the vector table, clocks, SysTick, the UART
 * rings and the PWM timer in QEMU; built only with WF_PORT_BRINGUP.
 */
#include <stdint.h>

#include "debug_console.h"
#include "wf/hal.h"

static uint16_t crc16_ccitt_false(const uint8_t *data, unsigned len)
{
    uint16_t crc = 0xFFFFu;
    for (unsigned i = 0u; i < len; i++) {
        crc ^= (uint16_t)(data[i] << 8);
        for (int bit = 0; bit < 8; bit++) {
            crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
        }
    }
    return crc;
}

static void send_heartbeat(uint16_t seq, uint32_t uptime_ms)
{
    uint8_t body[11] = {0x01u, (uint8_t)seq, (uint8_t)(seq >> 8), 1u, 1u, (uint8_t)uptime_ms,
                        (uint8_t)(uptime_ms >> 8), (uint8_t)(uptime_ms >> 16),
                        (uint8_t)(uptime_ms >> 24), 0u, 0u};
    uint16_t crc = crc16_ccitt_false(body, 9u);
    body[9] = (uint8_t)crc;
    body[10] = (uint8_t)(crc >> 8);
    uint8_t wire[16];
    unsigned out = 1u, code_at = 1u;
    wire[0] = 0u;
    wire[out++] = 0u;   /* placeholder of the first code byte */
    uint8_t code = 1u;
    for (unsigned i = 0u; i < sizeof body; i++) {
        if (body[i] == 0u) {
            wire[code_at] = code;
            code_at = out++;
            code = 1u;
        } else {
            wire[out++] = body[i];
            code++;
        }
    }
    wire[code_at] = code;
    wire[out++] = 0u;
    (void)wf_hal_uart_write(wire, out);
}

void bringup_app_run(void)
{
    uint16_t seq = 0u;
    uint32_t last = wf_hal_millis();
    (void)wf_hal_pwm_init(50u);
    wf_hal_pwm_set_compare(0u, 1500u);
    wf_hal_pwm_set_compare(1u, 1500u);
    for (;;) {
        uint32_t now = wf_hal_millis();
        if (now - last >= 500u) {
            last = now;
            send_heartbeat(seq++, now);
        }
        uint8_t sink[32];
        (void)wf_hal_uart_read(sink, sizeof sink);
        debug_console_poll();
    }
}
