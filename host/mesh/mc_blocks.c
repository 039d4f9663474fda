/* Block-wise marching cubes: each block copies its samples (plus a one-sample halo for the
 * central-difference normals) into scratch arrays, skips itself when every corner is on one side,
 * and otherwise triangulates its cells with the shared case table. A vertex depends only on its
 * global grid edge, so the same edge meshed from two blocks gives bit-identical vertices and the
 * assembly joins them by edge id. */
#include "host/mesh/mc_blocks.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/mc.h"
#include "host/model/floor_div.h"

#define MCB_NONE UINT32_MAX
#define MCB_L (MC_BLOCK_CELLS + 3) /* scratch samples per axis: cells + 1 corners + 2 halo */
#define MCB_C (MC_BLOCK_CELLS + 1) /* corners per axis */

#define MCB_HASH_MIN 64    /* initial slots of the block hash */
#define MCB_KEY_BITS 20     /* bits per axis of an edge id */

static void mcb_block_free(mc_block_mesh_t *k)
{
    free(k->pos);
    free(k->normal);
    free(k->rgb);
    free(k->key);
    free(k->tri);
    memset(k, 0, sizeof(*k));
}

void mc_blocks_free(mc_blocks_t *b)
{
    size_t slot = 0;
    for (mc_block_t *e; (e = block_table_next(&b->blocks, &slot)) != NULL;)
        mcb_block_free(&e->mesh);
    block_table_free(&b->blocks);
    mcb_block_free(&b->spare);
    free(b->keys);
    free(b->tab);
    free(b->val);
    free(b->rd);
    free(b->rdc);
    free(b->ins);
    free(b->col);
    free(b->cache);
    memset(b, 0, sizeof(*b));
}

_Static_assert(offsetof(mc_block_t, key) == 0, "a block_table entry starts with its key");

/* The slot of block k, or NULL when the hash holds none. */
static mc_block_t *mcb_find(const mc_blocks_t *b, const int32_t k[3])
{
    return block_table_find(&b->blocks, k);
}

/* The slot of block k, taken (clean, no triangles) when new; NULL when out of memory. */
static mc_block_t *mcb_insert(mc_blocks_t *b, const int32_t k[3])
{
    void *e;
    return block_table_insert(&b->blocks, k, &e) == ARGIL_OK ? e : NULL;
}

/* Frees slot e's arrays and gives the slot up. */
static void mcb_remove(mc_blocks_t *b, mc_block_t *e)
{
    mcb_block_free(&e->mesh);
    block_table_remove(&b->blocks, e);
}

/* True when [lo, hi) is a non-empty box within the indices and span a mesher can hold. */
static bool mcb_box_ok(const int32_t lo[3], const int32_t hi[3])
{
    for (int a = 0; a < 3; a++)
        if (lo[a] >= hi[a] || lo[a] < -MC_BLOCKS_INDEX_MAX || hi[a] > MC_BLOCKS_INDEX_MAX ||
            (int64_t)hi[a] - lo[a] > MC_BLOCKS_SPAN_MAX)
            return false;
    return true;
}

argil_err_t mc_blocks_init_box(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3],
                               float spacing_m, vec3_t origin_m, float iso)
{
    memset(b, 0, sizeof(*b));
    if (lo == NULL || hi == NULL || !mcb_box_ok(lo, hi))
        return ARGIL_ERR_ARG;
    if (!isfinite(spacing_m) || !(spacing_m > 0.0f) || !isfinite(iso) || !vec3_isfinite(origin_m))
        return ARGIL_ERR_ARG;
    for (int a = 0; a < 3; a++) {
        b->lo[a] = lo[a];
        b->hi[a] = hi[a];
        b->dims[a] = hi[a] - lo[a];
    }
    b->spacing_m = spacing_m;
    b->origin_m = origin_m;
    b->iso = iso;
    const argil_err_t te = block_table_init(&b->blocks, sizeof(mc_block_t), MCB_HASH_MIN);
    b->tab = malloc(sizeof(*b->tab));
    b->val = malloc(sizeof(float) * MCB_L * MCB_L * MCB_L);
    b->rd = malloc(sizeof(float) * MCB_L * MCB_L * MCB_L);
    b->rdc = malloc(3 * MCB_L * MCB_L * MCB_L);
    b->ins = malloc(MCB_L * MCB_L * MCB_L);
    b->col = malloc(3 * MCB_L * MCB_L * MCB_L);
    b->cache = malloc(sizeof(uint32_t) * 3 * MCB_C * MCB_C * MCB_C);
    if (te != ARGIL_OK || b->tab == NULL || b->val == NULL || b->rd == NULL || b->rdc == NULL ||
        b->ins == NULL || b->col == NULL || b->cache == NULL) {
        mc_blocks_free(b);
        return ARGIL_ERR_NOMEM;
    }
    mc_table_build(b->tab);
    mc_blocks_mark_all(b);
    return ARGIL_OK;
}

