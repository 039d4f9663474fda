/* Snapshot-and-diff journal over the sparse field's boxes. */
#include "host/model/undo.h"

#include <stdlib.h>
#include <string.h>

void undo_init(undo_t *u, size_t budget_bytes)
{
    memset(u, 0, sizeof(*u));
    u->budget_bytes = budget_bytes;
}

static void undo_drop_step(undo_step_t *s)
{
    free(s->e);
    s->e = NULL;
    s->n = 0;
}

void undo_free(undo_t *u)
{
    for (size_t i = 0; i < u->nsteps; i++)
        undo_drop_step(&u->steps[i]);
    free(u->steps);
    free(u->snap);
    free(u->pend);
    memset(u, 0, sizeof(*u));
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
    if (need > u->snap_cap) {
        float *p = realloc(u->snap, need * sizeof(float));
        if (p == NULL)
            return ARGIL_ERR_NOMEM;
        u->snap = p;
        u->snap_cap = need;
    }
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
    u->npend = 0;
    u->open = true;
    return ARGIL_OK;
}

/* Appends one entry to a growing array. */
static argil_err_t undo_push(undo_entry_t **e, size_t *n, size_t *cap, int store, int ch,
                             const int32_t ijk[3], float before, float after)
{
    if (*n == *cap) {
        const size_t nc = *cap ? 2 * *cap : 256;
        undo_entry_t *p = realloc(*e, nc * sizeof(undo_entry_t));
        if (p == NULL)
            return ARGIL_ERR_NOMEM;
        *e = p;
        *cap = nc;
    }
    undo_entry_t *en = &(*e)[(*n)++];
    en->store = (uint8_t)store;
    en->ch = (uint8_t)ch;
    memcpy(en->ijk, ijk, sizeof(en->ijk));
    en->before = before;
    en->after = after;
    return ARGIL_OK;
}

argil_err_t undo_note(undo_t *u, int store, int ch, const int32_t ijk[3], float before, float after)
{
    if (!u->open)
        return ARGIL_ERR_STATE;
    return undo_push(&u->pend, &u->npend, &u->pend_cap, store, ch, ijk, before, after);
}

/* Appends the entries of one channel box whose value changed; grows *e as needed. */
static argil_err_t undo_diff(const sparse_t *s, int store, int ch, const int32_t lo[3],
                             const int32_t dims[3], const float *before, undo_entry_t **e,
                             size_t *n, size_t *cap)
{
    const size_t row = (size_t)dims[0];
    float *now = malloc(sizeof(float) * (row ? row : 1));
    if (now == NULL)
        return ARGIL_ERR_NOMEM;
    for (int32_t z = 0; z < dims[2]; z++)
        for (int32_t y = 0; y < dims[1]; y++) {
            const int32_t rlo[3] = {lo[0], lo[1] + y, lo[2] + z}, rd[3] = {dims[0], 1, 1};
            sparse_read_box(s, ch, rlo, rd, now);
            const float *b = before + row * ((size_t)y + (size_t)dims[1] * z);
            if (memcmp(b, now, row * sizeof(float)) == 0)
                continue;
            for (int32_t x = 0; x < dims[0]; x++) {
                if (memcmp(&b[x], &now[x], sizeof(float)) == 0)
                    continue;
                const int32_t ijk[3] = {lo[0] + x, lo[1] + y, lo[2] + z};
                if (undo_push(e, n, cap, store, ch, ijk, b[x], now[x]) != ARGIL_OK) {
                    free(now);
                    return ARGIL_ERR_NOMEM;
                }
            }
        }
    free(now);
    return ARGIL_OK;
}

