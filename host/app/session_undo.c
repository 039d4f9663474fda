/* Undo and redo in the live session: a shadow of the model at the last stroke boundary, diffed
 * over the blocks the field marked dirty (see session_undo.h). */
#include "host/app/session_undo.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#include "host/solve/gsolve.h"

static float coef_defaults(const field_t *f, int c)
{
    return f->coef.defaults[c];
}

/* An empty shadow with the field's channel defaults. */
static argil_err_t shadow_init(session_undo_t *su, const field_t *f)
{
    float dc[1] = {coef_defaults(f, FC_P)};
    float ds[SESSION_UNDO_SAMP_CH];
    for (int c = 0; c < SESSION_UNDO_SAMP_CH; c++)
        ds[c] = f->samp.defaults[c];
    argil_err_t e = sparse_init(&su->sh_coef, 1, dc);
    if (e != ARGIL_OK)
        return e;
    e = sparse_init(&su->sh_samp, SESSION_UNDO_SAMP_CH, ds);
    if (e != ARGIL_OK)
        sparse_free(&su->sh_coef);
    return e;
}

static void shadow_free(session_undo_t *su)
{
    if (su->sh_ready) {
        sparse_free(&su->sh_coef);
        sparse_free(&su->sh_samp);
    }
    su->sh_ready = false;
}

/* The shadow becomes a copy of the whole field (the start, after a knot insertion); every dirty
 * flag is cleared. */
static argil_err_t shadow_take(session_undo_t *su, field_t *f)
{
    shadow_free(su);
    argil_err_t e = shadow_init(su, f);
    if (e != ARGIL_OK)
        return e;
    su->sh_ready = true;
    su->sh_gen = f->lattice_gen;
    sparse_t *live[2] = {&f->coef, &f->samp}, *sh[2] = {&su->sh_coef, &su->sh_samp};
    for (int k = 0; k < 2; k++) {
        size_t slot = 0;
        for (sparse_block_t *b; (b = sparse_next(live[k], &slot)) != NULL;) {
            sparse_block_t *sb;
            e = sparse_touch(sh[k], b->key, &sb);
            if (e != ARGIL_OK)
                return e;
            memcpy(sb->data, b->data, sizeof(float) * (size_t)sh[k]->nch * SPARSE_BN);
            b->dirty = false;
        }
    }
    return ARGIL_OK;
}

static argil_err_t pool_reserve(session_undo_t *su, size_t n);

static void set_note(session_undo_t *su, const char *msg)
{
    snprintf(su->note, sizeof(su->note), "%s", msg);
}

static void set_off(session_undo_t *su, const char *why)
{
    su->on = false;
    snprintf(su->off_reason, sizeof(su->off_reason), "%s", why);
    set_note(su, why);
}

/* No sealed step pending any more (its undo_t step, if open, is the caller's). */
static void pend_clear(session_undo_t *su)
{
    su->npend = su->pend_next = su->pend_copied = 0;
    su->pool_used = 0;
    su->pend_open = false;
    su->pend_joined = false;
    su->pend_err = ARGIL_OK;
}

/* The history is gone (out of memory while recording): an empty journal again, the shadow a
 * fresh copy. */
static void reset_history(session_undo_t *su, field_t *f)
{
    undo_free(&su->u);
    pend_clear(su);
    su->stats.resets++;
    su->stroke_open = false;
    if (undo_init_lazy(&su->u, su->budget_bytes) != ARGIL_OK || shadow_take(su, f) != ARGIL_OK) {
        undo_free(&su->u);
        shadow_free(su);
        set_off(su, "undo off: out of memory");
        return;
    }
    set_note(su, "undo history lost: out of memory");
}

