/* Expectations decided from recorded CAN frames and DRIVE_ENABLE edges (see hil_check.h). */
#include "hil_check.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/argil_limits.h"
#include "shared/hex_digit.h"
#include "sim/scn_clock.h"

#define ERR_FLAG 0x20000000u   /* <linux/can.h> CAN_ERR_FLAG */

void hil_obs_init(hil_obs_t *o)
{
    memset(o, 0, sizeof(*o));
    o->heartbeat_ticks = ARGIL_DRIVE_HEARTBEAT_CONSUMER_US / HIL_TICK_US;
}

void hil_obs_free(hil_obs_t *o)
{
    free(o->frame);
    free(o->gpio);
    hil_obs_init(o);
}

hil_err_t hil_obs_push_frame(hil_obs_t *o, int64_t t_us, const can_frame_t *f)
{
    if (o->n_frames == o->cap_frames) {
        const size_t cap = o->cap_frames ? o->cap_frames * 2u : 4096u;
        hil_frame_t *p = realloc(o->frame, cap * sizeof(*p));
        if (p == NULL)
            return HIL_ERR_MEMORY;
        o->frame = p;
        o->cap_frames = cap;
    }
    o->frame[o->n_frames].t_us = t_us;
    o->frame[o->n_frames].f = *f;
    o->n_frames++;
    if (scn_clock_is_tick(f))
        o->n_syncs++;
    return HIL_OK;
}

hil_err_t hil_obs_push_gpio(hil_obs_t *o, int64_t t_us, bool drive_enable)
{
    return hil_obs_push_gpio_sampled(o, -1, t_us, drive_enable);
}

hil_err_t hil_obs_push_gpio_sampled(hil_obs_t *o, int64_t prev_us, int64_t t_us,
                                    bool drive_enable)
{
    if (o->n_gpio == o->cap_gpio) {
        const size_t cap = o->cap_gpio ? o->cap_gpio * 2u : 64u;
        hil_gpio_t *p = realloc(o->gpio, cap * sizeof(*p));
        if (p == NULL)
            return HIL_ERR_MEMORY;
        o->gpio = p;
        o->cap_gpio = cap;
    }
    o->gpio[o->n_gpio].t_us = t_us;
    o->gpio[o->n_gpio].prev_us = prev_us >= 0 && prev_us < t_us ? prev_us : -1;
    o->gpio[o->n_gpio].drive_enable = drive_enable;
    o->n_gpio++;
    return HIL_OK;
}

const char *hil_err_name(hil_err_t e)
{
    switch (e) {
    case HIL_OK: return "ok";
    case HIL_ERR_SYNTAX: return "expected '(SECONDS.MICROSECONDS) ...'";
    case HIL_ERR_FRAME: return "bad frame (expected ID#HEXDATA, 3-digit id or 8-digit error id)";
    case HIL_ERR_ORDER: return "timestamp earlier than the line before";
    case HIL_ERR_EVENT: return "unknown event or a step line not in the scenario";
    case HIL_ERR_MEMORY: return "out of memory";
    case HIL_ERR_NO_START: return "the event log has no start line";
    case HIL_ERR_SCENARIO: return "the event log is of another scenario (start scenario NAME)";
    }
    return "?";
}

/* "(SECONDS.UUUUUU)" at p; returns the characters used, 0 when malformed. */
static size_t timestamp(const char *p, size_t len, int64_t *t_us)
{
    size_t i = 0;
    if (len < 10 || p[0] != '(')
        return 0;
    i = 1;
    int64_t s = 0;
    size_t digits = 0;
    while (i < len && p[i] >= '0' && p[i] <= '9' && digits < 12) {
        s = s * 10 + (p[i++] - '0');
        digits++;
    }
    if (digits == 0 || i + 8 > len || p[i] != '.')
        return 0;
    i++;
    int64_t us = 0;
    for (int k = 0; k < 6; k++) {
        if (p[i] < '0' || p[i] > '9')
            return 0;
        us = us * 10 + (p[i++] - '0');
    }
    if (p[i] != ')')
        return 0;
    *t_us = s * 1000000 + us;
    return i + 1;
}

hil_err_t hil_candump_line(const char *line, size_t len, int64_t *t_us, can_frame_t *f)
{
    size_t i = timestamp(line, len, t_us);
    if (i == 0 || i >= len || line[i] != ' ')
        return HIL_ERR_SYNTAX;
    while (i < len && line[i] == ' ')
        i++;
    const size_t iface = i;
    while (i < len && line[i] != ' ')
        i++;
    if (i == iface || i - iface > 15 || i >= len)
        return HIL_ERR_SYNTAX;
    while (i < len && line[i] == ' ')
        i++;
    const size_t id0 = i;
    uint32_t id = 0;
    while (i < len && line[i] != '#') {
        const int h = hex_digit_value(line[i]);
        if (h < 0 || i - id0 >= 8)
            return HIL_ERR_FRAME;
        id = id << 4 | (uint32_t)h;
        i++;
    }
    const size_t id_digits = i - id0;
    if (i >= len || (id_digits != 3 && id_digits != 8))
        return HIL_ERR_FRAME;
    if (id_digits == 3 ? id > 0x7FFu : (id & ERR_FLAG) == 0 || (id & 0xC0000000u) != 0)
        return HIL_ERR_FRAME; /* an 8-digit id is accepted only as an error frame */
    i++; /* '#' */
    memset(f, 0, sizeof(*f));
    f->id = id;
    size_t end = len;
    while (end > i && (line[end - 1] == ' ' || line[end - 1] == '\r' || line[end - 1] == '\n'))
        end--;
    const size_t n = end - i;
    if (n % 2u != 0 || n > 16u)
        return HIL_ERR_FRAME; /* also refuses "R" (remote) and "#" (CAN FD) */
    for (size_t k = 0; k < n / 2u; k++) {
        const int a = hex_digit_value(line[i + 2 * k]), b = hex_digit_value(line[i + 2 * k + 1]);
        if (a < 0 || b < 0)
            return HIL_ERR_FRAME;
        f->data[k] = (uint8_t)(a << 4 | b);
    }
    f->len = (uint8_t)(n / 2u);
    return HIL_OK;
}