argil_err_t undo_commit(undo_t *u, const field_t *f)
{
    if (!u->open)
        return ARGIL_ERR_STATE;
    u->open = false;
    undo_entry_t *e = u->pend; /* the noted entries first, then the snapshot diffs */
    size_t n = u->npend, cap = u->pend_cap;
    const size_t nc = (size_t)u->cdims[0] * u->cdims[1] * u->cdims[2];
    const size_t ns = (size_t)u->sdims[0] * u->sdims[1] * u->sdims[2];
    const float *src = u->snap;
    argil_err_t err = ARGIL_OK;
    for (int c = 0; c < FC_NCH && err == ARGIL_OK; c++)
        if (u->cmask & (1u << c)) {
            err = undo_diff(&f->coef, UNDO_STORE_COEF, c, u->clo, u->cdims, src, &e, &n, &cap);
            src += nc;
        }
    for (int c = 0; c < FS_NCH && err == ARGIL_OK; c++)
        if (u->smask & (1u << c)) {
            err = undo_diff(&f->samp, UNDO_STORE_SAMP, c, u->slo, u->sdims, src, &e, &n, &cap);
            src += ns;
        }
    u->pend = e; /* the working buffer stays warm for the next step */
    u->pend_cap = cap;
    u->npend = 0;
    if (err != ARGIL_OK || n == 0)
        return err;
    e = malloc(n * sizeof(undo_entry_t)); /* the step holds exactly its entries */
    if (e == NULL)
        return ARGIL_ERR_NOMEM;
    memcpy(e, u->pend, n * sizeof(undo_entry_t));
    for (size_t i = u->done; i < u->nsteps; i++) { /* a new edit clears the redo steps */
        u->bytes -= u->steps[i].n * sizeof(undo_entry_t);
        undo_drop_step(&u->steps[i]);
    }
    u->nsteps = u->done;
    if (u->nsteps == u->cap) {
        const size_t ncap = u->cap ? 2 * u->cap : 64;
        undo_step_t *p = realloc(u->steps, ncap * sizeof(undo_step_t));
        if (p == NULL) {
            free(e);
            return ARGIL_ERR_NOMEM;
        }
        u->steps = p;
        u->cap = ncap;
    }
    u->steps[u->nsteps].e = e;
    u->steps[u->nsteps].n = n;
    u->nsteps++;
    u->done = u->nsteps;
    u->bytes += n * sizeof(undo_entry_t);
    size_t drop = 0; /* oldest first, but always keep the newest step */
    while (u->bytes > u->budget_bytes && drop + 1 < u->nsteps) {
        u->bytes -= u->steps[drop].n * sizeof(undo_entry_t);
        undo_drop_step(&u->steps[drop]);
        drop++;
    }
    if (drop > 0) {
        memmove(u->steps, u->steps + drop, (u->nsteps - drop) * sizeof(undo_step_t));
        u->nsteps -= drop;
        u->done -= drop;
    }
    return ARGIL_OK;
}

static argil_err_t undo_apply(field_t *f, const undo_step_t *s, bool forward)
{
    for (size_t k = 0; k < s->n; k++) {
        const undo_entry_t *en = &s->e[forward ? k : s->n - 1 - k];
        sparse_t *st = en->store == UNDO_STORE_COEF ? &f->coef : &f->samp;
        argil_err_t e = sparse_set(st, en->ch, en->ijk[0], en->ijk[1], en->ijk[2],
                                   forward ? en->after : en->before);
        if (e != ARGIL_OK)
            return e;
    }
    return ARGIL_OK;
}

argil_err_t undo_undo(undo_t *u, field_t *f)
{
    if (u->open)
        return ARGIL_ERR_STATE;
    if (u->done == 0)
        return ARGIL_ERR_EMPTY;
    argil_err_t e = undo_apply(f, &u->steps[u->done - 1], false);
    if (e == ARGIL_OK)
        u->done--;
    return e;
}

argil_err_t undo_redo(undo_t *u, field_t *f)
{
    if (u->open)
        return ARGIL_ERR_STATE;
    if (u->done == u->nsteps)
        return ARGIL_ERR_EMPTY;
    argil_err_t e = undo_apply(f, &u->steps[u->done], true);
    if (e == ARGIL_OK)
        u->done++;
    return e;
}
