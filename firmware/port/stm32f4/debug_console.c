/* SPDX-License-Identifier: Apache-2.0 */
/* The QEMU build's debug console on USART2 (see debug_console.h); linked only into that build. */
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
static uint8_t rx_last;            /* the byte USART1 received before (the interrupt's own) */
static uint32_t compare_seen[2];   /* the compare registers at the last "P" line */

void debug_console_init(const wf_config_t *board_config)
{
    config = board_config;
    RCC_APB1ENR |= RCC_APB1ENR_USART2;
    USART_BRR(USART2_BASE) = (board_clocks.apb1_hz + BOARD_UART_BAUD / 2u) / BOARD_UART_BAUD;
    USART_CR1(USART2_BASE) = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE;
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
static void line(char tag, const int32_t *values, unsigned count)
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

void trace_rx_byte(uint8_t byte)
{
    if (byte == 0u && rx_last != 0u) {   /* a delimiter that ends a frame */
        const int32_t now = (int32_t)wf_hal_millis();
        line('Z', &now, 1u);
    }
    rx_last = byte;
}

void trace_compare(unsigned servo)
{
    const uint32_t now = servo == 0u ? TIM_CCR1(TIM3_BASE) : TIM_CCR2(TIM3_BASE);
    if (now != compare_seen[servo]) {   /* what the timer holds: the tests read it back */
        compare_seen[servo] = now;
        const int32_t event[3] = {(int32_t)wf_hal_millis(), (int32_t)servo, (int32_t)now};
        line('P', event, 3u);
    }
}

/* After each poll, from the main loop (no line lost): what the core did, read from its state. */
static uint32_t accepted_seen;
static uint32_t poll_seen_ms;
static bool poll_seen;
static uint32_t taken_seen_ms[2];   /* the take times of the last "T" lines, by kind */
static bool taken_seen[2];

/* A "T" line when the core's time of the last frame of ``kind`` moved: the poll that took it. */
static void trace_taken(int32_t kind, bool heard, uint32_t taken_ms)
{
    if (heard && (!taken_seen[kind] || taken_ms != taken_seen_ms[kind])) {
        taken_seen[kind] = true;
        taken_seen_ms[kind] = taken_ms;
        const int32_t taken[2] = {kind, (int32_t)taken_ms};
        line('T', taken, 2u);
    }
}

void trace_poll(const wf_app_t *app)
{
    trace_taken(0, app->host_seen, app->last_heartbeat_ms);
    trace_taken(1, app->commands_applied != 0u, app->last_command_ms);
    if (app->gaits_accepted != accepted_seen) {
        accepted_seen = app->gaits_accepted;
        const int32_t gait[3] = {(int32_t)app->now_ms, (int32_t)app->gait_id,
                                 (int32_t)app->gaits_accepted};
        line('G', gait, 3u);
    }
    if (app->gait_mode && poll_seen && app->now_ms - poll_seen_ms > 1u) {
        const int32_t jump[2] = {(int32_t)poll_seen_ms, (int32_t)app->now_ms};
        line('J', jump, 2u);
    }
    poll_seen_ms = app->now_ms;
    poll_seen = true;
}

/* The fault path: interrupts are masked and the main loop will not run again; everything
 * queued goes out first, then the fault's own line, synchronously. */
void trace_fault(uint8_t cause, uint32_t pc)
{
    const int32_t fault[4] = {cause, (int32_t)pc, (int32_t)TIM_CCR1(TIM3_BASE),
                              (int32_t)TIM_CCR2(TIM3_BASE)};
    flush();
    if (debug_ring.mask + 1u - ring_used(&debug_ring) >= 2u + 12u * 4u) {
        (void)ring_put(&debug_ring, 'F');
        for (unsigned i = 0u; i < 4u; i++) {
            (void)ring_put(&debug_ring, ' ');
            put_number(fault[i]);
        }
        (void)ring_put(&debug_ring, '\n');
    }
    flush();
}

/* --- failing on purpose ------------------------------------------------------------------ */
/* Each level keeps 64 bytes and uses them after the call, so no level is a tail call. */
__attribute__((noinline)) static uint32_t dive(uint32_t depth)
{
    volatile uint8_t pad[64];
    if (depth > 1000000u) {   /* never reached: 64 MB of stack */
        return 0u;
    }
    pad[depth % sizeof pad] = (uint8_t)depth;
    return dive(depth + 1u) + pad[(depth + 1u) % sizeof pad];
}

static void command(uint8_t byte)
{
    switch (byte) {
    case 'H':
        /* UsageFault is not enabled: the undefined instruction escalates to a HardFault. */
        __asm volatile("udf #0");
        break;
    case 'W':
        for (;;) {   /* the poll loop never comes back: only the watchdog ends this */
        }
    case 'S':
        (void)dive(0u);
        break;
    default:
        break;
    }
}

void debug_console_poll(void)
{
    while (USART_SR(USART2_BASE) & USART_SR_RXNE) {
        command((uint8_t)USART_DR(USART2_BASE));
    }
    uint32_t now = wf_hal_millis();
    if (now - last_config_ms >= 1000u) {
        last_config_ms = now;
        const int32_t timer[5] = {(int32_t)wf_hal_pwm_ticks_per_us(),
                                  (int32_t)board_pwm_period(), (int32_t)lines_dropped,
                                  (int32_t)board_uart_rx_overflows(),
                                  (int32_t)board_virtual_ns()};
        line('C', timer, 5u);
        for (unsigned i = 0u; i < WF_SERVO_COUNT; i++) {
            const wf_servo_cal_t *cal = &config->servo_cal[i];
            const int32_t servo[5] = {(int32_t)i, (int32_t)(cal->neutral_us * 1000.0f + 0.5f),
                                      (int32_t)(cal->us_per_rad * 1000.0f + 0.5f),
                                      cal->direction,
                                      (int32_t)(config->servo_limit_rad * 1e6f + 0.5f)};
            line('K', servo, 5u);
        }
        wf_health_t h = {0};
        wf_hal_health_port(&h);
        const int32_t health[9] = {h.reset_cause, (int32_t)h.fault_pc, (int32_t)h.fault_lr,
                                   (int32_t)h.fault_cfsr, (int32_t)h.fault_hfsr, h.flags,
                                   h.stack_free_min, h.stack_size, h.clock_source};
        line('R', health, 9u);
    }
    flush();
}

#endif /* WF_PORT_QEMU */