/* Calls fn for each non-blank line; stops at the first error. */
typedef hil_err_t (*line_fn)(void *ctx, const char *p, size_t n);

static hil_err_t each_line(const char *text, size_t len, uint32_t *err_line, line_fn fn,
                           void *ctx)
{
    uint32_t line = 0;
    size_t pos = 0;
    *err_line = 0;
    while (pos < len) {
        line++;
        size_t end = pos;
        while (end < len && text[end] != '\n')
            end++;
        const char *p = text + pos;
        size_t n = end - pos;
        pos = end + 1;
        while (n > 0 && (p[n - 1] == '\r' || p[n - 1] == ' '))
            n--;
        if (n == 0)
            continue;
        const hil_err_t e = fn(ctx, p, n);
        if (e != HIL_OK) {
            *err_line = line;
            return e;
        }
    }
    return HIL_OK;
}

static hil_err_t candump_fn(void *ctx, const char *p, size_t n)
{
    hil_obs_t *o = ctx;
    int64_t t;
    can_frame_t f;
    const hil_err_t e = hil_candump_line(p, n, &t, &f);
    if (e != HIL_OK)
        return e;
    if (o->n_frames > 0 && t < o->frame[o->n_frames - 1].t_us)
        return HIL_ERR_ORDER;
    return hil_obs_push_frame(o, t, &f);
}

hil_err_t hil_obs_add_candump(hil_obs_t *o, const char *text, size_t len, uint32_t *err_line)
{
    return each_line(text, len, err_line, candump_fn, o);
}

typedef struct {
    hil_obs_t *o;
    const scenario_t *s;
    int64_t last_us;
} events_ctx_t;

static bool word_is(const char *p, size_t n, const char *w)
{
    const size_t k = strlen(w);
    return n >= k && memcmp(p, w, k) == 0 && (n == k || p[k] == ' ');
}

static hil_err_t events_fn(void *vctx, const char *p, size_t n)
{
    events_ctx_t *c = vctx;
    int64_t t;
    size_t i = timestamp(p, n, &t);
    if (i == 0 || i >= n || p[i] != ' ')
        return HIL_ERR_SYNTAX;
    if (t < c->last_us)
        return HIL_ERR_ORDER;
    c->last_us = t;
    while (i < n && p[i] == ' ')
        i++;
    const char *w = p + i;
    const size_t wn = n - i;
    if (word_is(w, wn, "start")) {
        /* "start scenario NAME …": a log of another scenario is refused */
        static const char key[] = "start scenario ";
        const size_t k = sizeof(key) - 1u, nl = strlen(c->s->name);
        if (wn > k && memcmp(w, key, k) == 0 &&
            (wn - k < nl || memcmp(w + k, c->s->name, nl) != 0 ||
             (wn - k > nl && w[k + nl] != ' ')))
            return HIL_ERR_SCENARIO;
        c->o->have_start = true;
        c->o->start_us = t;
        return HIL_OK;
    }
    if (word_is(w, wn, "note") || word_is(w, wn, "end") || word_is(w, wn, "host"))
        return HIL_OK;
    if (word_is(w, wn, "mark")) {
        /* "mark at S.UUUUUU": exactly six decimals, as argil-sim writes them */
        static const char key[] = "mark at ";
        const size_t k = sizeof(key) - 1u;
        if (wn <= k || memcmp(w, key, k) != 0)
            return HIL_ERR_EVENT;
        int64_t sec = 0, frac = 0;
        size_t j = k, digits = 0;
        while (j < wn && w[j] >= '0' && w[j] <= '9' && digits < 5u) {
            sec = sec * 10 + (w[j++] - '0');
            digits++;
        }
        if (digits == 0 || j >= wn || w[j] != '.')
            return HIL_ERR_EVENT;
        j++;
        for (int d = 0; d < 6; d++) {
            if (j >= wn || w[j] < '0' || w[j] > '9')
                return HIL_ERR_EVENT;
            frac = frac * 10 + (w[j++] - '0');
        }
        uint32_t sync = 0;
        static const char sk[] = " sync=";
        const size_t sn = sizeof(sk) - 1u;
        if (j + sn < wn && memcmp(w + j, sk, sn) == 0) {
            j += sn;
            const size_t d0 = j;
            while (j < wn && w[j] >= '0' && w[j] <= '9' && j - d0 < 9u)
                sync = sync * 10u + (uint32_t)(w[j++] - '0');
            if (j == d0)
                return HIL_ERR_EVENT;
        }
        if (j < wn && w[j] != ' ')
            return HIL_ERR_EVENT;
        const int64_t t_s = sec * 1000000 + frac;
        for (uint32_t m = 0; m < c->o->n_marks; m++)
            if (c->o->mark_t_us[m] == t_s)
                return HIL_OK;
        if (c->o->n_marks == HIL_MARKS_MAX)
            return HIL_OK; /* more marks than a scenario has times: the rest are not needed */
        c->o->mark_t_us[c->o->n_marks] = t_s;
        c->o->mark_us[c->o->n_marks] = t;
        c->o->mark_sync[c->o->n_marks] = sync;
        c->o->n_marks++;
        return HIL_OK;
    }
    if (word_is(w, wn, "gpio_out")) {
        static const char key[] = "gpio_out DRIVE_ENABLE=";
        const size_t k = sizeof(key) - 1u;
        if (wn < k + 1u || memcmp(w, key, k) != 0 || (w[k] != '0' && w[k] != '1') ||
            (wn > k + 1u && w[k + 1u] != ' '))
            return HIL_ERR_EVENT;
        /* " prev=(SECONDS.MICROS)": the sample before; anything else after a space is a note */
        static const char pk[] = " prev=";
        const size_t pn = sizeof(pk) - 1u;
        int64_t prev = -1;
        if (wn > k + 1u + pn && memcmp(w + k + 1u, pk, pn) == 0) {
            const size_t used = timestamp(w + k + 1u + pn, wn - (k + 1u + pn), &prev);
            if (used == 0 || (k + 1u + pn + used < wn && w[k + 1u + pn + used] != ' '))
                return HIL_ERR_EVENT;
            if (prev > t)
                return HIL_ERR_ORDER;
        }
        return hil_obs_push_gpio_sampled(c->o, prev, t, w[k] == '1');
    }
    if (word_is(w, wn, "inject")) {
        static const char key[] = "inject line=";
        const size_t k = sizeof(key) - 1u;
        if (wn <= k || memcmp(w, key, k) != 0)
            return HIL_ERR_EVENT;
        uint32_t line = 0;
        size_t j = k;
        while (j < wn && w[j] >= '0' && w[j] <= '9' && line < 1000000u)
            line = line * 10u + (uint32_t)(w[j++] - '0');
        if (j == k)
            return HIL_ERR_EVENT;
        for (uint32_t s = 0; s < c->s->n_steps; s++) {
            if (c->s->step[s].line == line) {
                if (!c->o->step_seen[s]) {
                    c->o->step_seen[s] = true;
                    c->o->step_us[s] = t;
                }
                return HIL_OK;
            }
        }
        return HIL_ERR_EVENT;
    }
    return HIL_ERR_EVENT;
}

