/* The marching-cubes case table (derived at run time, no published table): for each of the 256
 * corner masks, the triangles as triples of cube edges, CCW seen from outside. */
#ifndef ARGIL_MC_TABLE_H
#define ARGIL_MC_TABLE_H

#include <stdint.h>

/* Cube corner c sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). Edge e runs along axis
 * a = e / 4; with u = (a+1)%3 and v = (a+2)%3 its lower corner has bit u = e & 1 and bit
 * v = (e >> 1) & 1. Face f lies on axis f / 2 at side f & 1. */
#define MC_EDGES 12
#define MC_TRI_MAX 10 /* 12 crossed edges in a single loop give 10 triangles; more loops fewer */

typedef struct {
    uint8_t n_tri;
    uint8_t edge[3 * MC_TRI_MAX]; /* cube edges, 3 per triangle, CCW seen from outside */
} mc_case_t;

typedef struct {
    mc_case_t cases[256]; /* by corner mask, bit c set = corner c inside (density > iso) */
} mc_table_t;

/* Derives all 256 cases from the face rule (deterministic; same table on every call). */
void mc_table_build(mc_table_t *tab);

#endif
