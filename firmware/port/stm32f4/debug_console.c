/* The QEMU build's debug console on USART2 (see debug_console.h). */
#include "debug_console.h"

#if WF_PORT_QEMU
#include "board.h"
#include "pwm.h"
#include "regs.h"
#include "ring.h"
#include "wf/hal.h"

RING_DEFINE(debug_ring, 2048);
static uint32_t last_config_ms;
static const wf_config_t *config;

void debug_console_init(const wf_config_t *board_config)
{
    config = board_config;
    RCC_APB1ENR |= RCC_APB1ENR_USART2;
    USART_BRR(USART2_BASE) = (BOARD_APB1_HZ + BOARD_UART_BAUD / 2u) / BOARD_UART_BAUD;
    USART_CR1(USART2_BASE) = USART_CR1_UE | USART_CR1_TE;
}

static void put_number(int32_t value)
{
    char digits[11];
    unsigned count = 0u;
    uint32_t magnitude = value < 0 ? 0u - (uint32_t)value : (uint32_t)value;
    if (value < 0) {
        (void)ring_put(&debug_ring, '-');
    }
    do {
        digits[count++] = (char)('0' + magnitude % 10u);
        magnitude /= 10u;
    } while (magnitude != 0u);
    while (count > 0u) {
        (void)ring_put(&debug_ring, (uint8_t)digits[--count]);
    }
}

static uint32_t lines_dropped;   /* Z lines the interrupt found no room for */

static bool in_interrupt(void)
{
    uint32_t ipsr;
    __asm volatile("mrs %0, ipsr" : "=r"(ipsr));
    return (ipsr & 0x1FFu) != 0u;
}

/* The main loop is the ring's consumer: it sends what the ring holds to USART2 (QEMU 7.2's
 * USART has no TXE interrupt and sends each DR write at once). */
static void flush(void)
{
    uint8_t byte;
    while (ring_get(&debug_ring, &byte)) {
        while (!(USART_SR(USART2_BASE) & USART_SR_TXE)) {
        }
        USART_DR(USART2_BASE) = byte;
    }
}

/* Called from the main loop and from the USART1 interrupt: the line is written with
 * interrupts masked, so the ring keeps a single producer at a time. The main loop makes room
 * first (it is the consumer), so none of its lines is lost; an interrupt that finds no room
 * drops its whole line and counts it (the "C" line reports the count): a cut line would be
 * misread. */
void debug_console_line(char tag, const int32_t *values, unsigned count)
{
    const uint32_t needed = 2u + 12u * count;
    if (!in_interrupt()) {
        while (debug_ring.mask + 1u - ring_used(&debug_ring) < needed) {
            flush();
        }
    }
    uint32_t primask = board_irq_save();
    if (debug_ring.mask + 1u - ring_used(&debug_ring) >= needed) {
        (void)ring_put(&debug_ring, (uint8_t)tag);
        for (unsigned i = 0u; i < count; i++) {
            (void)ring_put(&debug_ring, ' ');
            put_number(values[i]);
        }
        (void)ring_put(&debug_ring, '\n');
    } else {
        lines_dropped++;
    }
    board_irq_restore(primask);
}

void debug_console_poll(void)
{
    uint32_t now = wf_hal_millis();
    if (now - last_config_ms >= 1000u) {
        last_config_ms = now;
        const int32_t timer[5] = {(int32_t)wf_hal_pwm_ticks_per_us(),
                                  (int32_t)board_pwm_period(), (int32_t)lines_dropped,
                                  (int32_t)board_uart_rx_overflows(),
                                  (int32_t)board_virtual_ns()};
        debug_console_line('C', timer, 5u);
        for (unsigned i = 0u; i < WF_SERVO_COUNT; i++) {
            const wf_servo_cal_t *cal = &config->servo_cal[i];
            const int32_t servo[5] = {(int32_t)i, (int32_t)(cal->neutral_us * 1000.0f + 0.5f),
                                      (int32_t)(cal->us_per_rad * 1000.0f + 0.5f),
                                      cal->direction,
                                      (int32_t)(config->servo_limit_rad * 1e6f + 0.5f)};
            debug_console_line('K', servo, 5u);
        }
    }
    flush();
}

#endif /* WF_PORT_QEMU */