argil_err_t session_undo_init(session_undo_t *su, const field_t *f, size_t budget_bytes)
{
    memset(su, 0, sizeof(*su));
    su->budget_bytes = budget_bytes;
    if (f == NULL) {
        set_off(su, "undo needs the B-spline model (--global-solve bspline)");
        return ARGIL_OK;
    }
    if (budget_bytes == 0) {
        set_off(su, "undo off (--undo-mb 0)");
        return ARGIL_OK;
    }
    argil_err_t e = undo_init_lazy(&su->u, budget_bytes);
    if (e == ARGIL_OK)
        e = shadow_take(su, (field_t *)f);
    /* Room to copy aside as much as the field holds now and a quarter more (faulted in a chunk per
     * tick, grown with the field: prefault). */
    if (e == ARGIL_OK)
        e = pool_reserve(su, session_undo_shadow_bytes(su) / sizeof(float) * 5 / 4);
    if (e != ARGIL_OK) {
        session_undo_free(su);
        su->budget_bytes = budget_bytes;
        set_off(su, "undo off: out of memory");
        return e;
    }
    su->on = true;
    return ARGIL_OK;
}

void session_undo_free(session_undo_t *su)
{
    undo_free(&su->u);
    shadow_free(su);
    free(su->pend);
    if (su->pool != NULL)
        munmap(su->pool, su->pool_cap * sizeof(float));
    su->pend = NULL;
    su->pool = NULL;
    su->pend_cap = su->pool_cap = su->pool_pf = 0;
    pend_clear(su);
    su->on = false;
}

/* Notes every value of the first sh->nch channels that differs (bit for bit) between src (the
 * block's values, channel-major) and the block's shadow (when note), and copies src into the
 * shadow; *noted gets the changes noted. */
static argil_err_t block_note(session_undo_t *su, int store, const int32_t key[3], const float *src,
                              sparse_t *sh, bool note, size_t *noted)
{
    sparse_block_t *sb;
    argil_err_t e = sparse_touch(sh, key, &sb);
    if (e != ARGIL_OK)
        return e;
    const size_t bytes = sizeof(float) * (size_t)sh->nch * SPARSE_BN, n0 = su->u.cur.n;
    if (note && memcmp(src, sb->data, bytes) != 0)
        for (int c = 0; c < sh->nch && e == ARGIL_OK; c++) {
            const float *now = src + (size_t)c * SPARSE_BN, *was = sb->data + (size_t)c * SPARSE_BN;
            if (memcmp(now, was, sizeof(float) * SPARSE_BN) == 0)
                continue;
            /* Row by row (x fastest), the bits compared as integers. */
            for (int r = 0; r < SPARSE_BN / SPARSE_B && e == ARGIL_OK; r++) {
                const float *nr = now + r * SPARSE_B, *wr = was + r * SPARSE_B;
                if (memcmp(nr, wr, sizeof(float) * SPARSE_B) == 0)
                    continue;
                uint32_t nb[SPARSE_B], wb[SPARSE_B];
                memcpy(nb, nr, sizeof(nb));
                memcpy(wb, wr, sizeof(wb));
                int32_t ijk[3] = {key[0] * SPARSE_B, key[1] * SPARSE_B + r % SPARSE_B,
                                  key[2] * SPARSE_B + r / SPARSE_B};
                for (int x = 0; x < SPARSE_B && e == ARGIL_OK; x++)
                    if (nb[x] != wb[x]) {
                        ijk[0] = key[0] * SPARSE_B + x;
                        e = undo_note(&su->u, store, c, ijk, wr[x], nr[x]);
                    }
            }
        }
    memcpy(sb->data, src, bytes);
    if (noted != NULL)
        *noted = su->u.cur.n - n0;
    return e;
}

/* Notes the live block's changes (when note) and takes it into the shadow, clearing its dirty
 * flag; or (back) copies the shadow into the live block and keeps the flag (dropping drift). */
static argil_err_t block_sync(session_undo_t *su, int store, sparse_block_t *b, sparse_t *sh,
                              bool back, bool note)
{
    if (back) {
        sparse_block_t *sb;
        const argil_err_t e = sparse_touch(sh, b->key, &sb);
        if (e == ARGIL_OK)
            memcpy(b->data, sb->data, sizeof(float) * (size_t)sh->nch * SPARSE_BN);
        return e;
    }
    const argil_err_t e = block_note(su, store, b->key, b->data, sh, note, NULL);
    b->dirty = false;
    return e;
}

