/* Undo journal: runs of (before, after) pairs written into one ring that is mapped and faulted
 * in once (a first-touch page fault costs ~15 us on the target VM); boxes that editors do not
 * note themselves are snapshotted and diffed. */
#include "host/model/undo.h"

#include "host/model/f32_buf.h"

#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

/* Bytes of one change in a run of the given store: (before, after), or for UNDO_STORE_DREST
 * (d before, d after, rest before). */
static size_t undo_elem_bytes(int store)
{
    return (store == UNDO_STORE_DREST ? 3 : 2) * sizeof(float);
}

/* Anonymous memory with every page already faulted in and written once; NULL when the system
 * refuses. MAP_POPULATE alone is not enough on this VM: the first write to a populated page still
 * cost ~4 us (0.6-0.9 ms per 640 kB, the journal of one 128^3/40^3 carve) against 0.03 ms once
 * the page has been written, so the whole ring is cleared here, at init (~10-20 ms per 64 MB). */
static uint8_t *undo_map(size_t bytes)
{
    void *p = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_POPULATE, -1, 0);
    if (p == MAP_FAILED)
        return NULL;
    memset(p, 0, bytes);
    return (uint8_t *)p;
}

argil_err_t undo_init(undo_t *u, size_t budget_bytes)
{
    memset(u, 0, sizeof(*u));
    u->budget_bytes = budget_bytes;
    if (budget_bytes == 0)
        return ARGIL_OK;
    u->ring = undo_map(budget_bytes);
    if (u->ring == NULL)
        return ARGIL_ERR_NOMEM;
    u->ring_cap = budget_bytes;
    return ARGIL_OK;
}

argil_err_t undo_init_lazy(undo_t *u, size_t budget_bytes)
{
    memset(u, 0, sizeof(*u));
    u->budget_bytes = budget_bytes;
    if (budget_bytes == 0)
        return ARGIL_OK;
    void *p = mmap(NULL, budget_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED)
        return ARGIL_ERR_NOMEM;
    u->ring = (uint8_t *)p;
    u->ring_cap = budget_bytes;
    return ARGIL_OK;
}

void undo_free(undo_t *u)
{
    if (u->ring != NULL)
        munmap(u->ring, u->ring_cap);
    free(u->steps);
    free(u->snap);
    memset(u, 0, sizeof(*u));
}
static size_t undo_wrap(const undo_t *u, size_t off)
{
    return off >= u->ring_cap ? off - u->ring_cap : off;
}

static void undo_ring_put(undo_t *u, size_t off, const void *src, size_t n)
{
    const size_t first = u->ring_cap - off < n ? u->ring_cap - off : n;
    memcpy(u->ring + off, src, first);
    if (n > first)
        memcpy(u->ring, (const uint8_t *)src + first, n - first);
}

static void undo_ring_get(const undo_t *u, size_t off, void *dst, size_t n)
{
    const size_t first = u->ring_cap - off < n ? u->ring_cap - off : n;
    memcpy(dst, u->ring + off, first);
    if (n > first)
        memcpy((uint8_t *)dst + first, u->ring, n - first);
}

/* Moves n bytes from ring offset src to dst, dst coming before src in ring order. */
static void undo_ring_move(undo_t *u, size_t dst, size_t src, size_t n)
{
    while (n > 0) {
        size_t c = n;
        c = u->ring_cap - dst < c ? u->ring_cap - dst : c;
        c = u->ring_cap - src < c ? u->ring_cap - src : c;
        memmove(u->ring + dst, u->ring + src, c);
        dst = undo_wrap(u, dst + c);
        src = undo_wrap(u, src + c);
        n -= c;
    }
}

/* Ring offset just after the last held step (where a new step starts). */
static size_t undo_head(const undo_t *u)
{
    if (u->nsteps == 0)
        return 0;
    const undo_step_t *s = &u->steps[u->nsteps - 1];
    return undo_wrap(u, s->off + s->len);
}