argil_err_t mc_blocks_init(mc_blocks_t *b, const int32_t dims[3], float spacing_m,
                           vec3_t origin_m, float iso)
{
    memset(b, 0, sizeof(*b));
    if (dims == NULL)
        return ARGIL_ERR_ARG;
    const int32_t zero[3] = {0, 0, 0};
    return mc_blocks_init_box(b, zero, dims, spacing_m, origin_m, iso);
}

argil_err_t mc_blocks_grow(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3])
{
    if (b == NULL || b->blocks.entries == NULL || lo == NULL || hi == NULL)
        return ARGIL_ERR_ARG;
    for (int a = 0; a < 3; a++)
        if (lo[a] >= hi[a] || lo[a] < -MC_BLOCKS_INDEX_MAX || hi[a] > MC_BLOCKS_INDEX_MAX)
            return ARGIL_ERR_ARG;
    int32_t nlo[3], nhi[3];
    bool changed = false;
    for (int a = 0; a < 3; a++) {
        nlo[a] = lo[a] < b->lo[a] ? lo[a] : b->lo[a];
        nhi[a] = hi[a] > b->hi[a] ? hi[a] : b->hi[a];
        if ((int64_t)nhi[a] - nlo[a] > MC_BLOCKS_SPAN_MAX)
            return ARGIL_ERR_FULL;
        changed |= nlo[a] != b->lo[a] || nhi[a] != b->hi[a];
    }
    if (!changed)
        return ARGIL_OK;
    memcpy(b->lo, nlo, sizeof(nlo));
    memcpy(b->hi, nhi, sizeof(nhi));
    if (!(b->iso >= 0.0f))
        mc_blocks_mark_all(b); /* density 0 is inside: the box's faces were surface */
    return ARGIL_OK;
}

/* First and one-past-last block key per axis over the meshed box's padded cells
 * [lo, hi + 1). */
static void mcb_box_keys(const mc_blocks_t *b, int32_t klo[3], int32_t khi[3])
{
    for (int a = 0; a < 3; a++) {
        klo[a] = floor_div_i32(b->lo[a], MC_BLOCK_CELLS);
        khi[a] = floor_div_i32(b->hi[a], MC_BLOCK_CELLS) + 1;
    }
}

size_t mc_blocks_box_blocks(const mc_blocks_t *b)
{
    int32_t klo[3], khi[3];
    mcb_box_keys(b, klo, khi);
    return (size_t)(khi[0] - klo[0]) * (size_t)(khi[1] - klo[1]) * (size_t)(khi[2] - klo[2]);
}

static size_t mcb_block_bytes(const mc_block_mesh_t *k)
{
    return (size_t)k->cap_vert * (6 * sizeof(float) + sizeof(uint64_t) + (k->rgb != NULL ? 3 : 0)) +
           (size_t)k->cap_tri * 3 * sizeof(uint32_t);
}

size_t mc_blocks_bytes(const mc_blocks_t *b)
{
    if (b == NULL || b->blocks.entries == NULL)
        return 0;
    size_t n = sizeof(*b) + block_table_bytes(&b->blocks) + b->keys_cap * 3 * sizeof(int32_t) +
               sizeof(*b->tab) + (2 * sizeof(float) + 2 + 2 * 3) * MCB_L * MCB_L * MCB_L +
               sizeof(uint32_t) * 3 * MCB_C * MCB_C * MCB_C + mcb_block_bytes(&b->spare);
    size_t slot = 0;
    for (const mc_block_t *e; (e = block_table_next(&b->blocks, &slot)) != NULL;)
        n += mcb_block_bytes(&e->mesh);
    return n;
}

void mc_blocks_mark_all(mc_blocks_t *b)
{
    b->all_dirty = true;
}

