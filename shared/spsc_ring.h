/* Single-producer / single-consumer ring of byte records, lock-free: the link thread and the
 * fast loop hand frames to each other through two of these, and neither can ever wait on the
 * other. One producer thread and one consumer thread per ring; storage is the caller's. */
#ifndef ARGIL_SPSC_RING_H
#define ARGIL_SPSC_RING_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"

#define SPSC_RECORD_MAX 0xFFFFu   /* bytes in one record (a u16 length prefix) */

typedef struct {
    uint8_t *bytes;
    uint32_t mask;                /* capacity - 1; capacity is a power of two */
    _Atomic uint32_t head;        /* free-running read index (consumer writes) */
    _Atomic uint32_t tail;        /* free-running write index (producer writes) */
    _Atomic uint32_t dropped;     /* records the producer could not fit */
} spsc_ring_t;

/* capacity_bytes must be a power of two ≥ 16; ARGIL_ERR_ARG otherwise. */
argil_err_t spsc_init(spsc_ring_t *r, uint8_t *storage, uint32_t capacity_bytes);

/* Producer: appends one record, or ARGIL_ERR_FULL (and counts a drop) when it does not fit. */
argil_err_t spsc_push(spsc_ring_t *r, const uint8_t *data, size_t len);

/* Consumer: length of the next record, 0 when the ring is empty. */
size_t spsc_peek_len(spsc_ring_t *r);

/* Consumer: moves the next record into buf. ARGIL_ERR_EMPTY when there is none; ARGIL_ERR_FULL
 * when cap is too small (the record stays). */
argil_err_t spsc_pop(spsc_ring_t *r, uint8_t *buf, size_t cap, size_t *len);

/* Consumer: drops the next record; false when the ring is empty. */
bool spsc_skip(spsc_ring_t *r);

/* Bytes in use (approximate when the other side is active). */
uint32_t spsc_used(spsc_ring_t *r);

#endif
