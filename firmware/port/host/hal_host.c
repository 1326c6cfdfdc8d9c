/* The POSIX port of wf/hal.h: a settable clock, byte queues for the UART, recorded PWM
 * compares, I2C routed to a pluggable device model, a settable ADC reading. */
#include <string.h>

#include "wf/hal.h"
#include "wf_host.h"

static struct {
    uint32_t now_ms;
    uint8_t rx[WF_HOST_RX_CAPACITY];
    size_t rx_head, rx_len;
    uint8_t tx[WF_HOST_TX_CAPACITY];
    size_t tx_len, tx_capacity;
    uint32_t compare[WF_SERVO_COUNT];
    uint32_t frame_hz;
    wf_host_i2c_fn i2c;
    void *i2c_context;
    int32_t adc_raw;
} board;

void wf_host_reset(void)
{
    memset(&board, 0, sizeof board);
    board.tx_capacity = WF_HOST_TX_CAPACITY;
    board.adc_raw = 3392;
}

void wf_host_set_millis(uint32_t now_ms) { board.now_ms = now_ms; }

void wf_host_set_i2c_device(wf_host_i2c_fn device, void *context)
{
    board.i2c = device;
    board.i2c_context = context;
}

void wf_host_set_adc_raw(int32_t raw) { board.adc_raw = raw; }

void wf_host_set_tx_capacity(size_t capacity)
{
    board.tx_capacity = capacity < WF_HOST_TX_CAPACITY ? capacity : WF_HOST_TX_CAPACITY;
}

size_t wf_host_feed(const uint8_t *data, size_t len)
{
    size_t n = 0;
    for (; n < len && board.rx_len < WF_HOST_RX_CAPACITY; n++) {
        board.rx[(board.rx_head + board.rx_len++) % WF_HOST_RX_CAPACITY] = data[n];
    }
    return n;
}

size_t wf_host_take_output(uint8_t *out, size_t max)
{
    const size_t n = board.tx_len < max ? board.tx_len : max;
    memcpy(out, board.tx, n);
    memmove(board.tx, board.tx + n, board.tx_len - n);
    board.tx_len -= n;
    return n;
}

uint32_t wf_host_compare(unsigned servo) { return servo < WF_SERVO_COUNT ? board.compare[servo] : 0; }

uint32_t wf_host_pwm_frame_hz(void) { return board.frame_hz; }

/* --- wf/hal.h ------------------------------------------------------------------------- */
uint32_t wf_hal_millis(void) { return board.now_ms; }

size_t wf_hal_uart_read(uint8_t *buf, size_t max)
{
    size_t n = 0;
    for (; n < max && board.rx_len > 0; n++) {
        buf[n] = board.rx[board.rx_head];
        board.rx_head = (board.rx_head + 1) % WF_HOST_RX_CAPACITY;
        board.rx_len--;
    }
    return n;
}

size_t wf_hal_uart_write(const uint8_t *buf, size_t len)
{
    const size_t room = board.tx_capacity - board.tx_len;
    const size_t n = len < room ? len : room;
    memcpy(board.tx + board.tx_len, buf, n);
    board.tx_len += n;
    return n;
}

/* A 1 MHz timer tick, as the stm32f4 port's (prescaled) TIM3. */
uint32_t wf_hal_pwm_ticks_per_us(void) { return 1; }

bool wf_hal_pwm_init(uint32_t frame_hz)
{
    if (frame_hz < 50 || frame_hz > 333) {
        return false;
    }
    board.frame_hz = frame_hz;
    return true;
}

void wf_hal_pwm_set_compare(unsigned servo, uint32_t compare_ticks)
{
    if (servo < WF_SERVO_COUNT) {
        board.compare[servo] = compare_ticks;
    }
}

bool wf_hal_i2c_transfer(uint8_t address7, const uint8_t *tx, size_t tx_len, uint8_t *rx,
                         size_t rx_len)
{
    if (board.i2c == NULL) {
        return false; /* no device on the bus: NACK */
    }
    return board.i2c(board.i2c_context, address7, tx, tx_len, rx, rx_len);
}

int32_t wf_hal_adc_battery_raw(void) { return board.adc_raw; }