/* Drops the oldest k steps and the steps joined to the last of them (whole units). */
static void undo_drop_oldest(undo_t *u, size_t k)
{
    while (k > 0 && k < u->nsteps && u->steps[k].joined)
        k++;
    for (size_t i = 0; i < k; i++)
        u->bytes -= u->steps[i].len;
    memmove(u->steps, u->steps + k, (u->nsteps - k) * sizeof(undo_step_t));
    u->nsteps -= k;
    u->done = u->done > k ? u->done - k : 0;
}

/* Drops the redo steps; the open step (which follows them in the ring) moves down over them. */
static void undo_drop_redo(undo_t *u)
{
    if (u->done == u->nsteps)
        return;
    const size_t dst = u->steps[u->done].off;
    const size_t shift = u->cur.off >= dst ? u->cur.off - dst : u->cur.off + u->ring_cap - dst;
    for (size_t i = u->done; i < u->nsteps; i++)
        u->bytes -= u->steps[i].len;
    u->nsteps = u->done;
    undo_ring_move(u, dst, u->cur.off, u->cur.len);
    u->cur.off = dst;
    u->run_off = u->run_off >= shift ? u->run_off - shift : u->run_off + u->ring_cap - shift;
}

/* A larger ring holding only the open step (every older step is already dropped). */
static argil_err_t undo_grow(undo_t *u, size_t need)
{
    size_t cap = 2 * u->ring_cap > need ? 2 * u->ring_cap : need;
    cap = cap < 4096 ? 4096 : cap;
    uint8_t *r = undo_map(cap);
    if (r == NULL)
        return ARGIL_ERR_NOMEM;
    if (u->ring != NULL) {
        undo_ring_get(u, u->cur.off, r, u->cur.len);
        u->run_off = u->run_off >= u->cur.off ? u->run_off - u->cur.off : u->run_off + u->ring_cap - u->cur.off;
        munmap(u->ring, u->ring_cap);
    }
    u->ring = r;
    u->ring_cap = cap;
    u->cur.off = 0;
    return ARGIL_OK;
}

/* Room for k more bytes of the open step: redo steps go first (a step that records anything is
 * a new edit), then the oldest steps; the ring grows only when the open step alone needs it. */
static argil_err_t undo_reserve(undo_t *u, size_t k)
{
    if (u->bytes + u->cur.len + k <= u->ring_cap)
        return ARGIL_OK;
    undo_drop_redo(u);
    size_t drop = 0, held = u->bytes;
    while (drop < u->nsteps && held + u->cur.len + k > u->ring_cap)
        held -= u->steps[drop++].len;
    undo_drop_oldest(u, drop);
    held = u->bytes;
    return held + u->cur.len + k <= u->ring_cap ? ARGIL_OK : undo_grow(u, u->cur.len + k);
}

static void undo_close_run(undo_t *u)
{
    if (u->run.n == 0)
        return;
    undo_ring_put(u, u->run_off, &u->run, sizeof(undo_run_t));
    u->run.n = 0;
}

/* Appends one change to the open step, extending its last run when it continues it along x. */
__attribute__((noinline)) static argil_err_t undo_append(undo_t *u, int store, int ch, const int32_t ijk[3], const float *v)
{
    undo_run_t *r = &u->run;
    const bool extend = r->n > 0 && r->n < UINT16_MAX && r->ijk[0] + (int64_t)r->n == ijk[0] &&
                        r->ijk[1] == ijk[1] && r->ijk[2] == ijk[2] && r->store == store && r->ch == ch;
    const size_t eb = undo_elem_bytes(store), need = extend ? eb : sizeof(undo_run_t) + eb;
    if (!extend)
        undo_close_run(u);
    if (u->bytes + u->cur.len + need > u->ring_cap) {
        const argil_err_t e = undo_reserve(u, need);
        if (e != ARGIL_OK)
            return e;
    }
    if (!extend) {
        u->run_off = undo_wrap(u, u->cur.off + u->cur.len);
        u->cur.len += sizeof(undo_run_t);
        r->store = (uint8_t)store;
        r->ch = (uint8_t)ch;
        memcpy(r->ijk, ijk, sizeof(r->ijk));
    }
    const size_t at = undo_wrap(u, u->cur.off + u->cur.len);
    if (at + eb <= u->ring_cap)
        memcpy(u->ring + at, v, eb);
    else
        undo_ring_put(u, at, v, eb);
    u->cur.len += eb;
    u->cur.n++;
    r->n++;
    return ARGIL_OK;
}