/* Walks the field's dirty blocks: back = false: notes (when note) and takes them into the
 * shadow, clearing the flags; back = true: sets them to the shadow. Grows [lo, hi) by the
 * samples of each block (and those its coefficients reach). The first error is returned; the
 * walk goes on, so the shadow ends equal to the field either way. */
static argil_err_t walk_dirty(session_undo_t *su, field_t *f, bool back, bool note, int32_t lo[3],
                              int32_t hi[3])
{
    argil_err_t err = ARGIL_OK;
    sparse_t *live[2] = {&f->coef, &f->samp}, *sh[2] = {&su->sh_coef, &su->sh_samp};
    const int store[2] = {UNDO_STORE_COEF, UNDO_STORE_SAMP};
    for (int k = 0; k < 2; k++) {
        size_t slot = 0;
        for (sparse_block_t *b; (b = sparse_next(live[k], &slot)) != NULL;) {
            if (!b->dirty)
                continue;
            const argil_err_t e = block_sync(su, store[k], b, sh[k], back, note && err == ARGIL_OK);
            if (err == ARGIL_OK)
                err = e;
            int32_t blo[3], bhi[3];
            for (int a = 0; a < 3; a++) {
                blo[a] = b->key[a] * SPARSE_B;
                bhi[a] = blo[a] + SPARSE_B;
            }
            if (k == 0) {
                int32_t slo[3], shi[3];
                field_samples_of_coefs(f, blo, bhi, slo, shi);
                memcpy(blo, slo, sizeof(slo));
                memcpy(bhi, shi, sizeof(shi));
            }
            const bool none = hi[0] <= lo[0];
            for (int a = 0; a < 3; a++) {
                lo[a] = none || blo[a] < lo[a] ? blo[a] : lo[a];
                hi[a] = none || bhi[a] > hi[a] ? bhi[a] : hi[a];
            }
        }
    }
    return err;
}

static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* One session tick's recording work took ms. */
static void tick_work(session_undo_t *su, double ms)
{
    if (ms > su->stats.max_work_ms)
        su->stats.max_work_ms = ms;
    const double bin = ms * 100.0;
    su->stats.work_hist_10us[bin < (double)(SESSION_UNDO_HIST_BINS - 1u)
                                 ? (uint32_t)bin
                                 : SESSION_UNDO_HIST_BINS - 1u]++;
    su->stats.work_ticks++;
}

/* Floats of one block as the shadow of store k holds it. */
static size_t block_floats(const session_undo_t *su, uint32_t k)
{
    return (size_t)(k == 0 ? su->sh_coef.nch : su->sh_samp.nch) * SPARSE_BN;
}

/* The pool holds at least n floats (only grown with nothing pending). */
static argil_err_t pool_reserve(session_undo_t *su, size_t n)
{
    if (n <= su->pool_cap)
        return ARGIL_OK;
    size_t cap = su->pool_cap + su->pool_cap / 2;
    cap = cap > n ? cap : n;
    void *m = mmap(NULL, cap * sizeof(float), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS,
                   -1, 0);
    if (m == MAP_FAILED)
        return ARGIL_ERR_NOMEM;
    if (su->pool != NULL)
        munmap(su->pool, su->pool_cap * sizeof(float));
    su->pool = m;
    su->pool_cap = cap;
    su->pool_pf = 0;
    return ARGIL_OK;
}

/* The step sealed (its slices done): committed; on an error the history goes. */
static argil_err_t pend_commit(session_undo_t *su, field_t *f)
{
    argil_err_t e = su->pend_err;
    const argil_err_t ce = undo_commit_joined(&su->u, f, su->pend_joined);
    if (e == ARGIL_OK)
        e = ce;
    const bool joined = su->pend_joined;
    pend_clear(su);
    if (e != ARGIL_OK) {
        reset_history(su, f);
        return e;
    }
    if (su->u.cur.n > 0 && !joined) {
        su->stats.steps++;
        su->stats.last_step_bytes = su->u.cur.len;
        su->stats.last_step_changes = su->u.cur.n;
        if (su->u.cur.len > su->stats.max_step_bytes)
            su->stats.max_step_bytes = su->u.cur.len;
    }
    return ARGIL_OK;
}