void mc_blocks_mark(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3])
{
    if (b->all_dirty)
        return;
    /* Sample s (padded s + 1) is a corner of padded cells s, s + 1 and enters the normals of
     * vertices on edges with an end within one sample: padded cells [s - 1, s + 2]. */
    int32_t blo[3], bhi[3];
    for (int a = 0; a < 3; a++) {
        int64_t l = (int64_t)lo[a] - 1, h = (int64_t)hi[a] + 2; /* padded cells [l, h) */
        if (l < b->lo[a])
            l = b->lo[a];
        if (h > (int64_t)b->hi[a] + 1)
            h = (int64_t)b->hi[a] + 1;
        if (l >= h)
            return;
        blo[a] = floor_div_i32((int32_t)l, MC_BLOCK_CELLS); /* l, h within [lo, hi + 1] */
        bhi[a] = floor_div_i32((int32_t)(h - 1), MC_BLOCK_CELLS) + 1;
    }
    for (int32_t z = blo[2]; z < bhi[2]; z++)
        for (int32_t y = blo[1]; y < bhi[1]; y++)
            for (int32_t x = blo[0]; x < bhi[0]; x++) {
                const int32_t k[3] = {x, y, z};
                mc_block_t *e = mcb_insert(b, k);
                if (e == NULL) {
                    mc_blocks_mark_all(b); /* no room for the slot: mesh everything instead */
                    return;
                }
                e->dirty = 1;
            }
}

/* Grows a block's arrays to hold one more vertex / triangle. */
static argil_err_t mcb_grow_vert(mc_block_mesh_t *k, int with_rgb)
{
    if (k->n_vert < k->cap_vert)
        return ARGIL_OK;
    if (k->cap_vert >= UINT32_MAX / 2)
        return ARGIL_ERR_FULL;
    const size_t cap = k->cap_vert < 64 ? 64 : (size_t)k->cap_vert * 2;
    argil_err_t e = mesh_vert_arrays_resize(&k->pos, &k->normal, with_rgb ? &k->rgb : NULL, cap);
    if (e != ARGIL_OK)
        return e;
    uint64_t *key = realloc(k->key, cap * sizeof(uint64_t));
    if (key == NULL)
        return ARGIL_ERR_NOMEM;
    k->key = key;
    k->cap_vert = (uint32_t)cap;
    return ARGIL_OK;
}

static argil_err_t mcb_grow_tri(mc_block_mesh_t *k)
{
    if (k->n_tri < k->cap_tri)
        return ARGIL_OK;
    if (k->cap_tri >= UINT32_MAX / 8)
        return ARGIL_ERR_FULL;
    const size_t cap = k->cap_tri < 128 ? 128 : (size_t)k->cap_tri * 2;
    if (mesh_tri_array_resize(&k->tri, cap) != ARGIL_OK)
        return ARGIL_ERR_NOMEM;
    k->cap_tri = (uint32_t)cap;
    return ARGIL_OK;
}

/* Per-block working view. */
typedef struct {
    mc_blocks_t *b;
    mc_block_mesh_t *k;
    int32_t c0[3], nc[3]; /* first padded cell and cell count per axis */
    const uint8_t *rgb;
    mc_read_fn read;     /* NULL: density is the whole field's array */
    mc_read_rgb_fn read_rgb; /* colours through a reader (rgb NULL then) */
    const void *ctx;
} mcb_job_t;

/* Scratch index of padded sample p (global padded coordinates). */
static size_t mcb_l(const mcb_job_t *j, int32_t px, int32_t py, int32_t pz)
{
    return (size_t)(px - j->c0[0] + 1) +
           MCB_L * ((size_t)(py - j->c0[1] + 1) + MCB_L * (size_t)(pz - j->c0[2] + 1));
}

/* Copies the block's samples and halo (padded samples c0-1 .. c0+nc+1) into scratch; false when
 * one of them is not finite. Returns through *mixed whether corners lie on both sides. */