/* The common case of undo_append, small enough to inline: the change continues the open run and
 * the ring has room before its end; eb is 8 or 12 (a constant at each caller). false: not taken. */
static inline bool undo_append_fast(undo_t *u, int store, const int32_t ijk[3], const float *v, size_t eb)
{
    undo_run_t *r = &u->run;
    const size_t at = u->cur.off + u->cur.len;
    if (!(r->n > 0 && r->n < UINT16_MAX && r->ijk[0] + (int64_t)r->n == ijk[0] && r->ijk[1] == ijk[1] &&
          r->ijk[2] == ijk[2] && r->store == store && u->bytes + u->cur.len + eb <= u->ring_cap &&
          at + eb <= u->ring_cap))
        return false;
    memcpy(u->ring + at, v, eb);
    u->cur.len += eb;
    u->cur.n++;
    r->n++;
    return true;
}

argil_err_t undo_note(undo_t *u, int store, int ch, const int32_t ijk[3], float before, float after)
{
    if (!u->open)
        return ARGIL_ERR_STATE;
    if (store != UNDO_STORE_COEF && store != UNDO_STORE_SAMP)
        return ARGIL_ERR_ARG;
    const float v[2] = {before, after};
    if (u->run.ch == ch && undo_append_fast(u, store, ijk, v, sizeof(v)))
        return ARGIL_OK;
    return undo_append(u, store, ch, ijk, v);
}

argil_err_t undo_note_drest(undo_t *u, const int32_t ijk[3], float d_before, float d_after, float rest_before)
{
    if (!u->open)
        return ARGIL_ERR_STATE;
    const float v[3] = {d_before, d_after, rest_before};
    if (u->run.ch == FS_D && undo_append_fast(u, UNDO_STORE_DREST, ijk, v, sizeof(v)))
        return ARGIL_OK;
    return undo_append(u, UNDO_STORE_DREST, FS_D, ijk, v);
}

static size_t undo_box(const int32_t lo[3], const int32_t hi[3], int32_t dims[3])
{
    size_t n = 1;
    for (int a = 0; a < 3; a++) {
        dims[a] = hi[a] > lo[a] ? hi[a] - lo[a] : 0;
        n *= (size_t)dims[a];
    }
    return n;
}

static int undo_popcount(uint32_t m)
{
    int c = 0;
    for (; m; m &= m - 1)
        c++;
    return c;
}

argil_err_t undo_begin(undo_t *u, const field_t *f, const int32_t clo[3], const int32_t chi[3],
                       uint32_t cmask, const int32_t slo[3], const int32_t shi[3], uint32_t smask)
{
    if (u->open)
        return ARGIL_ERR_STATE;
    if ((cmask >> FC_NCH) != 0 || (smask >> FS_NCH) != 0)
        return ARGIL_ERR_ARG;
    const size_t nc = undo_box(clo, chi, u->cdims), ns = undo_box(slo, shi, u->sdims);
    const size_t need = nc * (size_t)undo_popcount(cmask) + ns * (size_t)undo_popcount(smask);
    if (!f32_buf_reserve(&u->snap, &u->snap_cap, need))
        return ARGIL_ERR_NOMEM;
    memcpy(u->clo, clo, sizeof(u->clo));
    memcpy(u->slo, slo, sizeof(u->slo));
    u->cmask = cmask;
    u->smask = smask;
    float *dst = u->snap;
    for (int c = 0; c < FC_NCH; c++)
        if (cmask & (1u << c)) {
            sparse_read_box(&f->coef, c, clo, u->cdims, dst);
            dst += nc;
        }
    for (int c = 0; c < FS_NCH; c++)
        if (smask & (1u << c)) {
            sparse_read_box(&f->samp, c, slo, u->sdims, dst);
            dst += ns;
        }
    u->cur.off = undo_head(u); /* after the redo steps: they stay unless this step records anything */
    u->cur.len = u->cur.n = 0;
    u->cur.lattice_gen = f->lattice_gen;
    u->run.n = 0;
    u->open = true;
    return ARGIL_OK;
}

