/* SPDX-License-Identifier: Apache-2.0 */
/* The POSIX port of wf/hal.h: a settable clock, byte queues for the UART, recorded PWM
 * compares, I2C routed to a pluggable device model, a settable ADC reading, a model of the
 * stm32f4 port's reset path (reset flags, the fault record that survives a reset, the fault
 * handler's neutral compares) and of its I2C bus recovery, and the calibration's storage: a
 * 16 KB unit with flash's rules (erased 0xFF, programming clears bits only) in RAM or in a
 * file, with faults to inject. */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <string.h>

#include "wf/fault_record.h"
#include "wf/hal.h"
#include "wf/i2c_bus.h"
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

/* What survives a reset that is not a power cycle: the stm32f4 port's .noinit record and the
 * reset flags its RCC_CSR holds for the next boot; and what the port decided at boot. */
static struct {
    wf_fault_record_t record;
    uint32_t reset_flags;
    uint32_t failsafe[WF_SERVO_COUNT];
    wf_health_t health; /* the port's fields only */
    wf_host_i2c_lines_fn lines;
    void *lines_context;
    uint8_t clock_source; /* what the next boot's clock set-up reaches */
} port;

void wf_host_reset(void)
{
    memset(&board, 0, sizeof board);
    board.tx_capacity = WF_HOST_TX_CAPACITY;
    board.adc_raw = 3392;
    memset(&port, 0, sizeof port);
    /* A power cycle: RAM holds nothing valid; power-on sets POR, BOR and PIN (RM0090 7.3.21). */
    port.reset_flags = WF_RESET_FLAG_POR | WF_RESET_FLAG_BOR | WF_RESET_FLAG_PIN;
    port.clock_source = WF_CLOCK_EMULATED;
}

void wf_host_set_clock_source(uint8_t source) { port.clock_source = source; }

/* --- the reset path ------------------------------------------------------------------- */
static void recover_bus(void);

void wf_host_boot(void)
{
    const uint16_t recoveries = port.health.i2c_bus_recoveries;
    memset(&port.health, 0, sizeof port.health);
    port.health.i2c_bus_recoveries = recoveries;
    wf_reset_cause_decide(port.reset_flags, &port.record, &port.health);
    port.reset_flags = 0u; /* RMVF */
    port.health.clock_source = port.clock_source;
    recover_bus(); /* the stm32f4 port's I2C init runs the recovery too */
}

void wf_host_set_failsafe_compares(const uint32_t compare[WF_SERVO_COUNT])
{
    memcpy(port.failsafe, compare, sizeof port.failsafe);
}

void wf_host_fault(uint32_t pc, uint32_t lr, uint32_t cfsr, uint32_t hfsr)
{
    for (unsigned i = 0; i < WF_SERVO_COUNT; i++) {
        board.compare[i] = port.failsafe[i];
    }
    wf_fault_record_save(&port.record, WF_RESET_FAULT, pc, lr, cfsr, hfsr);
    port.reset_flags |= WF_RESET_FLAG_SOFTWARE | WF_RESET_FLAG_PIN;
}

void wf_host_watchdog_reset(void)
{
    port.reset_flags |= WF_RESET_FLAG_IWDG | WF_RESET_FLAG_PIN;
}

void wf_host_set_reset_flags(uint32_t flags) { port.reset_flags = flags; }

void wf_host_set_uart_overruns(uint32_t count) { port.health.uart_rx_overruns = count; }

void wf_hal_health_port(wf_health_t *health)
{
    const wf_health_t *p = &port.health;
    health->reset_cause = p->reset_cause;
    health->clock_source = p->clock_source;
    health->flags = (uint8_t)((health->flags & ~(WF_HEALTH_FAULT_RECORD | WF_HEALTH_BOR_LEVEL3 |
                                                 WF_HEALTH_CSS_ON | WF_HEALTH_STACK_GUARD)) |
                              p->flags);
    health->fault_pc = p->fault_pc;
    health->fault_lr = p->fault_lr;
    health->fault_cfsr = p->fault_cfsr;
    health->fault_hfsr = p->fault_hfsr;
    health->stack_free_min = 0;
    health->stack_size = 0;
    health->uart_rx_overruns = p->uart_rx_overruns;
    health->i2c_bus_recoveries = p->i2c_bus_recoveries;
}

