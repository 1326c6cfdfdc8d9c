/* SPDX-License-Identifier: Apache-2.0 */
/*
 * USART1, the link to the host (115200 8N1, RM0090 30.6), interrupt driven: the RX interrupt
 * fills rx_ring (256 bytes: 22 ms at 115200 baud), the main loop empties it (wf_hal_uart_read);
 * the main loop fills tx_ring (wf_hal_uart_write) and the TXE interrupt empties it. Each ring
 * has one producer and one consumer (ring.h). Pins on the real board: PA9 TX, PA10 RX (AF7), the pins of the system
 * bootloader's USART1, so the radio that carries the link can also reflash the board.
 */
#include "board.h"
#include "debug_console.h"
#include "gpio.h"
#include "regs.h"
#include "ring.h"
#include "wf/hal.h"

RING_DEFINE(rx_ring, 256);
RING_DEFINE(tx_ring, 512);
static volatile uint32_t rx_overflows;   /* overruns: a byte came while DR was still full */

uint32_t board_uart_rx_overflows(void)
{
    return rx_overflows;
}

void board_uart_init(void)
{
    RCC_APB2ENR |= RCC_APB2ENR_USART1;
    gpio_alternate(GPIOA_BASE, 9u, 7u, 0);
    gpio_alternate(GPIOA_BASE, 10u, 7u, 0);
    USART_BRR(USART1_BASE) = (board_clocks.apb2_hz + BOARD_UART_BAUD / 2u) / BOARD_UART_BAUD;
    USART_CR2(USART1_BASE) = 0u;
    USART_CR3(USART1_BASE) = 0u;
    USART_CR1(USART1_BASE) = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
    NVIC_ISER(USART1_IRQN / 32u) = 1u << (USART1_IRQN % 32u);
}

void wf_usart1_handler(void)
{
    uint32_t status = USART_SR(USART1_BASE);
    const bool listening = (USART_CR1(USART1_BASE) & USART_CR1_RXNEIE) != 0u;
    if (listening && (status & (USART_SR_RXNE | USART_SR_ORE))) {
        if (ring_used(&rx_ring) > rx_ring.mask) {
            /* No room: leave the byte in DR and stop listening until the main loop has made
             * room (wf_hal_uart_read). QEMU then holds the next bytes back (it delivers one
             * only once DR was read): no loss. A real UART overruns on the next byte; the
             * overrun is counted when DR is read again. */
            USART_CR1(USART1_BASE) &= ~USART_CR1_RXNEIE;
        } else {
            uint8_t byte = (uint8_t)USART_DR(USART1_BASE);   /* the read clears RXNE, ORE */
            if (status & USART_SR_ORE) {
                rx_overflows = rx_overflows + 1u;
            }
            (void)ring_put(&rx_ring, byte);
            trace_rx_byte(byte);   /* the QEMU build: a "Z" line at each frame's end */
        }
    }
    if ((USART_CR1(USART1_BASE) & USART_CR1_TXEIE) && (status & USART_SR_TXE)) {
        uint8_t byte;
        if (ring_get(&tx_ring, &byte)) {
            USART_DR(USART1_BASE) = byte;
        } else {
            USART_CR1(USART1_BASE) &= ~USART_CR1_TXEIE;   /* nothing left: stop asking */
        }
    }
}

size_t wf_hal_uart_read(uint8_t *buf, size_t max)
{
    size_t count = 0u;
    while (count < max && ring_get(&rx_ring, &buf[count])) {
        count++;
    }
    if (count > 0u && !(USART_CR1(USART1_BASE) & USART_CR1_RXNEIE)) {
        /* There is room again: listen (CR1 is also written by the handler: masked). */
        uint32_t primask = board_irq_save();
        USART_CR1(USART1_BASE) |= USART_CR1_RXNEIE;
        board_irq_restore(primask);
    }
    return count;
}

size_t wf_hal_uart_write(const uint8_t *buf, size_t len)
{
    /* All or nothing (wf/hal.h): the interrupt only takes bytes out, so the room seen here
     * can only grow before the puts below, which then all succeed. */
    if (len > tx_ring.mask + 1u - ring_used(&tx_ring)) {
        return 0u;
    }
    size_t count = 0u;
    while (count < len && ring_put(&tx_ring, buf[count])) {
        count++;
    }
#if WF_PORT_QEMU
    /* QEMU 7.2's USART raises its interrupt for RXNE only, never for TXE, and sends each DR
     * write at once: the main loop is the ring's consumer here. */
    uint8_t byte;
    while (ring_get(&tx_ring, &byte)) {
        while (!(USART_SR(USART1_BASE) & USART_SR_TXE)) {
        }
        USART_DR(USART1_BASE) = byte;
    }
#else
    if (count > 0u) {
        /* CR1 is also written by the interrupt handler: change it with interrupts masked. */
        uint32_t primask = board_irq_save();
        USART_CR1(USART1_BASE) |= USART_CR1_TXEIE;
        board_irq_restore(primask);
    }
#endif
    return count;
}