/* Appends the changes of one channel box to the open step. */
static argil_err_t undo_diff(undo_t *u, const sparse_t *s, int store, int ch, const int32_t lo[3],
                             const int32_t dims[3], const float *before)
{
    const size_t row = (size_t)dims[0];
    float *now = malloc(sizeof(float) * (row ? row : 1));
    if (now == NULL)
        return ARGIL_ERR_NOMEM;
    argil_err_t e = ARGIL_OK;
    for (int32_t z = 0; z < dims[2] && e == ARGIL_OK; z++)
        for (int32_t y = 0; y < dims[1] && e == ARGIL_OK; y++) {
            const int32_t rlo[3] = {lo[0], lo[1] + y, lo[2] + z}, rd[3] = {dims[0], 1, 1};
            sparse_read_box(s, ch, rlo, rd, now);
            const float *b = before + row * ((size_t)y + (size_t)dims[1] * z);
            if (memcmp(b, now, row * sizeof(float)) == 0)
                continue;
            for (int32_t x = 0; x < dims[0] && e == ARGIL_OK; x++) {
                if (memcmp(&b[x], &now[x], sizeof(float)) == 0)
                    continue;
                const int32_t ijk[3] = {lo[0] + x, lo[1] + y, lo[2] + z};
                const float v[2] = {b[x], now[x]};
                e = undo_append(u, store, ch, ijk, v);
            }
        }
    free(now);
    return e;
}

argil_err_t undo_commit(undo_t *u, const field_t *f)
{
    return undo_commit_joined(u, f, false);
}

argil_err_t undo_commit_joined(undo_t *u, const field_t *f, bool joined)
{
    if (!u->open)
        return ARGIL_ERR_STATE;
    const size_t nc = (size_t)u->cdims[0] * u->cdims[1] * u->cdims[2];
    const size_t ns = (size_t)u->sdims[0] * u->sdims[1] * u->sdims[2];
    const float *src = u->snap;
    argil_err_t err = ARGIL_OK;
    for (int c = 0; c < FC_NCH && err == ARGIL_OK; c++)
        if (u->cmask & (1u << c)) {
            err = undo_diff(u, &f->coef, UNDO_STORE_COEF, c, u->clo, u->cdims, src);
            src += nc;
        }
    for (int c = 0; c < FS_NCH && err == ARGIL_OK; c++)
        if (u->smask & (1u << c)) {
            err = undo_diff(u, &f->samp, UNDO_STORE_SAMP, c, u->slo, u->sdims, src);
            src += ns;
        }
    undo_close_run(u);
    u->open = false;
    if (err != ARGIL_OK || u->cur.n == 0)
        return err;
    if (joined && u->done == 0)
        return ARGIL_OK; /* nothing to join: the changes stay, with nothing to take them back */
    undo_drop_redo(u); /* a new edit clears the redo steps */
    if (u->nsteps == u->cap) {
        const size_t ncap = u->cap ? 2 * u->cap : 64;
        undo_step_t *p = realloc(u->steps, ncap * sizeof(undo_step_t));
        if (p == NULL)
            return ARGIL_ERR_NOMEM;
        u->steps = p;
        u->cap = ncap;
    }
    u->cur.joined = joined;
    u->steps[u->nsteps++] = u->cur;
    u->done = u->nsteps;
    u->bytes += u->cur.len;
    /* Oldest units first (a step with the steps joined to it), but always keep the newest
     * unit. */
    size_t drop = 0, held = u->bytes;
    while (held > u->budget_bytes) {
        size_t end = drop + 1, b = u->steps[drop].len;
        while (end < u->nsteps && u->steps[end].joined)
            b += u->steps[end++].len;
        if (end >= u->nsteps)
            break;
        held -= b;
        drop = end;
    }
    undo_drop_oldest(u, drop);
    return ARGIL_OK;
}