static bool mcb_load(mcb_job_t *j, const float *density, bool *mixed)
{
    mc_blocks_t *b = j->b;
    const int32_t *d = b->dims, *blo = b->lo, *bhi = b->hi; /* d: the dense array's (= box) */
    memset(b->val, 0, sizeof(float) * MCB_L * MCB_L * MCB_L);
    memset(b->ins, 0, MCB_L * MCB_L * MCB_L);
    const bool colour = j->rgb != NULL || j->read_rgb != NULL;
    if (colour)
        memset(b->col, 0, 3 * MCB_L * MCB_L * MCB_L);
    /* original sample o = padded - 1; scratch index l = padded - c0 + 1 */
    const int32_t o0[3] = {j->c0[0] - 2, j->c0[1] - 2, j->c0[2] - 2};
    const int32_t n_l[3] = {j->nc[0] + 3, j->nc[1] + 3, j->nc[2] + 3};
    int32_t xlo = o0[0] < blo[0] ? blo[0] : o0[0];
    int32_t xhi = o0[0] + n_l[0] > bhi[0] ? bhi[0] : o0[0] + n_l[0];
    unsigned seen_in = 0, seen_out = 0;
    /* Through a reader: the box of the field the scratch covers, read once, then rows of it. */
    int32_t rlo[3] = {xlo, 0, 0}, rn[3] = {xhi - xlo, 0, 0};
    if (j->read != NULL) {
        for (int a = 1; a < 3; a++) {
            const int32_t l = o0[a] < blo[a] ? blo[a] : o0[a];
            const int32_t h = o0[a] + n_l[a] > bhi[a] ? bhi[a] : o0[a] + n_l[a];
            rlo[a] = l;
            rn[a] = h - l;
        }
        if (rn[0] <= 0 || rn[1] <= 0 || rn[2] <= 0) {
            *mixed = false;
            return true; /* the whole scratch lies beyond the field: all outside */
        }
        j->read(j->ctx, rlo, rn, b->rd);
        if (j->read_rgb != NULL)
            j->read_rgb(j->ctx, rlo, rn, b->rdc);
    }
    for (int32_t lz = 0; lz < n_l[2]; lz++) {
        const int32_t oz = o0[2] + lz;
        if (oz < blo[2] || oz >= bhi[2])
            continue;
        for (int32_t ly = 0; ly < n_l[1]; ly++) {
            const int32_t oy = o0[1] + ly;
            if (oy < blo[1] || oy >= bhi[1] || xlo >= xhi)
                continue;
            /* the dense array's row (only read when the box is [0, dims)) */
            const size_t src =
                j->read != NULL ? 0 : (size_t)d[0] * ((size_t)oy + (size_t)d[1] * (size_t)oz);
            const size_t dst = MCB_L * ((size_t)ly + MCB_L * (size_t)lz);
            const float *row =
                j->read != NULL
                    ? b->rd + (size_t)rn[0] * ((size_t)(oy - rlo[1]) +
                                               (size_t)rn[1] * (size_t)(oz - rlo[2]))
                    : density + src + xlo;
            for (int32_t ox = xlo; ox < xhi; ox++) {
                const float v = row[ox - xlo];
                if (!isfinite(v))
                    return false;
                b->val[dst + (size_t)(ox - o0[0])] = v;
                b->ins[dst + (size_t)(ox - o0[0])] = v > b->iso;
            }
            if (j->rgb != NULL)
                memcpy(b->col + 3 * (dst + (size_t)(xlo - o0[0])), j->rgb + 3 * (src + (size_t)xlo),
                       3 * (size_t)(xhi - xlo));
            else if (j->read_rgb != NULL)
                memcpy(b->col + 3 * (dst + (size_t)(xlo - o0[0])),
                       b->rdc + 3 * (size_t)rn[0] * ((size_t)(oy - rlo[1]) +
                                                     (size_t)rn[1] * (size_t)(oz - rlo[2])),
                       3 * (size_t)(xhi - xlo));
        }
    }
    /* The corners (scratch 1 .. nc+1 per axis); samples beyond the field are outside. */
    for (int32_t lz = 1; lz <= j->nc[2] + 1; lz++)
        for (int32_t ly = 1; ly <= j->nc[1] + 1; ly++) {
            const uint8_t *row = b->ins + MCB_L * ((size_t)ly + MCB_L * (size_t)lz);
            for (int32_t lx = 1; lx <= j->nc[0] + 1; lx++) {
                seen_in |= row[lx];
                seen_out |= (unsigned)(row[lx] ^ 1u);
            }
        }
    *mixed = seen_in && seen_out;
    return true;
}

/* Central-difference gradient (unscaled) at padded sample p, from scratch. */
static vec3_t mcb_gradient(const mcb_job_t *j, const int32_t p[3])
{
    const float *v = j->b->val;
    const size_t i = mcb_l(j, p[0], p[1], p[2]);
    return vec3(v[i + 1] - v[i - 1], v[i + MCB_L] - v[i - MCB_L],
                v[i + MCB_L * MCB_L] - v[i - MCB_L * MCB_L]);
}

/* Creates the vertex of the edge from padded sample p along axis a; same arithmetic as
 * mc_extract, so the positions and normals match it bit for bit. */