hil_err_t hil_obs_add_events(hil_obs_t *o, const scenario_t *s, const char *text, size_t len,
                             uint32_t *err_line)
{
    events_ctx_t c = {o, s, INT64_MIN};
    const hil_err_t e = each_line(text, len, err_line, events_fn, &c);
    if (e != HIL_OK)
        return e;
    if (!o->have_start)
        return HIL_ERR_NO_START;
    return HIL_OK;
}

static bool is_sync(const hil_frame_t *h);

/* The step scenario time t_us is anchored on: one at exactly t_us whose injection the log holds,
 * else the latest such step before t_us; -1 when none. */
static int anchor_step(const scenario_t *s, const hil_obs_t *o, int64_t t_us)
{
    int best = -1;
    for (uint32_t i = 0; i < s->n_steps; i++) {
        if (!o->step_seen[i] || s->step[i].t_us > t_us)
            continue;
        if (s->step[i].t_us == t_us)
            return (int)i;
        if (best < 0 || s->step[i].t_us >= s->step[best].t_us)
            best = (int)i;
    }
    return best;
}

/* Absolute time of scenario time t_us: the logged injection of a step at exactly that time;
 * else, on a log with SYNCs, as many board ticks after the latest step's injection as the
 * scenario puts between them (each side's injection is stamped when it acted, so a rig whose
 * sides run a few ticks apart is judged from what the board could see); else the rig's mark
 * of that time; else start + t. */
static int64_t abs_time(const scenario_t *s, const hil_obs_t *o, int64_t t_us)
{
    const int a = anchor_step(s, o, t_us);
    if (a >= 0 && s->step[a].t_us == t_us)
        return o->step_us[a];
    if (a >= 0 && o->n_syncs > 0) {
        const int64_t want = (t_us - s->step[a].t_us) / HIL_TICK_US;
        int64_t n = 0;
        if (want == 0)
            return o->step_us[a];
        for (size_t k = 0; k < o->n_frames; k++)
            if (o->frame[k].t_us > o->step_us[a] && is_sync(&o->frame[k]) && ++n == want)
                return o->frame[k].t_us;
        /* the log ends first: the marks below */
    }
    for (uint32_t m = 0; m < o->n_marks; m++) {
        if (o->mark_t_us[m] != t_us)
            continue;
        uint32_t n = 0;
        for (size_t k = 0; o->mark_sync[m] > 0 && k < o->n_frames; k++)
            if (o->frame[k].t_us > o->start_us && is_sync(&o->frame[k]) &&
                ++n == o->mark_sync[m])
                return o->frame[k].t_us;
        return o->mark_us[m];
    }
    return o->start_us + t_us;
}

/* The instant the rig's clock reached the scenario's end: its (duration / 1 ms)-th SYNC after
 * the start line; INT64_MAX without SYNCs or when the log ends first. */
