/* What changed since the last record: the blocks, then the samples, where the grid differs from
 * the journal's shadow, appended to the record buffer as runs (bridging short unchanged gaps)
 * while the shadow is brought up to date. */
#include <stdlib.h>
#include <string.h>

#include "host/io/journal_internal.h"

/* Room in j->views for n blocks; false when out of memory. */
static bool views_reserve(journal_t *j, size_t n)
{
    if (n <= j->views_cap)
        return true;
    size_t cap = j->views_cap > 0 ? j->views_cap : 64;
    while (cap < n)
        cap *= 2;
    grid_block_view_t *v = realloc(j->views, cap * sizeof(*v));
    if (v == NULL)
        return false;
    j->views = v;
    j->views_cap = cap;
    return true;
}

/* True when the grid's block v and the shadow's block b (NULL: absent) differ in kind inside
 * the sample box [gl, gh); two blocks without arrays compare in one step. */
static bool block_differs(const grid_t *g, const grid_block_view_t *v, const journal_block_t *b,
                          int kind, const int32_t gl[3], const int32_t gh[3])
{
    int32_t a0[3], a1[3];
    if (!journal_block_clip(v->key, gl, gh, a0, a1))
        return false;
    uint8_t lc[4], sc[4];
    const uint8_t *la = journal_grid_arr(g, v, kind, lc), *sa = journal_shadow_arr(b, kind, sc);
    const size_t es = journal_kind_bytes(kind), w = (size_t)(a1[0] - a0[0]);
    if (la == NULL && sa == NULL)
        return memcmp(lc, sc, es) != 0;
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const size_t li = journal_block_local(v->key, a0[0], y, z);
            if (la != NULL && sa != NULL) {
                if (memcmp(la + es * li, sa + es * li, es * w) != 0)
                    return true;
                continue;
            }
            const uint8_t *arr = (la != NULL ? la : sa) + es * li, *c = la != NULL ? sc : lc;
            for (size_t x = 0; x < w; x++)
                if (memcmp(arr + es * x, c, es) != 0)
                    return true;
        }
    return false;
}

/* Orders blocks as their samples come in the journal's sample order: z, then y, then x. */
static int view_order(const void *pa, const void *pb)
{
    const grid_block_view_t *a = pa, *b = pb;
    for (int q = 2; q >= 0; q--)
        if (a->key[q] != b->key[q])
            return a->key[q] < b->key[q] ? -1 : 1;
    return 0;
}

/* The blocks meeting the sample box [gl, gh) whose kind differs between the grid and the
 * shadow, in sample order, into j->views[0, *count). Looks only at blocks one of them holds
 * (a block neither holds reads the same in both). false when out of memory. */
bool journal_diff_blocks(journal_t *j, const grid_t *g, int kind, const int32_t gl[3],
                         const int32_t gh[3], size_t *count)
{
    *count = 0;
    int32_t k0[3], k1[3];
    uint64_t nk = 1;
    for (int a = 0; a < 3; a++) {
        if (gh[a] <= gl[a])
            return true;
        k0[a] = grid_block_index(gl[a]);
        k1[a] = grid_block_index(gh[a] - 1);
        nk *= (uint64_t)(k1[a] - k0[a] + 1);
    }
    const size_t held = g->blocks.count + j->shadow.blocks.count;
    if (!views_reserve(j, nk < (uint64_t)held ? (size_t)nk : held))
        return false;
    size_t n = 0;
    grid_block_view_t v;
    if (nk <= (uint64_t)held) { /* every block index of the box, already in order */
        int32_t k[3];
        for (k[2] = k0[2]; k[2] <= k1[2]; k[2]++)
            for (k[1] = k0[1]; k[1] <= k1[1]; k[1]++)
                for (k[0] = k0[0]; k[0] <= k1[0]; k[0]++) {
                    (void)grid_block_view(g, k, &v);
                    if (block_differs(g, &v, journal_shadow_find(&j->shadow, k), kind, gl, gh))
                        j->views[n++] = v;
                }
        *count = n;
        return true;
    }
    /* The blocks either side holds for kind, sorted, each once. */
    int32_t a0[3], a1[3];
    uint8_t cst[4];
    for (size_t slot = 0; grid_block_next(g, &slot, &v);)
        if (journal_block_clip(v.key, gl, gh, a0, a1) &&
            (kind == JOURNAL_KIND_DENS || journal_grid_arr(g, &v, kind, cst) != NULL))
            j->views[n++] = v;
    size_t sslot = 0;
    for (const journal_block_t *b; (b = block_table_next(&j->shadow.blocks, &sslot)) != NULL;) {
        if (journal_block_clip(b->key, gl, gh, a0, a1) &&
            (kind == JOURNAL_KIND_DENS || journal_shadow_arr(b, kind, cst) != NULL)) {
            (void)grid_block_view(g, b->key, &v);
            j->views[n++] = v;
        }
    }
    if (n > 1)
        qsort(j->views, n, sizeof(*j->views), view_order);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && view_order(&j->views[i], &j->views[i - 1]) == 0)
            continue;
        if (block_differs(g, &j->views[i], journal_shadow_find(&j->shadow, j->views[i].key), kind,
                          gl, gh))
            j->views[m++] = j->views[i];
    }
    *count = m;
    return true;
}