/* What changed since the last boundary (the field's dirty blocks) becomes the pending step: its
 * blocks listed (flags cleared), the step opened; diffed by pend_work. */
static argil_err_t pend_begin(session_undo_t *su, field_t *f, bool joined)
{
    const int32_t z[3] = {0, 0, 0};
    argil_err_t e = undo_begin(&su->u, f, z, z, 0, z, z, 0);
    if (e != ARGIL_OK) {
        reset_history(su, f);
        return e;
    }
    pend_clear(su);
    su->pend_open = true;
    su->pend_joined = joined;
    sparse_t *live[2] = {&f->coef, &f->samp};
    size_t need_blocks = 0, need_floats = 0;
    for (uint32_t k = 0; k < 2; k++) {
        size_t slot = 0;
        for (const sparse_block_t *b; (b = sparse_next(live[k], &slot)) != NULL;)
            if (b->dirty) {
                need_blocks++;
                need_floats += block_floats(su, k);
            }
    }
    if (need_blocks > su->pend_cap) {
        const size_t cap = need_blocks + need_blocks / 2 + 64;
        session_undo_pend_t *np = realloc(su->pend, cap * sizeof(*np));
        if (np == NULL) {
            reset_history(su, f);
            return ARGIL_ERR_NOMEM;
        }
        su->pend = np;
        su->pend_cap = cap;
    }
    if (pool_reserve(su, need_floats) != ARGIL_OK) {
        reset_history(su, f);
        return ARGIL_ERR_NOMEM;
    }
    for (uint32_t k = 0; k < 2; k++) {
        size_t slot = 0;
        for (sparse_block_t *b; (b = sparse_next(live[k], &slot)) != NULL;) {
            if (!b->dirty)
                continue;
            session_undo_pend_t *q = &su->pend[su->npend++];
            memcpy(q->key, b->key, sizeof(q->key));
            q->store = k;
            q->copy = 0;
            b->dirty = false; /* a write from now on belongs to the next stroke */
        }
    }
    return su->npend == 0 ? pend_commit(su, f) : ARGIL_OK;
}

/* Diffs pending blocks: at most about max_values changes and max_blocks blocks (SIZE_MAX: all),
 * committing the step after the last. */
static argil_err_t pend_work(session_undo_t *su, field_t *f, size_t max_values, size_t max_blocks)
{
    if (!su->pend_open)
        return ARGIL_OK;
    sparse_t *live[2] = {&f->coef, &f->samp}, *sh[2] = {&su->sh_coef, &su->sh_samp};
    const int store[2] = {UNDO_STORE_COEF, UNDO_STORE_SAMP};
    size_t values = 0, blocks = 0;
    while (su->pend_next < su->npend && values < max_values && blocks < max_blocks) {
        const session_undo_pend_t *q = &su->pend[su->pend_next++];
        const float *src;
        if (q->copy != 0) {
            src = su->pool + (q->copy - 1);
        } else {
            const sparse_block_t *b = sparse_find(live[q->store], q->key);
            if (b == NULL)
                continue; /* blocks are never taken out of the field but by a refine */
            src = b->data;
        }
        size_t noted = 0;
        /* A block new to the shadow is allocated and first touched: ~0.1 ms here. */
        const bool fresh = sparse_find(sh[q->store], q->key) == NULL;
        const argil_err_t e = block_note(su, store[q->store], q->key, src, sh[q->store],
                                         su->pend_err == ARGIL_OK, &noted);
        if (su->pend_err == ARGIL_OK)
            su->pend_err = e;
        values += noted + (fresh ? SESSION_UNDO_SLICE_VALUES / 2 : 0);
        blocks++;
    }
    if (su->pend_next < su->npend)
        return ARGIL_OK;
    return pend_commit(su, f);
}

argil_err_t session_undo_finish(session_undo_t *su, field_t *f)
{
    return su->on ? pend_work(su, f, SIZE_MAX, SIZE_MAX) : ARGIL_OK;
}

/* Copies aside pending blocks not yet diffed nor copied, up to max_bytes (SIZE_MAX: all);
 * true when none is left to copy. */