static argil_err_t mcb_make_vertex(mcb_job_t *j, const int32_t p[3], int a, uint32_t *id)
{
    mc_blocks_t *b = j->b;
    mc_block_mesh_t *k = j->k;
    int32_t p1[3] = {p[0], p[1], p[2]};
    p1[a] += 1;
    const size_t i0 = mcb_l(j, p[0], p[1], p[2]), i1 = mcb_l(j, p1[0], p1[1], p1[2]);
    const float d0 = b->val[i0], d1 = b->val[i1];
    vec3_t pos, n;
    mc_edge_point(b->origin_m, b->spacing_m, b->iso, p, a, d0, d1, mcb_gradient(j, p),
                  mcb_gradient(j, p1), &pos, &n);
    const bool colour = j->rgb != NULL || j->read_rgb != NULL;
    argil_err_t e = mcb_grow_vert(k, colour);
    if (e != ARGIL_OK)
        return e;
    const uint32_t v = k->n_vert++;
    mesh_vert_put(k->pos, k->normal, v, pos, n);
    if (colour) {
        const uint8_t *c = b->col + 3 * (d0 > b->iso ? i0 : i1); /* the inside end's paint */
        memcpy(k->rgb + 3 * (size_t)v, c, 3);
    }
    /* The box spans under 2^20 samples per axis, so the low 20 bits of each index tell edges
     * apart; the top bits stay below UINT64_MAX, the assembly's empty mark. */
    const uint64_t m = ((uint64_t)1 << MCB_KEY_BITS) - 1;
    k->key[v] = ((uint64_t)(uint32_t)p[2] & m) << (2 * MCB_KEY_BITS + 2) |
                ((uint64_t)(uint32_t)p[1] & m) << (MCB_KEY_BITS + 2) |
                ((uint64_t)(uint32_t)p[0] & m) << 2 | (uint64_t)a;
    *id = v;
    return ARGIL_OK;
}

/* Triangulates every cell of one block (scratch already loaded). */
static argil_err_t mcb_cells(mcb_job_t *j)
{
    mc_blocks_t *b = j->b;
    const uint8_t *ins = b->ins;
    const size_t cstride_y = MCB_C, cstride_z = (size_t)MCB_C * MCB_C;
    for (size_t i = 0; i < 3 * (size_t)MCB_C * MCB_C * MCB_C; i++)
        b->cache[i] = MCB_NONE;
    for (int32_t cz = 0; cz < j->nc[2]; cz++)
        for (int32_t cy = 0; cy < j->nc[1]; cy++) {
            const size_t r0 = MCB_L * ((size_t)cy + 1 + MCB_L * ((size_t)cz + 1)) + 1;
            for (int32_t cx = 0; cx < j->nc[0]; cx++) {
                const size_t i = r0 + (size_t)cx;
                const unsigned mask =
                    (unsigned)ins[i] | (unsigned)ins[i + 1] << 1 | (unsigned)ins[i + MCB_L] << 2 |
                    (unsigned)ins[i + MCB_L + 1] << 3 | (unsigned)ins[i + MCB_L * MCB_L] << 4 |
                    (unsigned)ins[i + MCB_L * MCB_L + 1] << 5 |
                    (unsigned)ins[i + MCB_L * MCB_L + MCB_L] << 6 |
                    (unsigned)ins[i + MCB_L * MCB_L + MCB_L + 1] << 7;
                if (mask == 0 || mask == 255)
                    continue;
                const mc_case_t *c = &b->tab->cases[mask];
                for (int t = 0; t < 3 * (int)c->n_tri; t += 3) {
                    uint32_t v[3];
                    for (int q = 0; q < 3; q++) {
                        const int e = c->edge[t + q], a = e / 4;
                        int32_t lc[3] = {cx, cy, cz}; /* block-local corner of the edge */
                        lc[(a + 1) % 3] += e & 1;
                        lc[(a + 2) % 3] += (e >> 1) & 1;
                        uint32_t *slot = &b->cache[3 * ((size_t)lc[0] + cstride_y * (size_t)lc[1] +
                                                        cstride_z * (size_t)lc[2]) +
                                                   (size_t)a];
                        if (*slot == MCB_NONE) {
                            const int32_t p[3] = {j->c0[0] + lc[0], j->c0[1] + lc[1],
                                                  j->c0[2] + lc[2]};
                            argil_err_t err = mcb_make_vertex(j, p, a, slot);
                            if (err != ARGIL_OK)
                                return err;
                        }
                        v[q] = *slot;
                    }
                    argil_err_t err = mcb_grow_tri(j->k);
                    if (err != ARGIL_OK)
                        return err;
                    uint32_t *tt = j->k->tri + 3 * (size_t)j->k->n_tri++;
                    tt[0] = v[0];
                    tt[1] = v[1];
                    tt[2] = v[2];
                }
            }
        }
    return ARGIL_OK;
}

static argil_err_t mcb_update(mc_blocks_t *b, const float *density, const uint8_t *rgb,
                              mc_read_fn read, mc_read_rgb_fn read_rgb, const void *ctx);