static int64_t rig_end(const scenario_t *s, const hil_obs_t *o)
{
    if (o->n_syncs == 0 || !o->have_start)
        return INT64_MAX;
    const int64_t want = s->duration_us / HIL_TICK_US;
    int64_t n = 0;
    for (size_t k = 0; k < o->n_frames; k++)
        if (o->frame[k].t_us > o->start_us && is_sync(&o->frame[k]) && ++n == want)
            return o->frame[k].t_us;
    return INT64_MAX;
}

/* True when scenario time t_us is anchored on a host-side step the log holds: the board sees
 * it only once the host link has delivered it. */
static bool host_anchored(const scenario_t *s, const hil_obs_t *o, int64_t t_us)
{
    const int a = anchor_step(s, o, t_us);
    return a >= 0 && scenario_action_is_host_side(s->step[a].action);
}

/* DRIVE_ENABLE level just before t (taken as high when nothing was logged before). */
static bool enable_before(const hil_obs_t *o, int64_t t)
{
    bool level = true;
    for (size_t k = 0; k < o->n_gpio && o->gpio[k].t_us <= t; k++)
        level = o->gpio[k].drive_enable;
    return level;
}

static bool rpdo(const hil_frame_t *h, uint8_t *node, uint16_t *cw, int16_t *tq)
{
    return (h->f.id & ERR_FLAG) == 0 && canopen_rpdo_decode(&h->f, node, cw, tq);
}

static bool cw_off(uint16_t cw)
{
    return cw == CIA402_CW_QUICK_STOP || cw == CIA402_CW_DISABLE_VOLTAGE;
}

#define MS(us) ((double)(us) / 1000.0)

/* The power state a controlword asks a drive for (CiA 402 transitions), −1 when it asks for
 * none that the drive must answer (quick stop: the state depends on where the drive was). */
static int32_t cw_target(uint16_t cw)
{
    if ((cw & 0x80u) != 0 || (cw & 0x02u) == 0)
        return (int32_t)CIA402_SWITCH_ON_DISABLED; /* fault reset, disable voltage */
    if ((cw & 0x06u) == 0x02u)
        return -1;
    if ((cw & 0x07u) == 0x06u)
        return (int32_t)CIA402_READY_TO_SWITCH_ON;
    if ((cw & 0x0Fu) == 0x07u)
        return (int32_t)CIA402_SWITCHED_ON;
    return (cw & 0x0Fu) == 0x0Fu ? (int32_t)CIA402_OPERATION_ENABLED : -1;
}

static bool is_sync(const hil_frame_t *h)
{
    return scn_clock_is_tick(&h->f);
}

/* Board ticks from t0 to t: SYNC frames in (t0, t]; −1 when the log has none. */
static int64_t ticks_between(const hil_obs_t *o, int64_t t0, int64_t t)
{
    if (o->n_syncs == 0)
        return -1;
    int64_t n = 0;
    for (size_t k = 0; k < o->n_frames && o->frame[k].t_us <= t; k++)
        n += o->frame[k].t_us > t0 && is_sync(&o->frame[k]);
    return n;
}

/* Time of the first SYNC after t (INT64_MAX if none). */
static int64_t first_sync_after(const hil_obs_t *o, int64_t t)
{
    for (size_t k = 0; k < o->n_frames; k++)
        if (o->frame[k].t_us > t && is_sync(&o->frame[k]))
            return o->frame[k].t_us;
    return INT64_MAX;
}

/* The bound's ticks: "within 3ms" allows 3 ticks at the nominal 1 kHz (at least 1). */
static int64_t bound_ticks(int64_t within_us)
{
    const int64_t n = (within_us + HIL_TICK_US - 1) / HIL_TICK_US;
    return n > 0 ? n : 1;
}

/* Last instant inside "within" from t0: t0 + within_us on a log without SYNCs, else just
 * before the SYNC that opens the tick after the bound's last, link ticks later for a host-side
 * step (INT64_MAX if the log ends). */
static int64_t bound_end(const hil_obs_t *o, int64_t t0, int64_t within_us, int64_t link)
{
    if (o->n_syncs == 0)
        return t0 + within_us;
    const int64_t want = bound_ticks(within_us) + link + 1;
    int64_t n = 0;
    for (size_t k = 0; k < o->n_frames; k++)
        if (o->frame[k].t_us > t0 && is_sync(&o->frame[k]) && ++n == want)
            return o->frame[k].t_us - 1;
    return INT64_MAX;
}

/* "1.234 ms, 2 ticks" (ticks only when the log has SYNCs) into buf; returns buf. */
static const char *lat(char *buf, size_t n, const hil_obs_t *o, int64_t t0, int64_t t)
{
    const int64_t ticks = ticks_between(o, t0, t);
    if (ticks < 0)
        snprintf(buf, n, "%.3f ms", MS(t - t0));
    else
        snprintf(buf, n, "%.3f ms, %lld tick%s", MS(t - t0), (long long)ticks,
                 ticks == 1 ? "" : "s");
    return buf;
}