static bool pend_copy(session_undo_t *su, field_t *f, size_t max_bytes)
{
    sparse_t *live[2] = {&f->coef, &f->samp};
    size_t bytes = 0;
    for (; su->pend_copied < su->npend; su->pend_copied++) {
        session_undo_pend_t *q = &su->pend[su->pend_copied];
        if (su->pend_copied < su->pend_next || q->copy != 0)
            continue;
        const size_t n = block_floats(su, q->store);
        if (bytes >= max_bytes)
            return false;
        const sparse_block_t *b = sparse_find(live[q->store], q->key);
        if (b == NULL)
            continue;
        memcpy(su->pool + su->pool_used, b->data, n * sizeof(float));
        q->copy = su->pool_used + 1;
        su->pool_used += n;
        bytes += n * sizeof(float);
        su->stats.copied_blocks++;
    }
    return true;
}

bool session_undo_slice(session_undo_t *su, field_t *f)
{
    if (!su->on || !su->pend_open)
        return false;
    su->stats.slices++;
    /* Copying aside first (about 20 times faster a block than the diff), so that the next
     * write's copy (session_undo_before_write) is short; then the diff. */
    if (pend_copy(su, f, SESSION_UNDO_SLICE_COPY_BYTES))
        (void)pend_work(su, f, SESSION_UNDO_SLICE_VALUES, SESSION_UNDO_SLICE_BLOCKS);
    return su->pend_open;
}

void session_undo_before_write(session_undo_t *su, field_t *f)
{
    if (su->on && su->pend_open)
        (void)pend_copy(su, f, SIZE_MAX);
}

/* The shadow is on another lattice after a knot insertion: taken again (the history before it
 * is cut: undo_undo refuses those steps). A pending step was copied aside before the refine
 * (session_undo_edit_start) and is finished on the old lattice first. */
static void follow_lattice(session_undo_t *su, field_t *f)
{
    if (!su->on || su->sh_gen == f->lattice_gen)
        return;
    if (su->pend_open) {
        bool all_copied = true;
        for (size_t i = su->pend_next; i < su->npend; i++)
            all_copied = all_copied && su->pend[i].copy != 0;
        if (!all_copied || session_undo_finish(su, f) != ARGIL_OK) {
            if (su->on && su->pend_open)
                reset_history(su, f);
            return;
        }
    }
    su->stroke_open = false;
    if (shadow_take(su, f) != ARGIL_OK)
        reset_history(su, f);
}

/* A stroke begins (real: an edit; else a press, real once touched). */
static argil_err_t stroke_begin(session_undo_t *su, field_t *f, bool real)
{
    if (!su->on)
        return ARGIL_OK;
    follow_lattice(su, f);
    if (!su->on)
        return ARGIL_ERR_NOMEM;
    argil_err_t e = session_undo_finish(su, f); /* an earlier step still pending */
    if (e != ARGIL_OK)
        return e;
    if (!su->stroke_open) {
        /* The first stroke since the start or an undo or redo: the redo steps go; the drift
         * since joins it. */
        undo_clear_redo(&su->u);
        su->stroke_open = true;
        su->stroke_real = real;
        su->stroke_after_drift = true;
        return ARGIL_OK;
    }
    if (!su->stroke_real) {
        su->stats.air_presses++;
        if (su->stroke_after_drift) {
            /* A press in the air after an undo or redo: no boundary; the new stroke goes on
             * from the same base. */
            su->stroke_real = real;
            return ARGIL_OK;
        }
    }
    /* The open stroke is sealed: one step, or joined to the step before (it changed nothing). */
    e = pend_begin(su, f, !su->stroke_real);
    su->stroke_real = real;
    su->stroke_after_drift = false;
    return e;
}

argil_err_t session_undo_edit_start(session_undo_t *su, field_t *f)
{
    const double t0 = cpu_ms();
    const argil_err_t e = stroke_begin(su, f, true);
    session_undo_before_write(su, f); /* the edit writes at once */
    if (su->on)
        tick_work(su, cpu_ms() - t0);
    return e;
}

argil_err_t session_undo_press(session_undo_t *su, field_t *f)
{
    return stroke_begin(su, f, false);
}