argil_err_t mc_blocks_update(mc_blocks_t *b, const float *density, const uint8_t *rgb)
{
    if (density == NULL)
        return ARGIL_ERR_ARG;
    return mcb_update(b, density, rgb, NULL, NULL, NULL);
}

argil_err_t mc_blocks_update_read(mc_blocks_t *b, mc_read_fn read, const void *ctx)
{
    if (read == NULL)
        return ARGIL_ERR_ARG;
    return mcb_update(b, NULL, NULL, read, NULL, ctx);
}

argil_err_t mc_blocks_update_read_rgb(mc_blocks_t *b, mc_read_fn read, mc_read_rgb_fn read_rgb,
                                      const void *ctx)
{
    if (read == NULL)
        return ARGIL_ERR_ARG;
    return mcb_update(b, NULL, NULL, read, read_rgb, ctx);
}

/* Meshes block k (in its slot, or in the spare then moved into a new slot when it has
 * triangles); a block left without triangles gives its slot up. */
static argil_err_t mcb_mesh_block(mc_blocks_t *b, const int32_t key[3], const float *density,
                                  const uint8_t *rgb, mc_read_fn read, mc_read_rgb_fn read_rgb,
                                  const void *ctx)
{
    mc_block_t *e = mcb_find(b, key);
    mcb_job_t j = {b, e != NULL ? &e->mesh : &b->spare, {0}, {0}, rgb, read, read_rgb, ctx};
    for (int a = 0; a < 3; a++) {
        /* the block's padded cells clipped to the box's [lo, hi + 1) */
        const int64_t c0 = (int64_t)key[a] * MC_BLOCK_CELLS, end = c0 + MC_BLOCK_CELLS;
        const int64_t l = c0 < b->lo[a] ? b->lo[a] : c0;
        const int64_t h = end > (int64_t)b->hi[a] + 1 ? (int64_t)b->hi[a] + 1 : end;
        j.c0[a] = (int32_t)l;
        j.nc[a] = (int32_t)(h - l);
    }
    mc_block_mesh_t *k = j.k;
    k->n_vert = 0;
    k->n_tri = 0;
    const bool colour = rgb != NULL || read_rgb != NULL;
    if (!colour) {
        free(k->rgb);
        k->rgb = NULL;
    } else if (k->rgb == NULL && k->cap_vert > 0) {
        k->rgb = malloc((size_t)k->cap_vert * 3);
        if (k->rgb == NULL)
            return ARGIL_ERR_NOMEM;
    }
    bool mixed = false, skip = false;
    if (read != NULL && b->outside != NULL) {
        /* the block's corners: samples [c0 - 1, c0 + nc) within the box */
        int32_t slo[3], sn[3];
        for (int a = 0; a < 3; a++) {
            const int32_t l = j.c0[a] - 1 < b->lo[a] ? b->lo[a] : j.c0[a] - 1;
            const int32_t h = j.c0[a] + j.nc[a] > b->hi[a] ? b->hi[a] : j.c0[a] + j.nc[a];
            slo[a] = l;
            sn[a] = h > l ? h - l : 0;
        }
        skip = sn[0] == 0 || sn[1] == 0 || sn[2] == 0 || b->outside(ctx, slo, sn, b->iso);
    }
    if (!skip && j.nc[0] > 0 && j.nc[1] > 0 && j.nc[2] > 0) {
        b->blocks_read++;
        if (!mcb_load(&j, density, &mixed))
            return ARGIL_ERR_NONFINITE;
        if (mixed) {
            const argil_err_t err = mcb_cells(&j);
            if (err != ARGIL_OK) {
                k->n_vert = 0;
                k->n_tri = 0;
                return err;
            }
            b->cells_meshed += (uint64_t)j.nc[0] * (uint64_t)j.nc[1] * (uint64_t)j.nc[2];
        }
    }
    b->blocks_meshed++;
    if (k->n_tri == 0) {
        if (e != NULL)
            mcb_remove(b, e);
        return ARGIL_OK;
    }
    if (e == NULL) {
        e = mcb_insert(b, key);
        if (e == NULL) {
            b->spare.n_vert = 0;
            b->spare.n_tri = 0;
            return ARGIL_ERR_NOMEM;
        }
        e->mesh = b->spare;
        memset(&b->spare, 0, sizeof(b->spare));
    }
    e->dirty = 0;
    return ARGIL_OK;
}