/* A record's runs of one kind being made. */
typedef struct {
    journal_t *j;
    const grid_t *g;
    int kind;
    bool open;                /* a run [start, end) is open */
    size_t start, end;        /* journal sample indices */
    uint32_t runs;            /* written */
    grid_block_view_t lv;     /* the grid block last read */
    bool lv_ok;
    journal_block_t *sb;      /* the shadow block last written (NULL: absent) */
    int32_t sb_key[3];
    bool sb_ok;
} emit_t;

/* Appends the run [start, end) of the grid's current values to the open record and to the
 * shadow; false when out of memory. */
static bool put_run(emit_t *e, size_t start, size_t end)
{
    journal_t *j = e->j;
    const size_t count = end - start, es = journal_kind_bytes(e->kind);
    if (!journal_buf_reserve(j, 8 + es * count))
        return false;
    uint8_t *p = j->buf + j->buf_len;
    le_put_u32(p, (uint32_t)start);
    le_put_u32(p + 4, (uint32_t)count);
    const size_t nx = (size_t)j->dims[0], ny = (size_t)j->dims[1];
    for (size_t i = start; i < end; i++) {
        const int32_t x = j->lo[0] + (int32_t)(i % nx), y = j->lo[1] + (int32_t)(i / nx % ny),
                      z = j->lo[2] + (int32_t)(i / (nx * ny));
        const int32_t k[3] = {grid_block_index(x), grid_block_index(y), grid_block_index(z)};
        const size_t li = journal_block_local(k, x, y, z);
        if (!e->lv_ok || memcmp(e->lv.key, k, sizeof(k)) != 0) {
            (void)grid_block_view(e->g, k, &e->lv);
            e->lv_ok = true;
        }
        uint8_t lc[4], sc[4];
        const uint8_t *la = journal_grid_arr(e->g, &e->lv, e->kind, lc);
        const uint8_t *val = la != NULL ? la + es * li : lc;
        uint8_t *out = p + 8 + es * (i - start);
        if (es == 4) {
            float f;
            memcpy(&f, val, 4);
            le_put_f32(out, f);
        } else {
            memcpy(out, val, es);
        }
        if (!e->sb_ok || memcmp(e->sb_key, k, sizeof(k)) != 0) {
            e->sb = journal_shadow_find(&j->shadow, k);
            memcpy(e->sb_key, k, sizeof(k));
            e->sb_ok = true;
        }
        uint8_t *sa = journal_shadow_arr(e->sb, e->kind, sc);
        if (sa == NULL) {
            if (memcmp(val, sc, es) == 0)
                continue;
            if (e->sb == NULL && (e->sb = journal_shadow_touch(&j->shadow, k)) == NULL)
                return false;
            if (!journal_shadow_arr_make(&j->shadow, e->sb, e->kind))
                return false;
            sa = journal_shadow_arr(e->sb, e->kind, sc);
        }
        memcpy(sa + es * li, val, es);
    }
    j->buf_len += 8 + es * count;
    if (e->kind == JOURNAL_KIND_DENS)
        j->stats.samples += count;
    else if (e->kind == JOURNAL_KIND_RGB)
        j->stats.rgb_samples += count;
    else
        j->stats.mat_samples += count;
    return true;
}