void session_undo_touched(session_undo_t *su)
{
    if (su->stroke_open)
        su->stroke_real = true;
}

/* Zeroes every coefficient velocity: a restored state is at rest. */
static void zero_velocity(field_t *f)
{
    size_t slot = 0;
    for (sparse_block_t *b; (b = sparse_next(&f->coef, &slot)) != NULL;)
        memset(b->data + (size_t)FC_V * SPARSE_BN, 0, sizeof(float) * SPARSE_BN);
}

argil_err_t session_undo_step(session_undo_t *su, field_t *f, bool redo, int32_t slo[3],
                              int32_t shi[3])
{
    for (int a = 0; a < 3; a++)
        slo[a] = shi[a] = 0;
    if (!su->on)
        return ARGIL_ERR_ARG;
    follow_lattice(su, f);
    if (!su->on)
        return ARGIL_ERR_NOMEM;
    const double t0 = cpu_ms();
    argil_err_t e = session_undo_finish(su, f);
    if (e != ARGIL_OK)
        return e;
    if (su->stroke_open) {
        /* The open stroke becomes a step (joined to the one before when it changed nothing);
         * a press in the air after an undo or redo left drift only. */
        if (su->stroke_real || !su->stroke_after_drift) {
            e = pend_begin(su, f, !su->stroke_real);
            if (e == ARGIL_OK)
                e = session_undo_finish(su, f);
            if (e != ARGIL_OK)
                return e;
        }
        su->stroke_open = false;
    }
    const undo_t *u = &su->u;
    if (redo ? u->done == u->nsteps : u->done == 0)
        return ARGIL_ERR_EMPTY;
    if (u->steps[redo ? u->done : u->done - 1].lattice_gen != f->lattice_gen)
        return ARGIL_ERR_STATE;
    int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    /* Drop the drift since the last boundary (the stroke, if any, is recorded already). */
    (void)walk_dirty(su, f, true, false, lo, hi);
    e = redo ? undo_redo(&su->u, f) : undo_undo(&su->u, f);
    /* The step's blocks (and the drift's) into the shadow; on an error the field holds part
     * of the step, which the shadow then holds too (the history goes). */
    const argil_err_t we = walk_dirty(su, f, false, false, lo, hi);
    if (e == ARGIL_OK)
        e = we;
    zero_velocity(f);
    const double ms = cpu_ms() - t0;
    if (ms > su->stats.max_request_ms)
        su->stats.max_request_ms = ms;
    if (e != ARGIL_OK) {
        reset_history(su, f);
        return e;
    }
    if (redo)
        su->stats.redos++;
    else
        su->stats.undos++;
    memcpy(slo, lo, sizeof(lo));
    memcpy(shi, hi, sizeof(hi));
    return ARGIL_OK;
}

size_t session_undo_undo_count(const session_undo_t *su)
{
    if (!su->on)
        return 0;
    return undo_units(&su->u, su->u.done) + (su->pend_open && !su->pend_joined ? 1u : 0u) +
           (su->stroke_open && su->stroke_real ? 1u : 0u);
}

size_t session_undo_redo_count(const session_undo_t *su)
{
    return su->on ? undo_units(&su->u, su->u.nsteps) - undo_units(&su->u, su->u.done) : 0;
}

double session_undo_work_median_ms(const session_undo_t *su)
{
    uint32_t c = 0;
    for (uint32_t i = 0; i < SESSION_UNDO_HIST_BINS; i++) {
        c += su->stats.work_hist_10us[i];
        if (2u * c >= su->stats.work_ticks && c > 0)
            return (double)i * 0.01;
    }
    return 0.0;
}

size_t session_undo_bytes(const session_undo_t *su)
{
    return su->u.bytes;
}

size_t session_undo_shadow_bytes(const session_undo_t *su)
{
    return su->sh_ready ? sparse_bytes(&su->sh_coef) + sparse_bytes(&su->sh_samp) : 0;
}

/* ---- the session ---- */