/* "3 ticks (3.000 ms at 1 kHz)" or "3.000 ms": the bound as it is asserted. */
static const char *bnd(char *buf, size_t n, const hil_obs_t *o, int64_t within_us,
                       int64_t link)
{
    if (o->n_syncs == 0)
        snprintf(buf, n, "%.3f ms", MS(within_us));
    else if (link > 0)
        snprintf(buf, n, "%lld ticks = %.3f ms at 1 kHz + %lld for the link",
                 (long long)bound_ticks(within_us), MS(within_us), (long long)link);
    else
        snprintf(buf, n, "%lld ticks = %.3f ms at 1 kHz", (long long)bound_ticks(within_us),
                 MS(within_us));
    return buf;
}

/* The heartbeat consumer from the bus's side (heartbeat_supervised, [t0, t_end)). A heartbeat
 * on the bus at h is read by the board in the tick that ends with the first SYNC after h, or
 * one tick later when it arrived after that tick's read; the board faults in the tick whose age
 * exceeds C = heartbeat_ticks ticks: with a the SYNCs since a drive's last heartbeat, its RPDOs
 * go off at a = C + 1, or C + 2 after a late read. A tick either way for the log's order of
 * frames from two senders: drives off while every a < C is a spurious fault, drives on with
 * some a > C + 2 a missed one; once off they stay off. Needs SYNCs. */
static void check_heartbeat_supervised(const hil_obs_t *o, int64_t t0, int64_t t_end,
                                       hil_result_t *r)
{
    const int64_t c = o->heartbeat_ticks, period = ARGIL_DRIVE_HEARTBEAT_PERIOD_US / HIL_TICK_US;
    if (o->n_syncs == 0) {
        snprintf(r->msg, sizeof(r->msg), "the log has no SYNC: heartbeat ages need board ticks");
        return;
    }
    int64_t syncs = 0, last_hb[ARGIL_DRIVES] = {-1, -1, -1}, widest = 0, t_off = -1;
    size_t rpdos = 0;
    for (size_t k = 0; k < o->n_frames && o->frame[k].t_us < t_end; k++) {
        const hil_frame_t *h = &o->frame[k];
        uint8_t node;
        nmt_state_t st;
        uint16_t cw;
        int16_t tq;
        if (is_sync(h)) {
            syncs++;
            continue;
        }
        if ((h->f.id & ERR_FLAG) == 0 && canopen_heartbeat_decode(&h->f, &node, &st) &&
            node >= 1 && node <= ARGIL_DRIVES) {
            const int64_t gap = last_hb[node - 1] < 0 ? 0 : syncs - last_hb[node - 1];
            if (h->t_us >= t0 && gap >= period + period / 2 && gap <= c)
                r->tolerated++; /* a lost heartbeat (or a late one) the board must ride */
            last_hb[node - 1] = syncs;
            continue;
        }
        if (h->t_us < t0 || !rpdo(h, &node, &cw, &tq))
            continue;
        rpdos++;
        int64_t age = 0;
        int oldest = 0;
        for (int j = 0; j < ARGIL_DRIVES; j++)
            if (last_hb[j] >= 0 && syncs - last_hb[j] > age) {
                age = syncs - last_hb[j];
                oldest = j + 1;
            }
        if (age > widest)
            widest = age;
        const bool on = cw == CIA402_CW_ENABLE_OP;
        if (t_off >= 0) {
            if (on || tq != 0) {
                r->observed_us = h->t_us - t0;
                snprintf(r->msg, sizeof(r->msg), "drive %u: controlword 0x%04X torque %d at "
                         "+%.3f ms after the drives went off at +%.3f ms", node, cw, tq,
                         MS(h->t_us - t0), MS(t_off - t0));
                return;
            }
            continue;
        }
        if (!on && age < c) {
            r->observed_us = h->t_us - t0;
            snprintf(r->msg, sizeof(r->msg), "drives off at +%.3f ms (drive %u: controlword "
                     "0x%04X) with every heartbeat under %lld ticks old (oldest %lld)",
                     MS(h->t_us - t0), node, cw, (long long)c, (long long)age);
            return;
        }
        if (on && age > c + 2) {
            r->observed_us = h->t_us - t0;
            snprintf(r->msg, sizeof(r->msg), "drive %d's last heartbeat %lld ticks old "
                     "(consumer %lld) and drives still on at +%.3f ms", oldest, (long long)age,
                     (long long)c, MS(h->t_us - t0));
            return;
        }
        if (!on) {
            t_off = h->t_us;
            r->observed_us = h->t_us - t0;
            r->observed_ticks = age;
        }
    }
    if (rpdos == 0) {
        snprintf(r->msg, sizeof(r->msg), "no RPDO in the window: nothing ran");
        return;
    }
    r->pass = true;
    if (t_off >= 0)
        snprintf(r->msg, sizeof(r->msg), "%u lost heartbeat(s) ridden; off at +%.3f ms, %lld "
                 "ticks after a drive's last heartbeat (consumer %lld), and stayed off",
                 r->tolerated, MS(t_off - t0), (long long)r->observed_ticks, (long long)c);
    else
        snprintf(r->msg, sizeof(r->msg), "%u lost heartbeat(s) ridden, on throughout: widest "
                 "heartbeat age %lld ticks (consumer %lld, %zu RPDOs)", r->tolerated,
                 (long long)widest, (long long)c, rpdos);
}

