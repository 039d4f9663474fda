/* Undo and redo in the live session: a shadow of the model at the last stroke boundary, diffed
 * over the blocks the field marked dirty (see session_undo.h). */
#include "host/app/session_undo.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "host/app/global_solve.h"

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
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < live[k]->cap; i++) {
            sparse_block_t *b = &live[k]->slots[i];
            if (b->data == NULL)
                continue;
            sparse_block_t *sb;
            e = sparse_touch(sh[k], b->key, &sb);
            if (e != ARGIL_OK)
                return e;
            memcpy(sb->data, b->data, sizeof(float) * (size_t)sh[k]->nch * SPARSE_BN);
            b->dirty = false;
        }
    return ARGIL_OK;
}

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

/* The history is gone (out of memory while recording): an empty journal again, the shadow a
 * fresh copy. */
static void reset_history(session_undo_t *su, field_t *f)
{
    undo_free(&su->u);
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
    su->on = false;
}

/* Notes every value of the first nch channels that differs (bit for bit) between the live block
 * and its shadow, copies it into the shadow and clears the dirty flag; or (back) copies the
 * shadow into the live block and keeps the flag (dropping drift). */
static argil_err_t block_sync(session_undo_t *su, int store, sparse_block_t *b, sparse_t *sh,
                              bool back, bool note)
{
    sparse_block_t *sb;
    argil_err_t e = sparse_touch(sh, b->key, &sb);
    if (e != ARGIL_OK)
        return e;
    const size_t bytes = sizeof(float) * (size_t)sh->nch * SPARSE_BN;
    if (back) {
        memcpy(b->data, sb->data, bytes);
        return ARGIL_OK;
    }
    if (note && memcmp(b->data, sb->data, bytes) != 0)
        for (int c = 0; c < sh->nch && e == ARGIL_OK; c++) {
            const float *now = b->data + (size_t)c * SPARSE_BN, *was = sb->data + (size_t)c * SPARSE_BN;
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
                int32_t ijk[3] = {b->key[0] * SPARSE_B, b->key[1] * SPARSE_B + r % SPARSE_B,
                                  b->key[2] * SPARSE_B + r / SPARSE_B};
                for (int x = 0; x < SPARSE_B && e == ARGIL_OK; x++)
                    if (nb[x] != wb[x]) {
                        ijk[0] = b->key[0] * SPARSE_B + x;
                        e = undo_note(&su->u, store, c, ijk, wr[x], nr[x]);
                    }
            }
        }
    memcpy(sb->data, b->data, bytes);
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
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < live[k]->cap; i++) {
            sparse_block_t *b = &live[k]->slots[i];
            if (b->data == NULL || !b->dirty)
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
    return err;
}

/* The shadow is on another lattice after a knot insertion: taken again (the history before it
 * is cut: undo_undo refuses those steps). */
static void follow_lattice(session_undo_t *su, field_t *f)
{
    if (!su->on || su->sh_gen == f->lattice_gen)
        return;
    su->stroke_open = false;
    if (shadow_take(su, f) != ARGIL_OK)
        reset_history(su, f);
}

static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void work_done(session_undo_t *su, double t0_ms)
{
    const double ms = cpu_ms() - t0_ms;
    if (ms > su->stats.max_work_ms)
        su->stats.max_work_ms = ms;
}

/* What changed since the last boundary becomes one step. */
static argil_err_t commit(session_undo_t *su, field_t *f)
{
    const int32_t z[3] = {0, 0, 0};
    int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    argil_err_t e = undo_begin(&su->u, f, z, z, 0, z, z, 0);
    const argil_err_t we = walk_dirty(su, f, false, e == ARGIL_OK, lo, hi);
    if (e == ARGIL_OK)
        e = we;
    const argil_err_t ce = undo_commit(&su->u, f);
    if (e == ARGIL_OK)
        e = ce;
    if (e != ARGIL_OK) {
        reset_history(su, f);
        return e;
    }
    if (su->u.cur.n > 0) {
        su->stats.steps++;
        su->stats.last_step_bytes = su->u.cur.len;
        su->stats.last_step_changes = su->u.cur.n;
        if (su->u.cur.len > su->stats.max_step_bytes)
            su->stats.max_step_bytes = su->u.cur.len;
    }
    return ARGIL_OK;
}

argil_err_t session_undo_edit_start(session_undo_t *su, field_t *f)
{
    if (!su->on)
        return ARGIL_OK;
    follow_lattice(su, f);
    if (!su->on)
        return ARGIL_ERR_NOMEM;
    if (!su->stroke_open) {
        /* The first stroke since the start or an undo or redo: the redo steps go; the drift
         * since joins it. */
        undo_clear_redo(&su->u);
        su->stroke_open = true;
        return ARGIL_OK;
    }
    const double t0 = cpu_ms();
    const argil_err_t e = commit(su, f);
    work_done(su, t0);
    return e;
}

/* Zeroes every coefficient velocity: a restored state is at rest. */
static void zero_velocity(field_t *f)
{
    for (size_t i = 0; i < f->coef.cap; i++) {
        float *d = f->coef.slots[i].data;
        if (d != NULL)
            memset(d + (size_t)FC_V * SPARSE_BN, 0, sizeof(float) * SPARSE_BN);
    }
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
    if (su->stroke_open) {
        const argil_err_t e = commit(su, f);
        if (e != ARGIL_OK)
            return e;
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
    argil_err_t e = redo ? undo_redo(&su->u, f) : undo_undo(&su->u, f);
    /* The step's blocks (and the drift's) into the shadow; on an error the field holds part
     * of the step, which the shadow then holds too (the history goes). */
    const argil_err_t we = walk_dirty(su, f, false, false, lo, hi);
    if (e == ARGIL_OK)
        e = we;
    zero_velocity(f);
    work_done(su, t0);
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
    return su->on ? su->u.done + (su->stroke_open ? 1u : 0u) : 0;
}

size_t session_undo_redo_count(const session_undo_t *su)
{
    return su->on ? su->u.nsteps - su->u.done : 0;
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
 * reaching the ring's end, so no held byte lies there (between boundaries no step is open). */
static void prefault(session_undo_t *su)
{
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

void session_undo_observe(session_undo_t *su, peer_t *p)
{
    if (!su->on || p->gs == NULL)
        return;
    prefault(su);
    field_t *f = &p->gs->field;
    follow_lattice(su, f);
    const bool pressed = host_pressed(p);
    if (pressed && !su->pressed)
        (void)session_undo_edit_start(su, f);
    su->pressed = pressed;
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