/* --- the I2C lines, for the bus recovery ------------------------------------------------ */
void wf_host_set_i2c_lines(wf_host_i2c_lines_fn lines, void *context)
{
    port.lines = lines;
    port.lines_context = context;
}

static int line(int op) { return port.lines(port.lines_context, op); }
static void host_scl(void *context, bool high)
{
    (void)context;
    (void)line(high ? WF_HOST_SCL_RELEASE : WF_HOST_SCL_LOW);
}
static void host_sda(void *context, bool high)
{
    (void)context;
    (void)line(high ? WF_HOST_SDA_RELEASE : WF_HOST_SDA_LOW);
}
static bool host_scl_high(void *context)
{
    (void)context;
    return line(WF_HOST_READ_SCL) != 0;
}
static bool host_sda_high(void *context)
{
    (void)context;
    return line(WF_HOST_READ_SDA) != 0;
}
static void host_half_bit(void *context)
{
    (void)context;
    (void)line(WF_HOST_HALF_BIT);
}

static bool bus_idle(void)
{
    return port.lines == NULL || (host_scl_high(NULL) && host_sda_high(NULL));
}

/* The stm32f4 port's rule: a recovery counts when it found the bus held. */
static void recover_bus(void)
{
    if (port.lines == NULL) {
        return;
    }
    const bool held = !bus_idle();
    static const wf_i2c_lines_t lines = {NULL, host_scl, host_sda, host_scl_high, host_sda_high,
                                         host_half_bit};
    (void)wf_i2c_bus_recover(&lines);
    if (held) {
        port.health.i2c_bus_recoveries++;
    }
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
    /* A capacity lowered below what the queue holds leaves no room (not a wrapped size). */
    const size_t room = board.tx_len < board.tx_capacity ? board.tx_capacity - board.tx_len : 0;
    if (len > room) {
        return 0; /* all or nothing (wf/hal.h) */
    }
    memcpy(board.tx + board.tx_len, buf, len);
    board.tx_len += len;
    return len;
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
    if (!bus_idle()) {
        recover_bus(); /* the stm32f4 port's BUSY check */
        if (!bus_idle()) {
            return false;
        }
    }
    if (board.i2c == NULL) {
        return false; /* no device on the bus: NACK */
    }
    const bool ok = board.i2c(board.i2c_context, address7, tx, tx_len, rx, rx_len);
    if (!ok) {
        recover_bus();
    }
    return ok;
}

int32_t wf_hal_adc_battery_raw(void) { return board.adc_raw; }

/* --- the calibration's storage ---------------------------------------------------------- */
/* Kept across wf_host_reset (a power cycle keeps flash); wf_host_storage_clear erases it. */
static struct {
    bool ready; /* zero-initialised statics are not erased flash: erased on first use */
    uint8_t bytes[WF_HOST_STORAGE_SIZE];
    char path[4096];
    bool has_path;
    int fault; /* wf_host_storage_fault_t */
    uint32_t erases;
    uint32_t programs;
} storage;

static void storage_ready(void)
{
    if (!storage.ready) {
        memset(storage.bytes, 0xFF, sizeof storage.bytes);
        storage.ready = true;
    }
}

void wf_host_storage_clear(void)
{
    memset(&storage, 0, sizeof storage);
    storage_ready();
}

/* The whole unit to the file, through a temporary one renamed over it: a crash of the host
 * program leaves the old file or the new one, as flash keeps each word old or new. */
