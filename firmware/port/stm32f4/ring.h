/* SPDX-License-Identifier: Apache-2.0 */
/*
 * A single-producer, single-consumer byte ring shared between an interrupt handler and the
 * main loop, without locks: the producer only writes `head`, the consumer only writes `tail`,
 * both are free-running 32-bit counters (a load or store of one is atomic on the Cortex-M4),
 * and the data store is ordered before the index store that publishes it (a data memory
 * barrier, so it also holds on a core that reorders). The size is a power of two.
 */
#ifndef WF_STM32F4_RING_H
#define WF_STM32F4_RING_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct {
    volatile uint32_t head;   /* written by the producer only */
    volatile uint32_t tail;   /* written by the consumer only */
    uint8_t *data;
    uint32_t mask;            /* size - 1 */
} ring_t;

#define RING_DEFINE(name, size)                                                        \
    _Static_assert(((size) & ((size) - 1)) == 0, "ring size must be a power of two");  \
    static uint8_t name##_store[size];                                                 \
    static ring_t name = {0u, 0u, name##_store, (size) - 1u}

static inline void ring_barrier(void)
{
    __asm volatile("dmb" ::: "memory");
}

static inline uint32_t ring_used(const ring_t *ring)
{
    return ring->head - ring->tail;
}

/* Producer side: stores one byte; false (nothing stored) when the ring is full. */
static inline bool ring_put(ring_t *ring, uint8_t byte)
{
    uint32_t head = ring->head;
    if (head - ring->tail > ring->mask) {
        return false;
    }
    ring->data[head & ring->mask] = byte;
    ring_barrier();
    ring->head = head + 1u;
    return true;
}

/* Consumer side: takes one byte into *byte; false when the ring is empty. */
static inline bool ring_get(ring_t *ring, uint8_t *byte)
{
    uint32_t tail = ring->tail;
    if (ring->head == tail) {
        return false;
    }
    ring_barrier();
    *byte = ring->data[tail & ring->mask];
    ring_barrier();
    ring->tail = tail + 1u;
    return true;
}

#endif /* WF_STM32F4_RING_H */