session_undo_cmd_t session_undo_feed(session_undo_lines_t *l, char c)
{
    if (c != '\n') {
        if (l->len < sizeof(l->buf))
            l->buf[l->len++] = c;
        else
            l->overlong = true;
        return SESSION_UNDO_CMD_NONE;
    }
    size_t a = 0, b = l->len;
    while (a < b && (l->buf[a] == ' ' || l->buf[a] == '\t' || l->buf[a] == '\r'))
        a++;
    while (b > a && (l->buf[b - 1] == ' ' || l->buf[b - 1] == '\t' || l->buf[b - 1] == '\r'))
        b--;
    const bool overlong = l->overlong;
    l->len = 0;
    l->overlong = false;
    if (!overlong && b - a == 4 && memcmp(l->buf + a, "undo", 4) == 0)
        return SESSION_UNDO_CMD_UNDO;
    if (!overlong && b - a == 4 && memcmp(l->buf + a, "redo", 4) == 0)
        return SESSION_UNDO_CMD_REDO;
    if (!overlong && b == a)
        return SESSION_UNDO_CMD_NONE;
    size_t n = 0;
    for (size_t i = a; i < b; i++)
        l->bad[n++] = l->buf[i] >= 0x20 && l->buf[i] < 0x7f ? l->buf[i] : '?';
    if (overlong) {
        memcpy(l->bad + n, "...", 3);
        n += 3;
    }
    l->bad[n] = '\0';
    return SESSION_UNDO_CMD_BAD;
}

bool session_undo_request(session_undo_t *su, session_undo_op_t op, int line)
{
    if (su->nq == SESSION_UNDO_QUEUE) {
        set_note(su, "undo: too many requests waiting");
        return false;
    }
    su->q[su->nq].op = op;
    su->q[su->nq].line = line;
    su->nq++;
    return true;
}

static bool host_pressed(const peer_t *p)
{
    return p->have_tm && (p->last_tm.buttons & 1u) != 0;
}

/* One chunk of the ring written with zeros, up to SESSION_UNDO_PREFAULT_AHEAD beyond the
 * furthest the steps ever reached: the steps are appended at the head and only wrap round after
 * reaching the ring's end, so no held byte lies there (between boundaries no step is open).
 * With nothing pending, the copy pool likewise (copying aside then pays no page faults). */
static void prefault(session_undo_t *su)
{
    /* The pool follows the field: room for every block it holds and a quarter more. */
    const size_t sh_floats = session_undo_shadow_bytes(su) / sizeof(float);
    if (!su->pend_open && su->pool_cap < sh_floats)
        (void)pool_reserve(su, sh_floats + sh_floats / 4);
    if (!su->pend_open && su->pool_pf < su->pool_cap) {
        const size_t n = su->pool_cap - su->pool_pf < SESSION_UNDO_PREFAULT_CHUNK / sizeof(float)
                             ? su->pool_cap - su->pool_pf
                             : SESSION_UNDO_PREFAULT_CHUNK / sizeof(float);
        memset(su->pool + su->pool_pf, 0, n * sizeof(float));
        su->pool_pf += n;
        return;
    }
    const undo_t *u = &su->u;
    if (u->ring == NULL)
        return;
    if (u->ring != su->pf_ring) {
        su->pf_ring = u->ring;
        su->pf_off = su->pf_head_max = 0;
    }
    const undo_step_t *last = u->nsteps ? &u->steps[u->nsteps - 1] : NULL;
    size_t head = last ? last->off + last->len : 0;
    head = head > u->ring_cap ? u->ring_cap : head; /* wrapped: every page was written */
    if (head > su->pf_head_max)
        su->pf_head_max = head;
    const size_t target = u->ring_cap - su->pf_head_max < SESSION_UNDO_PREFAULT_AHEAD
                              ? u->ring_cap
                              : su->pf_head_max + SESSION_UNDO_PREFAULT_AHEAD;
    const size_t page = 4096, from = (su->pf_head_max + page - 1) / page * page;
    if (su->pf_off < from)
        su->pf_off = from; /* the steps wrote those pages themselves */
    if (u->open || su->pf_off >= target)
        return;
    const size_t n = target - su->pf_off < SESSION_UNDO_PREFAULT_CHUNK ? target - su->pf_off
                                                                      : SESSION_UNDO_PREFAULT_CHUNK;
    memset(su->u.ring + su->pf_off, 0, n);
    su->pf_off += n;
}

