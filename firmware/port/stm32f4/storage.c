/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The calibration's storage (wf/hal.h's wf_hal_storage_*): one erase unit for the core's log
 * (wf/calibration_store.h).
 *
 * Hardware: flash sector 2, 0x08008000, 16 KB (RM0090 table 5), which the image never
 * reaches (stm32f4.ld caps it at sectors 0 and 1). RM0090 3.6: unlock (KEYR 0x45670123,
 * 0xCDEF89AB), 32-bit parallelism (PSIZE x32, allowed from 2.7 V: the brown-out reset sits at
 * level 3, 2.7 V), sector erase (SER, SNB 2, STRT) or word programming (PG), each wait on BSY
 * bounded, the error flags checked and cleared, locked again, the data cache reset (it may
 * hold the sector's old words), and every programmed word read back. Any failure: false.
 *
 * While the flash erases or programs, a fetch from it stalls the bus: the CPU, interrupts
 * included, waits. A word takes at most 100 us; a sector erase 0.25 s typical, 0.5 s at most
 * (datasheet, x32), longer than the watchdog's 150 ms, so the erase runs with the watchdog's
 * period stretched (board_watchdog_slow). Meanwhile the UART's received bytes overrun
 * (counted) and SysTick's ticks are lost, so the board's clock falls behind by the erase's
 * time; the PWM timer keeps its pulses. The core writes only for a SERVO_TRIM SAVE or
 * FACTORY, which it takes in stream mode only, and erases once every 455 records.
 *
 * The QEMU build: QEMU's netduinoplus2 maps flash as ROM and models no flash interface, so
 * the unit is a 1 KB page of .noinit RAM with the same rules (erased 0xFF, programming clears
 * bits): it survives a system reset (the watchdog's, the fault path's) within one emulator
 * run, as the fault record does, and is lost with the emulator.
 */
#include <string.h>

#include "board.h"
#include "regs.h"
#include "wf/hal.h"

#if WF_PORT_QEMU

enum { UNIT_SIZE = 1024 };

__attribute__((section(".noinit"))) static uint32_t unit[UNIT_SIZE / 4];

size_t wf_hal_storage_size(void)
{
    return UNIT_SIZE;
}

bool wf_hal_storage_read(uint32_t offset, uint8_t *buf, size_t len)
{
    if (offset > UNIT_SIZE || len > UNIT_SIZE - offset) {
        return false;
    }
    memcpy(buf, (const uint8_t *)unit + offset, len);
    return true;
}

bool wf_hal_storage_erase(void)
{
    memset(unit, 0xFF, sizeof unit);
    return true;
}

bool wf_hal_storage_program(uint32_t offset, const uint32_t *words, size_t count)
{
    if (offset % 4u != 0u || offset > UNIT_SIZE || count > (UNIT_SIZE - offset) / 4u) {
        return false;
    }
    for (size_t i = 0; i < count; i++) {
        unit[offset / 4u + i] &= words[i];
    }
    return true;
}

#else

#define SECTOR_BASE 0x08008000u
enum {
    SECTOR = 2,
    SECTOR_SIZE = 16384,
    /* Loop bounds of the BSY waits at >= 4 cycles per pass of 168 MHz: a word 100 us at
     * most (datasheet), waited for up to 1 ms; an erase 0.5 s at most, waited for up to 2 s.
     * A slower clock (the HSI fallback) only lengthens the bound. */
    WORD_LOOPS = 42000,
    ERASE_LOOPS = 84000000,
};

size_t wf_hal_storage_size(void)
{
    return SECTOR_SIZE;
}

bool wf_hal_storage_read(uint32_t offset, uint8_t *buf, size_t len)
{
    if (offset > SECTOR_SIZE || len > SECTOR_SIZE - offset) {
        return false;
    }
    memcpy(buf, (const uint8_t *)SECTOR_BASE + offset, len);
    return true;
}

static bool wait_idle(uint32_t loops)
{
    for (uint32_t i = 0; i < loops; i++) {
        if (!(FLASH_SR & FLASH_SR_BSY)) {
            return true;
        }
    }
    return false;
}

static bool unlock(void)
{
    if (!wait_idle(WORD_LOOPS)) {
        return false;
    }
    FLASH_SR = FLASH_SR_ERRORS | FLASH_SR_EOP; /* write 1 to clear what an earlier one left */
    if (FLASH_CR & FLASH_CR_LOCK) {
        FLASH_KEYR = FLASH_KEY1;
        FLASH_KEYR = FLASH_KEY2;
    }
    if (FLASH_CR & FLASH_CR_LOCK) {
        return false; /* a wrong sequence locks the interface until the next reset */
    }
    FLASH_CR = (FLASH_CR & ~(FLASH_CR_PSIZE_MASK | FLASH_CR_SNB_MASK | FLASH_CR_PG |
                             FLASH_CR_SER)) | FLASH_CR_PSIZE_X32;
    return true;
}

/* Locks the interface, resets the data cache (it may still hold the sector's old words) and
 * returns whether the operation ended in time without an error flag. */
static bool finish(bool waited)
{
    const bool clean = waited && !(FLASH_SR & FLASH_SR_ERRORS);
    FLASH_SR = FLASH_SR_ERRORS | FLASH_SR_EOP;
    FLASH_CR = (FLASH_CR & ~(FLASH_CR_PG | FLASH_CR_SER | FLASH_CR_SNB_MASK)) | FLASH_CR_LOCK;
    if (FLASH_ACR & FLASH_ACR_DCEN) {
        FLASH_ACR &= ~FLASH_ACR_DCEN;
        FLASH_ACR |= FLASH_ACR_DCRST;
        FLASH_ACR &= ~FLASH_ACR_DCRST;
        FLASH_ACR |= FLASH_ACR_DCEN;
    }
    return clean;
}

bool wf_hal_storage_erase(void)
{
    if (!unlock()) {
        return false;
    }
    board_watchdog_slow(true);
    FLASH_CR |= FLASH_CR_SER | FLASH_CR_SNB(SECTOR);
    FLASH_CR |= FLASH_CR_STRT;
    const bool waited = wait_idle(ERASE_LOOPS);
    board_watchdog_slow(false);
    if (!finish(waited)) {
        return false;
    }
    const volatile uint32_t *word = (const volatile uint32_t *)SECTOR_BASE;
    for (uint32_t i = 0; i < SECTOR_SIZE / 4u; i++) {
        if (word[i] != 0xFFFFFFFFu) {
            return false;
        }
    }
    return true;
}

bool wf_hal_storage_program(uint32_t offset, const uint32_t *words, size_t count)
{
    if (offset % 4u != 0u || offset > SECTOR_SIZE || count > (SECTOR_SIZE - offset) / 4u) {
        return false;
    }
    if (!unlock()) {
        return false;
    }
    volatile uint32_t *target = (volatile uint32_t *)(SECTOR_BASE + offset);
    bool waited = true;
    FLASH_CR |= FLASH_CR_PG;
    for (size_t i = 0; i < count && waited && !(FLASH_SR & FLASH_SR_ERRORS); i++) {
        target[i] = words[i];
        waited = wait_idle(WORD_LOOPS);
    }
    if (!finish(waited)) {
        return false;
    }
    for (size_t i = 0; i < count; i++) {
        if (target[i] != words[i]) {
            return false;
        }
    }
    return true;
}

#endif