static argil_err_t mcb_update(mc_blocks_t *b, const float *density, const uint8_t *rgb,
                              mc_read_fn read, mc_read_rgb_fn read_rgb, const void *ctx)
{
    if (b == NULL || b->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    if (density != NULL)
        for (int a = 0; a < 3; a++)
            if (b->lo[a] != 0 || b->hi[a] != b->dims[a])
                return ARGIL_ERR_ARG; /* grown past the array */
    const bool colour = rgb != NULL || read_rgb != NULL;
    if (colour != (b->has_rgb != 0)) {
        mc_blocks_mark_all(b);
        b->has_rgb = colour;
    }
    b->blocks_meshed = 0;
    b->blocks_read = 0;
    b->cells_meshed = 0;
    if (b->all_dirty) {
        int32_t klo[3], khi[3];
        mcb_box_keys(b, klo, khi);
        for (int32_t z = klo[2]; z < khi[2]; z++)
            for (int32_t y = klo[1]; y < khi[1]; y++)
                for (int32_t x = klo[0]; x < khi[0]; x++) {
                    const int32_t key[3] = {x, y, z};
                    const argil_err_t e = mcb_mesh_block(b, key, density, rgb, read, read_rgb, ctx);
                    if (e != ARGIL_OK)
                        return e; /* still all dirty */
                }
        b->all_dirty = false;
        size_t slot = 0; /* every slot lies in the box and was meshed */
        for (mc_block_t *e; (e = block_table_next(&b->blocks, &slot)) != NULL;)
            e->dirty = 0;
        return ARGIL_OK;
    }
    /* The dirty keys first: meshing moves slots (a block may give its slot up). */
    size_t n = 0, slot = 0;
    for (const mc_block_t *e; (e = block_table_next(&b->blocks, &slot)) != NULL;)
        n += e->dirty;
    if (n > b->keys_cap) {
        int32_t *k = realloc(b->keys, n * 3 * sizeof(int32_t));
        if (k == NULL)
            return ARGIL_ERR_NOMEM;
        b->keys = k;
        b->keys_cap = n;
    }
    n = 0;
    slot = 0;
    for (const mc_block_t *e; (e = block_table_next(&b->blocks, &slot)) != NULL;)
        if (e->dirty)
            memcpy(b->keys + 3 * n++, e->key, 3 * sizeof(int32_t));
    for (size_t i = 0; i < n; i++) {
        const argil_err_t e = mcb_mesh_block(b, b->keys + 3 * i, density, rgb, read, read_rgb, ctx);
        if (e != ARGIL_OK)
            return e;
    }
    return ARGIL_OK;
}

/* Multiplicative hash of an edge id into a table of 2^bits slots. */
static size_t mcb_hash(uint64_t key, int bits)
{
    return (size_t)((key * 0x9E3779B97F4A7C15ull) >> (64 - bits));
}

/* Orders slots by block key: z, then y, then x. */
static int mcb_cmp_key(const void *pa, const void *pb)
{
    const mc_block_t *a = *(const mc_block_t *const *)pa, *b = *(const mc_block_t *const *)pb;
    for (int ax = 2; ax >= 0; ax--)
        if (a->key[ax] != b->key[ax])
            return a->key[ax] < b->key[ax] ? -1 : 1;
    return 0;
}

argil_err_t mc_blocks_assemble(const mc_blocks_t *b, mesh_t *out)
{
    if (b == NULL || out == NULL || b->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    mesh_clear(out);
    size_t total_v = 0, total_t = 0, max_v = 0, n_blk = 0, slot = 0;
    for (const mc_block_t *e; (e = block_table_next(&b->blocks, &slot)) != NULL;) {
        const mc_block_mesh_t *k = &e->mesh;
        if (k->n_tri == 0)
            continue;
        n_blk++;
        total_v += k->n_vert;
        total_t += k->n_tri;
        if (k->n_vert > max_v)
            max_v = k->n_vert;
    }
    if (b->has_rgb && !out->has_rgb && mesh_enable_rgb(out) != ARGIL_OK)
        return ARGIL_ERR_NOMEM;
    if (!b->has_rgb && out->has_rgb) {
        free(out->rgb);
        out->rgb = NULL;
        out->has_rgb = 0;
    }
    int bits = 4;
    while (((size_t)1 << bits) < 2 * total_v + 16)
        bits++;
    const size_t slots = (size_t)1 << bits;
    uint64_t *keys = malloc(slots * sizeof(uint64_t));
    uint32_t *vals = malloc(slots * sizeof(uint32_t));
    uint32_t *remap = malloc((max_v + 1) * sizeof(uint32_t));
    const mc_block_t **order = malloc((n_blk + 1) * sizeof(*order));
    argil_err_t e = ARGIL_ERR_NOMEM;
    if (keys == NULL || vals == NULL || remap == NULL || order == NULL)
        goto done;
    n_blk = 0;
    slot = 0;
    for (const mc_block_t *blk; (blk = block_table_next(&b->blocks, &slot)) != NULL;)
        if (blk->mesh.n_tri > 0)
            order[n_blk++] = blk;
    qsort(order, n_blk, sizeof(*order), mcb_cmp_key);
    memset(keys, 0xff, slots * sizeof(uint64_t)); /* UINT64_MAX = empty; no edge id reaches it */
    e = mesh_reserve(out, total_v, total_t);
    if (e != ARGIL_OK)
        goto done;
    for (size_t bi = 0; bi < n_blk; bi++) {
        const mc_block_mesh_t *k = &order[bi]->mesh;
        for (uint32_t v = 0; v < k->n_vert; v++) {
            size_t h = mcb_hash(k->key[v], bits);
            while (keys[h] != UINT64_MAX && keys[h] != k->key[v])
                h = (h + 1) & (slots - 1);
            if (keys[h] == UINT64_MAX) {
                keys[h] = k->key[v];
                const size_t id = out->n_vert++;
                memcpy(out->pos + 3 * id, k->pos + 3 * (size_t)v, 3 * sizeof(float));
                memcpy(out->normal + 3 * id, k->normal + 3 * (size_t)v, 3 * sizeof(float));
                if (b->has_rgb)
                    memcpy(out->rgb + 3 * id, k->rgb + 3 * (size_t)v, 3);
                vals[h] = (uint32_t)id;
            }
            remap[v] = vals[h];
        }
        for (size_t t = 0; t < 3 * (size_t)k->n_tri; t++)
            out->tri[3 * out->n_tri + t] = remap[k->tri[t]];
        out->n_tri += k->n_tri;
    }
    e = ARGIL_OK;
done:
    free(keys);
    free(vals);
    free(remap);
    free(order);
    if (e != ARGIL_OK)
        mesh_clear(out);
    return e;
}

argil_err_t mc_extract_region(const float *density, const uint8_t *rgb, const int32_t dims[3],
                              float spacing_m, vec3_t origin_m, float iso, const int32_t lo[3],
                              const int32_t hi[3], mesh_t *out)
{
    if (out == NULL)
        return ARGIL_ERR_ARG;
    mesh_clear(out);
    if (density == NULL || dims == NULL)
        return ARGIL_ERR_ARG;
    int32_t l[3] = {0, 0, 0}, h[3] = {dims[0], dims[1], dims[2]}, n[3];
    for (int a = 0; a < 3; a++) {
        if (lo != NULL)
            l[a] = lo[a];
        if (hi != NULL)
            h[a] = hi[a];
        if (l[a] < 0 || h[a] > dims[a] || l[a] >= h[a])
            return ARGIL_ERR_ARG;
        n[a] = h[a] - l[a];
    }
    const bool whole = n[0] == dims[0] && n[1] == dims[1] && n[2] == dims[2];
    float *sub = NULL;
    uint8_t *subc = NULL;
    argil_err_t e = ARGIL_OK;
    if (!whole) {
        const size_t cnt = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
        sub = malloc(cnt * sizeof(float));
        subc = rgb != NULL ? malloc(cnt * 3) : NULL;
        if (sub == NULL || (rgb != NULL && subc == NULL)) {
            free(sub);
            free(subc);
            return ARGIL_ERR_NOMEM;
        }
        size_t i = 0;
        for (int32_t z = l[2]; z < h[2]; z++)
            for (int32_t y = l[1]; y < h[1]; y++, i += (size_t)n[0]) {
                const size_t src = (size_t)l[0] + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z);
                memcpy(sub + i, density + src, (size_t)n[0] * sizeof(float));
                if (subc != NULL)
                    memcpy(subc + 3 * i, rgb + 3 * src, 3 * (size_t)n[0]);
            }
        origin_m = vec3(origin_m.x + spacing_m * (float)l[0], origin_m.y + spacing_m * (float)l[1],
                        origin_m.z + spacing_m * (float)l[2]);
    }
    mc_blocks_t b;
    e = mc_blocks_init(&b, n, spacing_m, origin_m, iso);
    if (e == ARGIL_OK) {
        e = mc_blocks_update(&b, whole ? density : sub, whole ? rgb : subc);
        if (e == ARGIL_OK)
            e = mc_blocks_assemble(&b, out);
        mc_blocks_free(&b);
    }
    free(sub);
    free(subc);
    if (e != ARGIL_OK)
        mesh_clear(out);
    return e;
}