void session_undo_observe(session_undo_t *su, peer_t *p, uint32_t dt_us)
{
    if (!su->on || p->gs == NULL)
        return;
    field_t *f = &p->gs->field;
    const double t0 = cpu_ms();
    const bool had_work = su->pend_open;
    follow_lattice(su, f);
    if (su->stroke_open && !su->stroke_real &&
        (p->stats.impulse_total_ns != su->press_impulse_ns ||
         p->stats.host_tool_edits != su->press_host_edits))
        session_undo_touched(su);
    const bool pressed = host_pressed(p);
    bool worked = had_work;
    if (pressed && !su->pressed) {
        su->press_impulse_ns = p->stats.impulse_total_ns;
        su->press_host_edits = p->stats.host_tool_edits;
        (void)session_undo_press(su, f);
        worked = true;
    }
    su->pressed = pressed;
    if (!su->on)
        return;
    if (peer_solve_due(p, dt_us))
        session_undo_before_write(su, f); /* the solve writes the field next */
    else if (!session_undo_slice(su, f) && !worked)
        prefault(su);
    if (worked)
        tick_work(su, cpu_ms() - t0);
}

void session_undo_peer_edit_start(session_undo_t *su, peer_t *p)
{
    if (su->on && p->gs != NULL)
        (void)session_undo_edit_start(su, &p->gs->field);
}

session_undo_result_t session_undo_process(session_undo_t *su, peer_t *p, bool hand_pressed,
                                           bool solved, int *line, char *msg, size_t msg_len)
{
    *line = 0;
    if (msg_len > 0)
        msg[0] = '\0';
    if (su->nq == 0)
        return SESSION_UNDO_NONE;
    const bool redo = su->q[0].op == SESSION_UNDO_OP_REDO;
    const char *verb = redo ? "redo" : "undo";
    *line = su->q[0].line;
    session_undo_result_t r = SESSION_UNDO_REFUSED;
    if (!su->on) {
        snprintf(msg, msg_len, "%s refused: %s", verb, su->off_reason);
    } else if (hand_pressed) {
        snprintf(msg, msg_len, "%s refused: button 1 is held (release it first)", verb);
    } else if (host_pressed(p) || !solved) {
        return SESSION_UNDO_WAIT;
    } else if (su->pend_open || su->stroke_open) {
        /* The open stroke is sealed here and diffed a slice a tick like any other (what the
         * solver changes meanwhile is drift, dropped by the undo); the request waits for it. */
        if (!su->pend_open) {
            if (su->stroke_real || !su->stroke_after_drift)
                (void)pend_begin(su, &p->gs->field, !su->stroke_real);
            su->stroke_open = false;
        }
        if (su->pend_open)
            return SESSION_UNDO_WAIT;
        return session_undo_process(su, p, hand_pressed, solved, line, msg, msg_len);
    } else {
        int32_t lo[3], hi[3], glo[3], ghi[3];
        argil_err_t e = session_undo_step(su, &p->gs->field, redo, lo, hi);
        if (e == ARGIL_OK)
            e = gsolve_restored(p->gs, p->grid, lo, hi, glo, ghi);
        if (e == ARGIL_OK) {
            peer_model_restored(p, glo, ghi);
            r = SESSION_UNDO_DONE;
            snprintf(msg, msg_len, "%s", redo ? "redone" : "undone");
        } else {
            snprintf(msg, msg_len, "%s refused: %s", verb,
                     e == ARGIL_ERR_EMPTY ? (redo ? "nothing to redo" : "nothing to undo")
                     : e == ARGIL_ERR_STATE ? "history cut at the knot refinement"
                                            : "out of memory (the history is lost)");
        }
    }
    if (r == SESSION_UNDO_REFUSED)
        su->stats.refused++;
    set_note(su, msg);
    su->nq--;
    memmove(su->q, su->q + 1, (size_t)su->nq * sizeof(su->q[0]));
    return r;
}
