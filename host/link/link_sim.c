/* The in-process simulated board as a host-link transport, in real time: each poll runs the
 * board core and the simulated arm (the hand holding still at the workspace centre, or pressing
 * the stylus into the clay: "sim:press") for the 1 ms ticks the wall clock has reached, so
 * `argil connect --device sim` behaves like a board on a cable. The deterministic lockstep
 * session is `argil sculpt`, not this. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "host/link/link.h"
#include "shared/link_framer.h"
#include "sim/rig/rig.h"

#define SIM_CATCH_UP_TICKS 50u   /* at most this many ticks per poll; later ones are skipped */
#define LINK_SIM_PRESS_PERIOD_S 2.0  /* "sim:press": one press every 2 s: */
#define SIM_PRESS_START_S 0.2        /* … button 1 down 0.2 s into it, */
#define SIM_PRESS_LEN_S 1.4          /* … for 1.4 s, down and up again (half a sine), */
#define SIM_PRESS_DEPTH_M 0.014      /* … 14 mm below the hold point: 4 mm into the clay */

typedef struct {
    sim_rig_t rig;
    vec3_t hold_m;                 /* where the hand holds the stylus */
    link_sim_hand_t hand;
    uint32_t tick_us;
    uint64_t start_us;
    uint64_t ticks;
    uint64_t skipped_ticks;
    uint8_t rx[SIM_RIG_LINK_BYTES];
    size_t rx_len, rx_at;
} sim_link_t;

static argil_err_t sim_send(link_t *l, const uint8_t *frame, size_t len)
{
    sim_link_t *s = l->impl;
    return sim_rig_host_send(&s->rig, frame, len);
}

static size_t sim_recv(link_t *l, uint8_t *buf, size_t cap)
{
    sim_link_t *s = l->impl;
    if (s->rx_at >= s->rx_len) {
        s->rx_len = sim_rig_host_receive(&s->rig, s->rx, sizeof(s->rx));
        s->rx_at = 0;
        if (s->rx_len == 0)
            return 0;
    }
    const size_t f = link_frame_size(s->rx + s->rx_at, s->rx_len - s->rx_at);
    if (f == 0 || f > s->rx_len - s->rx_at || f > cap) {
        l->stats.errors_rx++;
        s->rx_at = s->rx_len = 0;
        return 0;
    }
    memcpy(buf, s->rx + s->rx_at, f);
    s->rx_at += f;
    return f;
}

/* Where the hand puts the stylus at board time t_s, its velocity, and button 1. */
static void hand_at(const sim_link_t *s, double t_s, vec3_t *pos_m, vec3_t *vel_m_s, bool *b1)
{
    *pos_m = s->hold_m;
    *vel_m_s = vec3(0, 0, 0);
    *b1 = false;
    if (s->hand != LINK_SIM_HAND_PRESS)
        return;
    const double u = (fmod(t_s, LINK_SIM_PRESS_PERIOD_S) - SIM_PRESS_START_S) / SIM_PRESS_LEN_S;
    if (u <= 0.0 || u >= 1.0)
        return;
    const double w = M_PI / SIM_PRESS_LEN_S;
    pos_m->z -= (float)(SIM_PRESS_DEPTH_M * sin(M_PI * u));
    vel_m_s->z = (float)(-SIM_PRESS_DEPTH_M * w * cos(M_PI * u));
    *b1 = true;
}

static void sim_tick(sim_link_t *s)
{
    vec3_t pos_m, vel_m_s;
    bool b1;
    hand_at(s, (double)(s->ticks + s->skipped_ticks) * s->tick_us * 1e-6, &pos_m, &vel_m_s, &b1);
    sim_rig_set_hand(&s->rig, pos_m, vel_m_s, b1, false);
    (void)sim_rig_step_ns(&s->rig, s->tick_us);
    s->ticks++;
}

static void sim_poll(link_t *l, uint32_t wait_us, uint64_t now_us)
{
    sim_link_t *s = l->impl;
    if (s->start_us == 0)
        s->start_us = now_us;
    const uint64_t due = (now_us - s->start_us) / s->tick_us;
    if (due > s->ticks + s->skipped_ticks + SIM_CATCH_UP_TICKS)
        s->skipped_ticks = due - s->ticks - SIM_CATCH_UP_TICKS;
    while (s->ticks + s->skipped_ticks < due)
        sim_tick(s);
    /* Sleep until the next tick is due, at most wait_us. */
    const uint64_t next_us = s->start_us + (s->ticks + s->skipped_ticks + 1u) * s->tick_us;
    uint64_t nap_us = next_us > now_us ? next_us - now_us : 0;
    if (nap_us > wait_us)
        nap_us = wait_us;
    if (nap_us > 0) {
        const struct timespec ts = {0, (long)nap_us * 1000L};
        nanosleep(&ts, NULL);
    }
}

static void sim_close(link_t *l)
{
    free(l->impl);
}

static const link_ops_t SIM_OPS = {sim_send, sim_recv, sim_poll, sim_close};

argil_err_t link_sim_open(link_t *l, link_sim_hand_t hand, char *err, size_t err_len)
{
    sim_link_t *s = calloc(1, sizeof(*s));
    if (!s) {
        snprintf(err, err_len, "out of memory for the simulated board");
        return ARGIL_ERR_NOMEM;
    }
    sim_rig_cfg_t cfg;
    sim_rig_cfg_default(&cfg);
    if (sim_rig_init(&s->rig, &cfg) != ARGIL_OK) {
        free(s);
        snprintf(err, err_len, "sim: the simulated board refused its configuration");
        return ARGIL_ERR_ARG;
    }
    s->tick_us = cfg.board.tick_us;
    s->hold_m = sim_rig_tip_m(&s->rig);
    s->hand = hand;
    link_attach(l, &SIM_OPS, s, true);
    return ARGIL_OK;
}