void hil_check_expect(const scenario_t *s, const hil_obs_t *o, uint32_t i, hil_result_t *r)
{
    const scn_expect_t *e = &s->expect[i];
    const int64_t t0 = abs_time(s, o, e->t_us);
    /* A host-side step reaches the board through the link: its bound starts link_ticks later. */
    const int64_t link = o->n_syncs > 0 && host_anchored(s, o, e->t_us) ? o->link_ticks : 0;
    /* A window ends no later than the rig's own end: the SYNC at which its clock (one tick per
     * SYNC since the start line) reached the duration. A time counted from a step's logged
     * injection carries the arm stand-in's lag at that step, and counted past the end it ran
     * into the rig's shutdown: the arm stops answering, the host leaves (can_drop_1pct, CI
     * 2026-12-02: "heartbeat 253 ticks old" and a host-lost fault, both after the end). */
    int64_t t_end = abs_time(s, o, scenario_until_us(s, e));
    const int64_t t_rig_end = rig_end(s, o);
    if (t_end > t_rig_end)
        t_end = t_rig_end;
    const int64_t t_bound = bound_end(o, t0, e->within_us, link);
    const bool gpio = o->n_gpio > 0;
    char la[48], bo[48];
    r->pass = false;
    r->observed_us = -1;
    r->observed_ticks = -1;
    r->tolerated = 0;
    size_t rpdos = 0;
    uint8_t node;
    uint16_t cw;
    int16_t tq;
    switch (e->kind) {
    case SCN_EXP_TORQUE_ZERO:
    case SCN_EXP_FORCE_ZERO:
    case SCN_EXP_FAULT: {
        /* The last "bad" RPDO in [t0, t_end): torque non-zero (or, for fault, drives not
         * commanded off); the condition holds from the next RPDO on. */
        const bool fault = e->kind == SCN_EXP_FAULT;
        int64_t t_can = -1;          /* first RPDO of the final run of good ones */
        bool any_bad = false;
        for (size_t k = 0; k < o->n_frames; k++) {
            const hil_frame_t *h = &o->frame[k];
            if (h->t_us < t0 || h->t_us >= t_end || !rpdo(h, &node, &cw, &tq))
                continue;
            rpdos++;
            if (tq != 0 || (fault && !cw_off(cw))) {
                any_bad = true;
                t_can = -1;
            } else if (t_can < 0) {
                t_can = h->t_us;
            }
        }
        if (rpdos > 0 && t_can < 0) {
            snprintf(r->msg, sizeof(r->msg), "still %s at the end of the window (%zu RPDOs seen)",
                     fault ? "drives commanded on or torque non-zero" : "torque non-zero", rpdos);
            return;
        }
        /* No offending frame after the injection at all (the board's first frame already
         * complied, or it fell silent, as in bus-off): observed at once. */
        const int64_t t_first_ok = t_can;
        if (!any_bad)
            t_can = t0;
        int64_t t_obs = t_can;
        if (fault && gpio) {
            bool level = enable_before(o, t0);
            int64_t t_low = level ? -1 : t0;
            for (size_t k = 0; k < o->n_gpio; k++) {
                const hil_gpio_t *g = &o->gpio[k];
                if (g->t_us < t0 || g->t_us >= t_end)
                    continue;
                /* the earliest the edge can have been: just after the sample before, or t0
                 * itself when that sample was taken before t0 (unknown: the sample's time) */
                if (!g->drive_enable && level)
                    t_low = g->prev_us >= t0 ? g->prev_us + 1 : g->prev_us >= 0 ? t0 : g->t_us;
                if (g->drive_enable) {
                    snprintf(r->msg, sizeof(r->msg), "DRIVE_ENABLE back high at +%.3f ms",
                             MS(g->t_us - t0));
                    return;
                }
                level = g->drive_enable;
            }
            if (t_low < 0) {
                snprintf(r->msg, sizeof(r->msg), "DRIVE_ENABLE never went low");
                return;
            }
            if (t_low > t_obs)
                t_obs = t_low;
        }
        r->observed_us = t_obs - t0;
        r->observed_ticks = ticks_between(o, t0, t_obs);
        if (e->until != SCN_UNTIL_NONE) {
            r->pass = !any_bad && (!fault || !gpio || t_obs == t0);
            snprintf(r->msg, sizeof(r->msg), "%s from +%.3f ms (%zu RPDOs checked)",
                     r->pass ? "held" : "reached only", MS(t_obs - t0), rpdos);
            return;
        }
        /* A tick writes its GPIO outputs after its SYNC: DRIVE_ENABLE of the bound's last tick
         * falls before the next tick's SYNC, one SYNC later than that tick's RPDOs. */
        r->pass = t_can <= t_bound &&
                  (!fault || !gpio || t_obs <= bound_end(o, t0, e->within_us, link + 1));
        if (any_bad)
            snprintf(r->msg, sizeof(r->msg), "observed after %s (bound %s, %zu RPDOs%s)",
                     lat(la, sizeof(la), o, t0, t_obs), bnd(bo, sizeof(bo), o, e->within_us, link),
                     rpdos, fault && gpio ? ", DRIVE_ENABLE" : "");
        else
            snprintf(r->msg, sizeof(r->msg),
                     "observed after %s: no offending RPDO after the injection, first "
                     "RPDO at +%.3f ms (bound %s%s)",
                     lat(la, sizeof(la), o, t0, t_obs), t_first_ok < 0 ? -1.0 : MS(t_first_ok - t0),
                     bnd(bo, sizeof(bo), o, e->within_us, link),
                     fault && gpio ? ", DRIVE_ENABLE" : "");
        return;
    }
    case SCN_EXP_QUICK_STOP: {
        int64_t t_node[ARGIL_DRIVES] = {-1, -1, -1};
        for (size_t k = 0; k < o->n_frames; k++) {
            const hil_frame_t *h = &o->frame[k];
            if (h->t_us < t0 || h->t_us > t_bound || !rpdo(h, &node, &cw, &tq))
                continue;
            if (node >= 1 && node <= ARGIL_DRIVES && cw == CIA402_CW_QUICK_STOP &&
                t_node[node - 1] < 0)
                t_node[node - 1] = h->t_us;
        }
        int64_t worst = t0;
        for (int j = 0; j < ARGIL_DRIVES; j++) {
            if (t_node[j] < 0) {
                snprintf(r->msg, sizeof(r->msg), "drive %d got no QUICK_STOP within %s",
                         j + 1, bnd(bo, sizeof(bo), o, e->within_us, link));
                return;
            }
            if (t_node[j] > worst)
                worst = t_node[j];
        }
        r->pass = true;
        r->observed_us = worst - t0;
        r->observed_ticks = ticks_between(o, t0, worst);
        snprintf(r->msg, sizeof(r->msg), "every drive got QUICK_STOP after %s (bound %s)",
                 lat(la, sizeof(la), o, t0, worst), bnd(bo, sizeof(bo), o, e->within_us, link));
        return;
    }
    case SCN_EXP_ENABLED: {
        /* The board walks each drive to OPERATION_ENABLED one controlword at a time and waits
         * for the drive's statusword between them: the time the drives take to answer is the
         * drives' (on a rig, the arm stand-in's, which lags the board under emulation), the
         * rest the board's. The bound holds the board's share: per drive, the ticks from t0 to
         * its ENABLE_OP less the ticks each controlword waited for the drive's answer (from
         * the board's first RPDO with it to the first TPDO with the state it asks for; a
         * controlword the board replaced before its answer came counts as the board's). */
        bool on[ARGIL_DRIVES] = {false, false, false};
        uint16_t last_cw[ARGIL_DRIVES] = {0xFFFFu, 0xFFFFu, 0xFFFFu};
        int32_t state[ARGIL_DRIVES] = {-1, -1, -1};
        int64_t req_t[ARGIL_DRIVES] = {-1, -1, -1}, t_on[ARGIL_DRIVES] = {-1, -1, -1};
        int32_t req_target[ARGIL_DRIVES] = {-1, -1, -1};
        int64_t wait[ARGIL_DRIVES] = {0, 0, 0};
        const bool ticks = o->n_syncs > 0;
        for (size_t k = 0; k < o->n_frames; k++) {
            const hil_frame_t *h = &o->frame[k];
            uint16_t sw;
            int32_t pos;
            int16_t tqa;
            if ((h->f.id & ERR_FLAG) == 0 && canopen_tpdo_decode(&h->f, &node, &sw, &pos, &tqa)) {
                if (node < 1 || node > ARGIL_DRIVES)
                    continue;
                const int j = node - 1;
                const int32_t st = (int32_t)cia402_state_from_statusword(sw);
                if (h->t_us >= t0 && req_t[j] >= 0 && st == req_target[j]) {
                    wait[j] += ticks ? ticks_between(o, req_t[j], h->t_us) : h->t_us - req_t[j];
                    req_t[j] = -1;
                }
                state[j] = st;
                continue;
            }
            if (!rpdo(h, &node, &cw, &tq) || node < 1 || node > ARGIL_DRIVES)
                continue;
            const int j = node - 1;
            if (h->t_us < t0) {
                last_cw[j] = cw;
                continue;
            }
            if (cw != last_cw[j]) {
                req_t[j] = -1;
                const int32_t target = cw_target(cw);
                if (cw != CIA402_CW_ENABLE_OP && target >= 0 && target != state[j]) {
                    req_t[j] = h->t_us;
                    req_target[j] = target;
                }
                last_cw[j] = cw;
            }
            on[j] = cw == CIA402_CW_ENABLE_OP;
            if (on[j] && t_on[j] < 0)
                t_on[j] = h->t_us;
            if (!on[j])
                t_on[j] = -1;
            if (!(on[0] && on[1] && on[2] && (!gpio || enable_before(o, h->t_us))))
                continue;
            int64_t board = 0, drives = 0, last_on = t0;
            for (int d = 0; d < ARGIL_DRIVES; d++) {
                const int64_t total = ticks ? ticks_between(o, t0, t_on[d]) : t_on[d] - t0;
                if (total - wait[d] > board)
                    board = total - wait[d];
                if (wait[d] > drives)
                    drives = wait[d];
                if (t_on[d] > last_on)
                    last_on = t_on[d];
            }
            /* DRIVE_ENABLE after the last drive's ENABLE_OP is the board's too */
            board += ticks ? ticks_between(o, last_on, h->t_us) : h->t_us - last_on;
            const int64_t allowed = ticks ? bound_ticks(e->within_us) + link : e->within_us;
            r->pass = board <= allowed;
            r->observed_us = h->t_us - t0;
            r->observed_ticks = ticks ? board : -1;
            if (ticks)
                snprintf(r->msg, sizeof(r->msg), "every drive enabled after %s: the drives "
                         "answered in %lld, the board took %lld (bound %s)",
                         lat(la, sizeof(la), o, t0, h->t_us), (long long)drives,
                         (long long)board, bnd(bo, sizeof(bo), o, e->within_us, link));
            else
                snprintf(r->msg, sizeof(r->msg), "every drive enabled after %.3f ms: the "
                         "drives answered in %.3f ms, the board took %.3f ms (bound %s)",
                         MS(h->t_us - t0), MS(drives), MS(board),
                         bnd(bo, sizeof(bo), o, e->within_us, link));
            return;
        }
        snprintf(r->msg, sizeof(r->msg), "drives not all enabled by the end of the log (bound %s)",
                 bnd(bo, sizeof(bo), o, e->within_us, link));
        return;
    }
    case SCN_EXP_TORQUE_NONZERO:
        for (size_t k = 0; k < o->n_frames; k++) {
            const hil_frame_t *h = &o->frame[k];
            if (h->t_us < t0 || h->t_us > t_bound || !rpdo(h, &node, &cw, &tq))
                continue;
            if (tq != 0) {
                r->pass = true;
                r->observed_us = h->t_us - t0;
                r->observed_ticks = ticks_between(o, t0, h->t_us);
                snprintf(r->msg, sizeof(r->msg), "torque %d ‰ on drive %u after %s (bound %s)",
                         tq, node, lat(la, sizeof(la), o, t0, h->t_us),
                         bnd(bo, sizeof(bo), o, e->within_us, link));
                return;
            }
        }
        snprintf(r->msg, sizeof(r->msg), "no non-zero torque within %s",
                 bnd(bo, sizeof(bo), o, e->within_us, link));
        return;
    case SCN_EXP_NO_TORQUE_FRAMES:
    case SCN_EXP_RUNNING: {
        const bool running = e->kind == SCN_EXP_RUNNING;
        /* A tick ends with its SYNC: the RPDOs of the tick in progress at T were computed from
         * inputs read before T, so on a log with SYNCs no_torque_frames starts at its end. */
        int64_t t_from = running || o->n_syncs == 0 ? t0 : first_sync_after(o, t0);
        for (int64_t k = 0; !running && k < link && t_from != INT64_MAX; k++)
            t_from = first_sync_after(o, t_from);
        for (size_t k = 0; k < o->n_frames; k++) {
            const hil_frame_t *h = &o->frame[k];
            if (h->t_us < t_from || h->t_us >= t_end || !rpdo(h, &node, &cw, &tq))
                continue;
            rpdos++;
            if (running ? cw != CIA402_CW_ENABLE_OP : tq != 0) {
                r->observed_us = h->t_us - t0;
                snprintf(r->msg, sizeof(r->msg), "drive %u: controlword 0x%04X torque %d at +%.3f ms",
                         node, cw, tq, MS(h->t_us - t0));
                return;
            }
        }
        if (running && gpio) {
            bool level = enable_before(o, t0);
            for (size_t k = 0; k < o->n_gpio; k++)
                if (o->gpio[k].t_us >= t0 && o->gpio[k].t_us < t_end && !o->gpio[k].drive_enable)
                    level = false;
            if (!level) {
                snprintf(r->msg, sizeof(r->msg), "DRIVE_ENABLE low within the window");
                return;
            }
        }
        if (running && rpdos == 0) {
            snprintf(r->msg, sizeof(r->msg), "no RPDO in the window: nothing ran");
            return;
        }
        r->pass = true;
        snprintf(r->msg, sizeof(r->msg), "held for %.3f ms (%zu RPDOs)", MS(t_end - t0), rpdos);
        return;
    }
    case SCN_EXP_SAFE: {
        /* Walk RPDOs and DRIVE_ENABLE edges in time order; a rearm ends the latch. */
        scn_expect_t to_rearm = *e;
        to_rearm.until = SCN_UNTIL_REARM;
        const int64_t t_rearm = abs_time(s, o, scenario_until_us(s, &to_rearm));
        const int64_t t_stop = t_rearm < t_end ? t_rearm : t_end;
        int64_t t_off = -1;
        size_t g = 0;
        for (size_t k = 0; k < o->n_frames; k++) {
            const hil_frame_t *h = &o->frame[k];
            if (h->t_us >= t_stop)
                break;
            for (; g < o->n_gpio && o->gpio[g].t_us <= h->t_us; g++)
                if (o->gpio[g].t_us >= t0 && !o->gpio[g].drive_enable && t_off < 0)
                    t_off = o->gpio[g].t_us;
            if (h->t_us < t0 || !rpdo(h, &node, &cw, &tq))
                continue;
            rpdos++;
            if (t_off >= 0 && tq != 0) {
                r->observed_us = h->t_us - t0;
                snprintf(r->msg, sizeof(r->msg),
                         "torque %d on drive %u at +%.3f ms after the drives went off at +%.3f ms",
                         tq, node, MS(h->t_us - t0), MS(t_off - t0));
                return;
            }
            if (cw_off(cw) && t_off < 0)
                t_off = h->t_us;
        }
        r->pass = true;
        if (t_off >= 0)
            snprintf(r->msg, sizeof(r->msg), "drives off at +%.3f ms, no torque after (%zu RPDOs)",
                     MS(t_off - t0), rpdos);
        else
            snprintf(r->msg, sizeof(r->msg), "ran without a fault (%zu RPDOs)", rpdos);
        return;
    }
    case SCN_EXP_HEARTBEAT_SUPERVISED:
        check_heartbeat_supervised(o, t0, t_end, r);
        return;
    default:
        snprintf(r->msg, sizeof(r->msg), "unknown expectation");
        return;
    }
}