/* Sample i (journal index, increasing) differs: it joins the open run when at most
 * JOURNAL_RUN_GAP unchanged samples lie between (they are written too), else the open run is
 * written and a new one starts. false when out of memory. */
static bool emit_sample(emit_t *e, size_t i)
{
    if (e->open && i - e->end <= JOURNAL_RUN_GAP) {
        e->end = i + 1;
        return true;
    }
    if (e->open) {
        if (!put_run(e, e->start, e->end))
            return false;
        e->runs++;
    }
    e->open = true;
    e->start = i;
    e->end = i + 1;
    return true;
}

/* Appends as runs, in sample order, the samples of kind inside [gl, gh) that differ between the
 * grid and the shadow, over the changed blocks j->views[0, nviews), and brings the shadow up to
 * date; then drops the shadow arrays that became uniform. *runs counts the runs. false when out
 * of memory. */
bool journal_diff_put_runs(journal_t *j, const grid_t *g, int kind, const int32_t gl[3],
                           const int32_t gh[3], size_t nviews, uint32_t *runs)
{
    emit_t e;
    memset(&e, 0, sizeof(e));
    e.j = j;
    e.g = g;
    e.kind = kind;
    const size_t es = journal_kind_bytes(kind), nx = (size_t)j->dims[0], ny = (size_t)j->dims[1];
    const grid_block_view_t *vs = j->views;
    for (size_t a = 0; a < nviews;) {
        size_t b = a; /* [a, b): one slab of blocks (same z index) */
        while (b < nviews && vs[b].key[2] == vs[a].key[2])
            b++;
        const int32_t bz = vs[a].key[2] * GRID_B;
        const int32_t z0 = bz > gl[2] ? bz : gl[2], z1 = bz + GRID_B < gh[2] ? bz + GRID_B : gh[2];
        for (int32_t z = z0; z < z1; z++)
            for (size_t c = a; c < b;) {
                size_t d = c; /* [c, d): one row of blocks (same y index) */
                while (d < b && vs[d].key[1] == vs[c].key[1])
                    d++;
                const int32_t by = vs[c].key[1] * GRID_B;
                const int32_t y0 = by > gl[1] ? by : gl[1];
                const int32_t y1 = by + GRID_B < gh[1] ? by + GRID_B : gh[1];
                for (int32_t y = y0; y < y1; y++)
                    for (size_t q = c; q < d; q++) {
                        const int32_t bx = vs[q].key[0] * GRID_B;
                        const int32_t x0 = bx > gl[0] ? bx : gl[0];
                        const int32_t x1 = bx + GRID_B < gh[0] ? bx + GRID_B : gh[0];
                        /* This row's samples of both, copied before a run may write the
                         * shadow (only samples before the current one). */
                        uint8_t lc[4], sc[4], lrow[4 * GRID_B], srow[4 * GRID_B];
                        const uint8_t *la = journal_grid_arr(g, &vs[q], kind, lc);
                        const journal_block_t *sb = journal_shadow_find(&j->shadow, vs[q].key);
                        const uint8_t *sa = journal_shadow_arr(sb, kind, sc);
                        const size_t li = journal_block_local(vs[q].key, x0, y, z);
                        const size_t w = (size_t)(x1 - x0);
                        for (size_t x = 0; x < w; x++) {
                            memcpy(lrow + es * x, la != NULL ? la + es * (li + x) : lc, es);
                            memcpy(srow + es * x, sa != NULL ? sa + es * (li + x) : sc, es);
                        }
                        if (memcmp(lrow, srow, es * w) == 0)
                            continue;
                        const size_t i0 =
                            (size_t)(x0 - j->lo[0]) +
                            nx * ((size_t)(y - j->lo[1]) + ny * (size_t)(z - j->lo[2]));
                        for (size_t x = 0; x < w; x++)
                            if (memcmp(lrow + es * x, srow + es * x, es) != 0 &&
                                !emit_sample(&e, i0 + x))
                                return false;
                    }
                c = d;
            }
        a = b;
    }
    if (e.open) {
        if (!put_run(&e, e.start, e.end))
            return false;
        e.runs++;
    }
    for (size_t q = 0; q < nviews; q++) {
        journal_block_t *sb = journal_shadow_find(&j->shadow, vs[q].key);
        if (sb != NULL)
            journal_shadow_arr_compact(&j->shadow, sb, kind);
    }
    *runs = e.runs;
    return true;
}
