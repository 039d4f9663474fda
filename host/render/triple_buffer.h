/* A wait-free triple buffer between one writer thread and one reader thread: the writer fills
 * its own slot and publishes it, the reader takes the newest published slot; neither ever waits,
 * and a slot is never written while the reader holds it. Only slot indices (0..2) move here; the
 * caller owns the three slots. */
#ifndef ARGIL_TRIPLE_BUFFER_H
#define ARGIL_TRIPLE_BUFFER_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#define TRIPLE_BUFFER_FRESH 4u    /* set in `middle` when it holds a slot the reader has not taken */

typedef struct {
    uint32_t back;                /* the writer's slot */
    _Atomic uint32_t middle;      /* the slot in between, | TRIPLE_BUFFER_FRESH once published */
    uint32_t front;               /* the reader's slot */
    uint64_t published;           /* writer: slots published so far */
    uint64_t taken;               /* reader: fresh slots taken so far */
} triple_buffer_t;

/* Writer 0, middle 1 (not fresh), reader 2. */
void triple_buffer_init(triple_buffer_t *t);

/* Writer: the slot it may fill now. */
uint32_t triple_buffer_back(const triple_buffer_t *t);

/* Writer: hands the filled slot over (replacing an untaken one) and returns the next slot to
 * fill. One atomic exchange. */
uint32_t triple_buffer_publish(triple_buffer_t *t);

/* Reader: true when a published slot waits to be taken (one sequentially consistent load). */
bool triple_buffer_has_fresh(const triple_buffer_t *t);

/* Reader: takes the newest published slot if there is one the reader has not seen (true), and
 * returns its slot in *slot either way. One atomic load, plus one exchange when fresh. */
bool triple_buffer_take(triple_buffer_t *t, uint32_t *slot);

#endif