static bool storage_flush(void)
{
    if (!storage.has_path) {
        return true;
    }
    char tmp[sizeof storage.path + 8];
    snprintf(tmp, sizeof tmp, "%s.tmp", storage.path);
    FILE *f = fopen(tmp, "wb");
    if (f == NULL) {
        return false;
    }
    const bool written = fwrite(storage.bytes, 1, sizeof storage.bytes, f) == sizeof storage.bytes;
    const bool closed = fclose(f) == 0;
    if (!written || !closed || rename(tmp, storage.path) != 0) {
        remove(tmp);
        return false;
    }
    return true;
}

bool wf_host_storage_use_file(const char *path)
{
    wf_host_storage_clear();
    if (strlen(path) >= sizeof storage.path) {
        return false;
    }
    FILE *f = fopen(path, "rb");
    if (f != NULL) {
        /* A short file is erased past its end; a longer one's tail is not the unit's. */
        const size_t n = fread(storage.bytes, 1, sizeof storage.bytes, f);
        const bool failed = ferror(f) != 0;
        fclose(f);
        if (failed) {
            return false;
        }
        memset(storage.bytes + n, 0xFF, sizeof storage.bytes - n);
    }
    strcpy(storage.path, path);
    storage.has_path = true;
    return true;
}

void wf_host_storage_set_fault(int fault) { storage.fault = fault; }

size_t wf_host_storage_peek(uint32_t offset, uint8_t *out, size_t len)
{
    storage_ready();
    if (offset >= sizeof storage.bytes) {
        return 0;
    }
    const size_t n = len < sizeof storage.bytes - offset ? len : sizeof storage.bytes - offset;
    memcpy(out, storage.bytes + offset, n);
    return n;
}

size_t wf_host_storage_poke(uint32_t offset, const uint8_t *data, size_t len)
{
    storage_ready();
    if (offset >= sizeof storage.bytes) {
        return 0;
    }
    const size_t n = len < sizeof storage.bytes - offset ? len : sizeof storage.bytes - offset;
    memcpy(storage.bytes + offset, data, n);
    return storage_flush() ? n : 0;
}

uint32_t wf_host_storage_erases(void) { return storage.erases; }

uint32_t wf_host_storage_programs(void) { return storage.programs; }

size_t wf_hal_storage_size(void) { return WF_HOST_STORAGE_SIZE; }

bool wf_hal_storage_read(uint32_t offset, uint8_t *buf, size_t len)
{
    storage_ready();
    if (offset > sizeof storage.bytes || len > sizeof storage.bytes - offset) {
        return false;
    }
    memcpy(buf, storage.bytes + offset, len);
    return true;
}

bool wf_hal_storage_erase(void)
{
    storage_ready();
    if (storage.fault == WF_HOST_STORAGE_FAIL_ERASE) {
        return false;
    }
    memset(storage.bytes, 0xFF, sizeof storage.bytes);
    storage.erases++;
    return storage_flush();
}

bool wf_hal_storage_program(uint32_t offset, const uint32_t *words, size_t count)
{
    storage_ready();
    if (offset % 4u != 0 || offset > sizeof storage.bytes ||
        count > (sizeof storage.bytes - offset) / 4u) {
        return false;
    }
    if (storage.fault == WF_HOST_STORAGE_FAIL_PROGRAM) {
        return false;
    }
    /* A power cut: the first half of the words programmed, then nothing. */
    const size_t programmed = storage.fault == WF_HOST_STORAGE_CUT_PROGRAM ? count / 2u : count;
    for (size_t i = 0; i < programmed; i++) {
        uint8_t bytes[4];
        memcpy(bytes, &words[i], sizeof bytes);
        for (size_t b = 0; b < 4; b++) {
            storage.bytes[offset + 4u * i + b] &= bytes[b]; /* flash: clears bits only */
        }
    }
    if (storage.fault == WF_HOST_STORAGE_STUCK_BITS && programmed > 0) {
        storage.bytes[offset] = 0xFFu; /* worn cells: read 1 whatever was programmed */
    }
    storage.programs++;
    const bool flushed = storage_flush();
    return flushed && storage.fault != WF_HOST_STORAGE_CUT_PROGRAM;
}