/* Writes the before (undo) or after (redo) values of every change of step s into the field. */
static argil_err_t undo_apply(const undo_t *u, field_t *f, const undo_step_t *s, bool forward)
{
    size_t pos = s->off, left = s->len;
    while (left >= sizeof(undo_run_t)) {
        undo_run_t r;
        undo_ring_get(u, pos, &r, sizeof(r));
        pos = undo_wrap(u, pos + sizeof(r));
        left -= sizeof(r);
        sparse_t *st = r.store == UNDO_STORE_COEF ? &f->coef : &f->samp;
        const size_t eb = undo_elem_bytes(r.store);
        for (uint32_t k = 0; k < r.n; k++) {
            float v[3];
            undo_ring_get(u, pos, v, eb);
            pos = undo_wrap(u, pos + eb);
            left -= eb;
            const int32_t x = r.ijk[0] + (int32_t)k;
            argil_err_t e = sparse_set(st, r.ch, x, r.ijk[1], r.ijk[2], forward ? v[1] : v[0]);
            if (e == ARGIL_OK && r.store == UNDO_STORE_DREST) /* the plastic rule, same arithmetic */
                e = sparse_set(st, FS_REST, x, r.ijk[1], r.ijk[2], forward ? v[2] + (v[1] - v[0]) : v[2]);
            if (e != ARGIL_OK)
                return e;
        }
    }
    return ARGIL_OK;
}

size_t undo_units(const undo_t *u, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < n && i < u->nsteps; i++)
        k += !u->steps[i].joined;
    return k;
}

/* The unit holding step i: [*first, *end). */
static void undo_unit_of(const undo_t *u, size_t i, size_t *first, size_t *end)
{
    size_t a = i, b = i + 1;
    while (a > 0 && u->steps[a].joined)
        a--;
    while (b < u->nsteps && u->steps[b].joined)
        b++;
    *first = a;
    *end = b;
}

argil_err_t undo_undo(undo_t *u, field_t *f)
{
    if (u->open)
        return ARGIL_ERR_STATE;
    if (u->done == 0)
        return ARGIL_ERR_EMPTY;
    size_t a, b;
    undo_unit_of(u, u->done - 1, &a, &b);
    for (size_t i = a; i < u->done; i++)
        if (u->steps[i].lattice_gen != f->lattice_gen)
            return ARGIL_ERR_STATE;
    while (u->done > a) {
        const argil_err_t e = undo_apply(u, f, &u->steps[u->done - 1], false);
        if (e != ARGIL_OK)
            return e;
        u->done--;
    }
    return ARGIL_OK;
}

argil_err_t undo_redo(undo_t *u, field_t *f)
{
    if (u->open)
        return ARGIL_ERR_STATE;
    if (u->done == u->nsteps)
        return ARGIL_ERR_EMPTY;
    size_t a, b;
    undo_unit_of(u, u->done, &a, &b);
    for (size_t i = u->done; i < b; i++)
        if (u->steps[i].lattice_gen != f->lattice_gen)
            return ARGIL_ERR_STATE;
    while (u->done < b) {
        const argil_err_t e = undo_apply(u, f, &u->steps[u->done], true);
        if (e != ARGIL_OK)
            return e;
        u->done++;
    }
    return ARGIL_OK;
}

void undo_clear_redo(undo_t *u)
{
    if (u->open || u->done == u->nsteps)
        return;
    u->cur.off = undo_head(u);
    u->cur.len = 0;
    undo_drop_redo(u);
}
