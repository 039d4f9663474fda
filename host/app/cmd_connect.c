/* argil connect: a live session with a board over the host link. A link thread only moves
 * frames between the transport and two lock-free rings; the solver thread (this command's
 * main thread) runs the host's protocol peer on the global clay, records telemetry and prints
 * a status line; Ctrl-C ends it and the clay is written like `argil sculpt` writes it. */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "host/app/cli_opts.h"
#include "host/app/commands.h"
#include "host/model/host_tool.h"
#include "host/app/peer.h"
#include "host/app/peer_journal.h"
#include "host/app/session_files.h"
#include "host/app/session_undo.h"
#include "host/io/argil_file.h"
#include "host/link/link.h"
#include "host/link/link_crypto.h"
#include "host/link/link_key_file.h"
#include "host/mesh/grid_mesh.h"
#include "host/mesh/mc.h"
#include "host/mesh/mesh_check.h"
#include "host/model/grid.h"
#include "shared/arm_kin.h"
#include "shared/safety_codes.h"
#include "shared/spsc_ring.h"

#define CONNECT_RX_RING_BYTES (1u << 20)  /* ~1 s of board traffic if the solver stalls */
#define CONNECT_TX_RING_BYTES (1u << 18)
#define CONNECT_HELLO_PERIOD_US 100000u   /* HELLO again until the board answers, */
#define CONNECT_HELLO_PERIOD_MAX_US 800000u /* doubling up to this: each board HELLO restarts
                                             * the window upload, so on a slow link (the HIL VM
                                             * under load: replies after > 100 ms) a HELLO every
                                             * 100 ms drew up to 7 board HELLOs per resync */
#define CONNECT_REARM_PERIOD_US 100000u
#define CONNECT_GRID_EDGE 72
#define CONNECT_SPACING_M 0.00125f
#define CONNECT_CLAY_RADIUS_M 0.030f
#define CONNECT_CLAY_BELOW_M 0.040f       /* clay centre below the workspace centre */
#define CONNECT_CHECKPOINT_S 60.0f        /* the journal rotates onto a new snapshot this often */

static volatile sig_atomic_t g_connect_stop;

/* Ctrl-C or SIGTERM: the solver loop ends the session at its next step. */
static void on_stop_signal(int sig)
{
    (void)sig;
    g_connect_stop = 1;
}

/* What the link thread publishes for the solver thread (relaxed atomics: counters only). */
typedef struct {
    _Atomic uint32_t state;         /* link_state_t */
    _Atomic uint32_t resyncs;       /* reconnections seen (each asks for a HELLO) */
    _Atomic uint32_t frames_rx, frames_tx, errors_rx, errors_tx, reconnects;
    _Atomic uint32_t tx_dropped;    /* frames the transport could not take */
    _Atomic uint32_t auth_refused;  /* keyed UDP: datagrams whose tag did not verify */
} link_pub_t;

typedef struct {
    link_t link;
    spsc_ring_t rx, tx;             /* link → solver, solver → link */
    uint8_t *rx_store, *tx_store;
    link_pub_t pub;
    _Atomic bool stop;
} conn_t;

typedef struct {
    conn_t *c;
    grid_t grid;
    peer_t peer;
    FILE *csv;
    uint32_t csv_rows;
    uint64_t t0_us, now_us;
    /* what the board said */
    uint32_t board_hellos;
    uint32_t board_restarts;        /* telemetry tick went backwards */
    uint32_t active_entries;        /* transitions into ACTIVE */
    uint8_t last_state;
    bool have_tm;
    uint32_t prev_tick;
    uint32_t deadline_misses;
    float peak_force_n;
    /* per status period */
    uint32_t worst_compute_ns;
    uint32_t tick_at_status;
    uint64_t board_us_at_status;
    bool have_status_ref;
    /* window round trip: a window fully sent → telemetry reports it in use */
    uint32_t rtt_version;
    uint64_t rtt_t0_us;
    bool rtt_pending;
    double rtt_ms, rtt_worst_ms;
    uint32_t rtt_samples;
    uint32_t windows_seen;
    /* autosave journal (host/app/peer_journal.h) */
    journal_t journal;
    peer_journal_t journal_steps;
    bool journaling;
    /* undo / redo of strokes (host/app/session_undo.h), asked for on standard input */
    session_undo_t undo;
    session_undo_lines_t cmd;
    bool stdin_open;
    uint32_t undo_solves;           /* peer solves seen by the undo */
} conn_solver_t;

/* The monotonic clock, microseconds. */
static uint64_t mono_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

/* ---- the link thread: frames between the transport and the rings, nothing else ---- */

static void *link_thread(void *arg)
{
    conn_t *c = arg;
    static uint8_t frame[PROTO_FRAME_MAX];
    uint32_t losses = 0, drops = 0;
    while (!atomic_load_explicit(&c->stop, memory_order_acquire)) {
        link_poll(&c->link, 1000u, mono_us());
        /* The poll may have waited, or the whole process been stopped: judge the silence
         * with a fresh clock before taking in the frames that end it. */
        link_set_time(&c->link, mono_us());
        if (c->link.fsm.losses != losses) {
            /* A loss marker in order with the frames: 1 byte, 1 when the transport itself
             * went away (USB unplug), 0 for silence. */
            const uint8_t by_transport = c->link.fsm.transport_drops != drops;
            (void)spsc_push(&c->rx, &by_transport, 1);
            losses = c->link.fsm.losses;
            drops = c->link.fsm.transport_drops;
        }
        size_t n;
        while ((n = link_recv(&c->link, frame, sizeof(frame))) > 0)
            (void)spsc_push(&c->rx, frame, n); /* full: counted by the ring as dropped */
        size_t len;
        while (spsc_pop(&c->tx, frame, sizeof(frame), &len) == ARGIL_OK)
            if (link_send(&c->link, frame, len) != ARGIL_OK)
                atomic_fetch_add_explicit(&c->pub.tx_dropped, 1u, memory_order_relaxed);
        if (link_take_resync(&c->link))
            atomic_fetch_add_explicit(&c->pub.resyncs, 1u, memory_order_relaxed);
        const link_stats_t *s = &c->link.stats;
        atomic_store_explicit(&c->pub.state, (uint32_t)link_state(&c->link), memory_order_relaxed);
        atomic_store_explicit(&c->pub.frames_rx, s->frames_rx, memory_order_relaxed);
        atomic_store_explicit(&c->pub.frames_tx, s->frames_tx, memory_order_relaxed);
        atomic_store_explicit(&c->pub.errors_rx, s->errors_rx, memory_order_relaxed);
        atomic_store_explicit(&c->pub.errors_tx, s->errors_tx, memory_order_relaxed);
        atomic_store_explicit(&c->pub.reconnects, s->reconnects, memory_order_relaxed);
        atomic_store_explicit(&c->pub.auth_refused, s->auth_refused, memory_order_relaxed);
    }
    /* Last frames out (the heartbeat that says we are going). */
    size_t len;
    while (spsc_pop(&c->tx, frame, sizeof(frame), &len) == ARGIL_OK)
        (void)link_send(&c->link, frame, len);
    link_poll(&c->link, 0u, mono_us());
    return NULL;
}

/* ---- the solver thread ---- */

static bool ring_send(void *ctx, const uint8_t *frame, size_t len)
{
    conn_solver_t *s = ctx;
    return spsc_push(&s->c->tx, frame, len) == ARGIL_OK;
}

/* Refusals the board reported in its newest RT_STATS, all reasons together. */
static uint32_t board_refusals(const peer_t *p)
{
    const proto_link_counts_t *l = &p->last_rt.link;
    return l->wrong_source + l->no_session + l->duplicate + l->stale + l->decode_errors +
           l->bad_mac + l->bad_nonce;
}

/* A telemetry frame from the board: counts restarts and ACTIVE entries, times the window
 * round trip and writes the CSV row. */
static void on_telemetry(void *ctx, const msg_telemetry_t *t)
{
    conn_solver_t *s = ctx;
    if (s->have_tm && t->tick < s->prev_tick)
        s->board_restarts++;
    if (t->state == SAFETY_ACTIVE && (!s->have_tm || s->last_state != SAFETY_ACTIVE))
        s->active_entries++;
    s->have_tm = true;
    s->prev_tick = t->tick;
    s->last_state = t->state;
    s->deadline_misses = t->deadline_misses;
    if (t->compute_ns > s->worst_compute_ns)
        s->worst_compute_ns = t->compute_ns;
    const double fn = sqrt((double)t->force_n[0] * t->force_n[0] +
                           (double)t->force_n[1] * t->force_n[1] +
                           (double)t->force_n[2] * t->force_n[2]);
    if ((float)fn > s->peak_force_n)
        s->peak_force_n = (float)fn;
    if (s->rtt_pending && t->window_version == s->rtt_version) {
        s->rtt_pending = false;
        s->rtt_ms = (double)(s->now_us - s->rtt_t0_us) / 1000.0;
        if (s->rtt_ms > s->rtt_worst_ms)
            s->rtt_worst_ms = s->rtt_ms;
        s->rtt_samples++;
    }
    if (!s->csv)
        return;
    fprintf(s->csv, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%s,%u,%u,%u,%u,%u,%.6f,%u,%u,%u\n",
            (double)(s->now_us - s->t0_us) * 1e-6, (double)t->pos_m[0] * 1e3,
            (double)t->pos_m[1] * 1e3, (double)t->pos_m[2] * 1e3, (double)t->force_n[0],
            (double)t->force_n[1], (double)t->force_n[2], fn,
            safety_state_name((safety_state_t)t->state), t->tool_kind, t->buttons, t->flags & 1u,
            (t->flags >> 1) & 1u, t->tick, (double)t->time_us * 1e-6, t->compute_ns / 1000u,
            t->deadline_misses, t->window_version);
    s->csv_rows++;
}

/* The once-a-second status line on stderr (redrawn in place on a terminal). */
static void status_line(conn_solver_t *s, bool tty, double elapsed_s, uint32_t rx_per_s,
                        uint32_t tx_per_s)
{
    const link_state_t ls = (link_state_t)atomic_load(&s->c->pub.state);
    const msg_telemetry_t *t = &s->peer.last_tm;
    double loop_hz = 0.0;
    if (s->have_tm && s->have_status_ref && t->time_us > s->board_us_at_status &&
        t->tick >= s->tick_at_status)
        loop_hz = (double)(t->tick - s->tick_at_status) * 1e6 /
                  (double)(t->time_us - s->board_us_at_status);
    const double fn = s->have_tm ? sqrt((double)t->force_n[0] * t->force_n[0] +
                                        (double)t->force_n[1] * t->force_n[1] +
                                        (double)t->force_n[2] * t->force_n[2])
                                 : 0.0;
    char loop[32], rtt[32];
    if (loop_hz > 0.0)
        snprintf(loop, sizeof(loop), "%5.0f Hz", loop_hz);
    else
        snprintf(loop, sizeof(loop), "    - Hz");
    if (s->rtt_samples > 0)
        snprintf(rtt, sizeof(rtt), "%.1f ms", s->rtt_ms);
    else
        snprintf(rtt, sizeof(rtt), "-");
    fprintf(stderr,
            "%sconnect %6.1f s  link %-9s  board %-6s  loop %s  worst tick %4u us  "
            "window rtt %s  force %.3f N  frames/s in %u out %u  board refused %u%s",
            tty ? "\r" : "", elapsed_s, link_state_name(ls),
            s->have_tm ? safety_state_name((safety_state_t)t->state) : "-", loop,
            s->worst_compute_ns / 1000u, rtt, fn, rx_per_s, tx_per_s, board_refusals(&s->peer),
            tty ? "  " : "\n");
    fflush(stderr);
    s->worst_compute_ns = 0;
    if (s->have_tm) {
        s->tick_at_status = t->tick;
        s->board_us_at_status = t->time_us;
        s->have_status_ref = true;
    }
}

/* ---- undo and redo: command lines on standard input ---- */

/* Reads what standard input has (never waits), queues its undo and redo lines, then works on the
 * queue right after a solve step (session_undo_process); says on stderr what each did. */
static void undo_commands(conn_solver_t *s, bool tty)
{
    const char *nl = tty ? "\n" : "";
    while (s->stdin_open) {
        struct pollfd pfd = {STDIN_FILENO, POLLIN, 0};
        if (poll(&pfd, 1, 0) <= 0 || (pfd.revents & (POLLIN | POLLHUP | POLLERR)) == 0)
            break;
        char buf[256];
        const ssize_t n = read(STDIN_FILENO, buf, sizeof(buf));
        if (n <= 0) {
            if (n < 0 && (errno == EINTR || errno == EAGAIN))
                break;
            s->stdin_open = false; /* end of input: the session goes on */
            break;
        }
        for (ssize_t i = 0; i < n; i++) {
            const session_undo_cmd_t c = session_undo_feed(&s->cmd, buf[i]);
            if (c == SESSION_UNDO_CMD_BAD)
                fprintf(stderr, "%sargil connect: stdin: '%s' is no command (undo, redo)\n", nl,
                        s->cmd.bad);
            else if (c != SESSION_UNDO_CMD_NONE &&
                     !session_undo_request(&s->undo, (session_undo_op_t)c, 0))
                fprintf(stderr, "%sargil connect: %s refused: too many requests waiting\n", nl,
                        c == SESSION_UNDO_CMD_UNDO ? "undo" : "redo");
        }
    }
    const bool solved = s->peer.stats.solves != s->undo_solves;
    s->undo_solves = s->peer.stats.solves;
    const bool held = s->peer.have_tm && (s->peer.last_tm.buttons & 1u) != 0;
    for (;;) {
        int line = 0;
        char msg[160];
        const session_undo_result_t r =
            session_undo_process(&s->undo, &s->peer, held, solved, &line, msg, sizeof(msg));
        if (r == SESSION_UNDO_NONE || r == SESSION_UNDO_WAIT)
            break;
        fprintf(stderr, "%sargil connect: %s (undo %zu | redo %zu)\n", nl, msg,
                session_undo_undo_count(&s->undo), session_undo_redo_count(&s->undo));
    }
}

/* ---- files ---- */

/* Creates the directory path unless it exists (ARGIL_ERR_IO, errno set, when it cannot). */
static argil_err_t make_dir(const char *path)
{
    return mkdir(path, 0777) == 0 || errno == EEXIST ? ARGIL_OK : ARGIL_ERR_IO;
}

/* Writes DIR/final.ply and DIR/model.argil (edits: the journal's edit count) from the clay, as
 * argil sculpt does: painted colour as vertex colours and COLR, a paint tool's settings in TOOL
 * and PNTS; one line into err on failure. */
static argil_err_t write_model(const grid_t *g, const host_tool_t *ht, const char *dir,
                               uint32_t edits, size_t *triangles, char *err, size_t err_len)
{
    mesh_t m;
    mesh_init(&m);
    int32_t rlo[3], rn[3];
    const bool painted = grid_rgb_painted(g);
    uint8_t *rgb = painted ? grid_dense_copy_rgb(g, rlo, rn) : NULL;
    argil_err_t rc = painted && rgb == NULL ? ARGIL_ERR_NOMEM
                     : rgb != NULL          ? grid_mesh_region(g, rgb, g->iso, &m)
                                            : grid_mesh_extract(g, g->iso, &m);
    if (rc != ARGIL_OK) {
        snprintf(err, err_len, "meshing the clay failed");
        mesh_free(&m);
        free(rgb);
        return rc;
    }
    *triangles = m.n_tri;
    argil_doc_t doc;
    argil_doc_init(&doc);
    doc.grid = *g; /* borrowed: the document is not freed */
    doc.rgb = rgb;
    if (host_action_paints(ht->action)) { /* the paint settings; other sessions' files as before */
        doc.tool.paint_chosen = true;
        memcpy(doc.tool.paint_rgb, ht->rgb, 3);
        doc.tool.soft_paint_per_s = ht->action == HOST_ACT_SOFT_PAINT
                                        ? ht->strength
                                        : host_action_default_strength(HOST_ACT_SOFT_PAINT);
    }
    doc.state.edits = edits;
    char ply_path[4096], model_path[4096];
    snprintf(ply_path, sizeof(ply_path), "%s/final.ply", dir);
    snprintf(model_path, sizeof(model_path), "%s/model.argil", dir);
    rc = session_files_write(ply_path, &m, model_path, &doc, err, err_len);
    mesh_free(&m);
    free(rgb);
    return rc;
}

/* ---- the command ---- */

/* The host tool's names for help and errors, ", "-separated: which 'a' every action, 's' the
 * actions that take a strength, 'h' the shapes. wrap > 0: a new line indented by 19 spaces
 * (the help's option column) before a name that would end past column wrap. */
static void host_tool_names(char which, size_t wrap, char *out, size_t cap)
{
    out[0] = '\0';
    size_t line_at = 0; /* where the current line starts in out */
    const int n = which == 'h' ? HOST_SHAPE_COUNT : HOST_ACT_COUNT;
    for (int k = 0; k < n; k++) {
        if (which == 's' && !host_action_has_strength((host_action_t)k))
            continue;
        const char *name = which == 'h' ? host_shape_name((host_shape_t)k)
                                        : host_action_name((host_action_t)k);
        const size_t len = strlen(out);
        const bool wrap_now =
            wrap > 0 && len > 0 && 19 + (len - line_at) + strlen(name) + 2 > wrap;
        const char *sep = len == 0 ? "" : wrap_now ? ",\n                   " : ", ";
        snprintf(out + len, cap - len, "%s%s", sep, name);
        if (wrap_now)
            line_at = len + 2;
    }
}

/* The text of `argil connect --help`. */
static void usage_connect(FILE *f)
{
    char actions[256], strengths[256], shapes[128];
    host_tool_names('a', 88, actions, sizeof(actions));
    host_tool_names('s', 88, strengths, sizeof(strengths));
    host_tool_names('h', 0, shapes, sizeof(shapes));
    fprintf(f,
            "usage: argil connect [--device DEV] [--key FILE] [--seconds N] [--arm]\n"
            "                     [--telemetry FILE.csv]\n"
            "                     [--out DIR] [--quiet] [--global-solve bspline|springs]\n"
            "                     [--knot-ratio 1|2|4] [--action NAME [--strength S]]\n"
            "                     [--shape NAME] [--mirror AXES] [--autosave-s S]\n"
            "                     [--no-journal] [--discard-journal] [--undo-mb N]\n"
            "\n"
            "A live session with a board: the host keeps the global clay, sends the board its\n"
            "local window and tool, applies the impulses the board sends back, and records the\n"
            "board's telemetry. A status line on stderr once a second: link state, board safety\n"
            "state, board loop rate, worst tick compute time, window round trip (a window's last\n"
            "chunk sent -> the board's telemetry reports it in use), force, frames per second.\n"
            "If the link is lost (cable, board restart) the clay is kept and the host\n"
            "resynchronises (HELLO, tool and window again) when the board is back.\n"
            "\n"
            "options:\n"
            "  --device DEV     sim            the simulated board in this process, in real time;\n"
            "                                  its hand holds the stylus still above the clay\n"
            "                   sim:press      the same, its hand pressing the stylus 4 mm into\n"
            "                                  the clay every 2 s with button 1 held\n"
            "                   udp:HOST:PORT  a board daemon on the network (argil-board --link udp:…)\n"
            "                   usb            the first USB board 1209:0001 (default)\n"
            "                   usb:VID:PID    a USB board by vendor and product id (hex)\n"
            "                   usb:BUS-PORT[.PORT…]  a USB board by where it is plugged (lsusb -t)\n"
            "  --key FILE       udp: the link key file the board has (argil keygen FILE; mode\n"
            "                   0600): every datagram carries its tag (docs/link.md). A board\n"
            "                   without a key refuses to arm unless started with --insecure\n"
            "  --seconds N      end after N seconds (default: run until Ctrl-C)\n"
            "  --arm            arm the board (forces on) once it has its window; when it\n"
            "                   faults because it lost the host (link loss, host stall), arm\n"
            "                   it again; any other fault stays latched\n"
            "  --telemetry FILE write the telemetry there (default DIR/telemetry.csv)\n"
            "  --out DIR        where to write final.ply, model.argil and telemetry.csv at the\n"
            "                   end (default out; created if missing)\n"
            "  --quiet          no status line and no summary\n"
            "  --global-solve bspline|springs\n"
            "                   the host's global solve: the implicit B-spline model or the\n"
            "                   explicit density springs on the grid (default springs; bspline\n"
            "                   when --knot-ratio, --action, --shape or --mirror ask for it)\n"
            "  --knot-ratio 1|2|4\n"
            "                   B-spline: grid samples per knot span (default 1, one coefficient\n"
            "                   per sample); 2 or 4 solve fewer coefficients\n"
            "  --action NAME    the board's tool becomes carve, and while stylus button 1 is held\n"
            "                   the host model does NAME at the tip (B-spline; docs/script.md):\n"
            "                   %s\n"
            "  --strength S     per second held, 0..100, for the actions that take one:\n"
            "                   %s\n"
            "  --shape NAME     the host tool's shape: %s (default sphere)\n"
            "  --mirror AXES    also act mirrored across the model's planes: none (default), x,\n"
            "                   y, z or axes together such as xz\n"
            "  --autosave-s S   journal every edit into DIR/journal.log and make it durable\n"
            "                   within S seconds (default 1; docs/files.md); a clean end (also\n"
            "                   Ctrl-C) removes it, after a crash 'argil recover DIR' restores\n"
            "                   the model\n"
            "  --no-journal     no autosave journal\n"
            "  --undo-mb N      memory for undo and redo, MiB (default 256; 0: no undo; needs\n"
            "                   the B-spline model): one step per stroke (a press of stylus\n"
            "                   button 1 that touched the clay, until the next), the oldest\n"
            "                   dropped first. Type 'undo' or 'redo' and Enter on standard\n"
            "                   input (as the sculpt script's verbs; done after the next solve\n"
            "                   step, refused while button 1 is held); each says on stderr\n"
            "                   what it did\n"
            "  --discard-journal\n"
            "                   start even though DIR holds an unfinished session's journal,\n"
            "                   deleting it\n"
            "  -h, --help       this text\n"
            "\n"
            "exit status: 0 ran for --seconds; 130 ended by Ctrl-C or SIGTERM (files written);\n"
            "1 the link could not be opened (no such device, permission), the board never\n"
            "answered, its datagrams had no valid tag for --key, it refused to arm (--arm), or\n"
            "a file could not be written; 2 a bad option, device string or key file.\n"
            "USB without root needs firmware/board/70-argil.rules (docs/link.md).\n",
            actions, strengths, shapes);
}

typedef struct {
    const char *device;
    const char *key_file;           /* udp: the link key (NULL: none) */
    double seconds;                 /* 0: until Ctrl-C */
    bool arm;
    const char *telemetry;
    const char *out_dir;
    bool quiet;
    peer_global_solve_t global_solve;
    int knot_ratio;                 /* B-spline: grid samples per knot span, 1, 2 or 4 */
    host_tool_t host_tool;          /* what the board's carve does on the host */
    bool host_tool_set;             /* --action, --shape or --mirror given: the tool is carve */
    bool journal;                   /* autosave journal in out_dir */
    bool discard_journal;
    float autosave_s;
    uint32_t undo_mb;               /* undo journal budget, MiB (0: no undo) */
} connect_opts_t;

/* The host-model settings after the options: strength against the action, the B-spline model
 * for knots and host tools; ARGIL_ERR_ARG when they do not fit together (one line said why). */
static argil_err_t check_model_opts(connect_opts_t *o, bool solve_given, bool strength_given,
                            const char *host_opt)
{
    host_tool_t *t = &o->host_tool;
    if (strength_given && !host_action_has_strength(t->action)) {
        char list[256];
        host_tool_names('s', 0, list, sizeof(list));
        fprintf(stderr, "argil connect: --strength: action '%s' takes none (only %s do)\n",
                host_action_name(t->action), list);
        return ARGIL_ERR_ARG;
    }
    if (!strength_given)
        t->strength = host_action_default_strength(t->action);
    const char *needs = o->knot_ratio > 1 ? "--knot-ratio" : host_opt;
    if (needs && o->global_solve == PEER_SOLVE_SPRINGS) {
        if (solve_given) {
            fprintf(stderr, "argil connect: %s needs the B-spline model (--global-solve "
                            "bspline), not springs\n", needs);
            return ARGIL_ERR_ARG;
        }
        o->global_solve = PEER_SOLVE_BSPLINE;
    }
    return ARGIL_OK;
}

/* Which host-model options parse_opts met, for check_model_opts to judge together. */
typedef struct {
    bool solve_given, strength_given;
    const char *host_opt;           /* the first of --action, --shape, --mirror given */
} model_opts_seen_t;

/* Takes the host-model option argv[*i] (--strength, --action, --shape, --mirror), moving *i
 * past its value. */
static cli_opt_t take_model_opt(connect_opts_t *o, model_opts_seen_t *seen, int argc,
                                char **argv, int *i)
{
    const char *a = argv[*i];
    const char *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (strcmp(a, "--strength") == 0) {
        char *end = NULL;
        const double x = v ? strtod(v, &end) : 0.0;
        if (!v || end == v || *end != '\0' || !(x >= 0.0 && x <= HOST_STRENGTH_MAX)) {
            fprintf(stderr, "argil connect: --strength needs a number 0..%g (per second "
                            "held)\n", (double)HOST_STRENGTH_MAX);
            return CLI_OPT_BAD;
        }
        o->host_tool.strength = (float)x;
        seen->strength_given = true;
    } else if (strcmp(a, "--action") == 0 || strcmp(a, "--shape") == 0 ||
               strcmp(a, "--mirror") == 0) {
        const int k = !v                 ? -1
                      : a[2] == 'a'      ? host_action_from_name(v)
                      : a[2] == 's'      ? host_shape_from_name(v)
                                         : host_mirror_from_name(v);
        if (k < 0) {
            char list[256];
            host_tool_names(a[2] == 's' ? 'h' : 'a', 0, list, sizeof(list));
            fprintf(stderr, "argil connect: %s needs %s, got '%s'\n", a,
                    a[2] == 'm' ? "none, or the axes x, y, z (e.g. xz)" : list,
                    v ? v : "nothing");
            return CLI_OPT_BAD;
        }
        if (a[2] == 'a')
            o->host_tool.action = (host_action_t)k;
        else if (a[2] == 's')
            o->host_tool.shape = (host_shape_t)k;
        else
            o->host_tool.mirror = (uint32_t)k;
        o->host_tool_set = true;
        if (!seen->host_opt)
            seen->host_opt = a;
    } else {
        return CLI_OPT_OTHER;
    }
    (*i)++;
    return CLI_OPT_TAKEN;
}

/* What parse_opts's option reader works on: the options and what it met. */
typedef struct {
    connect_opts_t o;
    model_opts_seen_t seen;
} connect_parse_t;

/* The options of argil connect that are not flags or plain words: the session's, the host
 * model's and --seconds. */
static cli_opt_t take_connect_opt(void *opts, int argc, char **argv, int *i)
{
    connect_parse_t *cp = opts;
    connect_opts_t *o = &cp->o;
    const cli_session_t shared = {&o->global_solve, &cp->seen.solve_given, &o->knot_ratio, NULL,
                                  &o->autosave_s, NULL, &o->undo_mb};
    cli_opt_t r = cli_session_option("connect", &shared, argc, argv, i);
    if (r == CLI_OPT_OTHER)
        r = take_model_opt(o, &cp->seen, argc, argv, i);
    if (r != CLI_OPT_OTHER || strcmp(argv[*i], "--seconds") != 0)
        return r;
    const char *v = cli_value("connect", "a value", argc, argv, i);
    if (!v)
        return CLI_OPT_BAD;
    char *end;
    errno = 0;
    const double sec = strtod(v, &end);
    if (errno || end == v || *end != '\0' || !(sec > 0.0) || sec > 1e7) {
        fprintf(stderr, "argil connect: --seconds must be a number > 0, got '%s'\n", v);
        return CLI_OPT_BAD;
    }
    o->seconds = sec;
    return CLI_OPT_TAKEN;
}

/* argil connect's command line (cli_parse). */
static const cli_flag_t CONNECT_FLAGS[] = {
    {"--arm", offsetof(connect_parse_t, o.arm), true},
    {"--quiet", offsetof(connect_parse_t, o.quiet), true},
    {"--no-journal", offsetof(connect_parse_t, o.journal), false},
    {"--discard-journal", offsetof(connect_parse_t, o.discard_journal), true},
};
static const cli_word_t CONNECT_WORDS[] = {
    {"--device", offsetof(connect_parse_t, o.device)},
    {"--key", offsetof(connect_parse_t, o.key_file)},
    {"--telemetry", offsetof(connect_parse_t, o.telemetry)},
    {"--out", offsetof(connect_parse_t, o.out_dir)},
};
static const cli_cmd_t CONNECT_CLI = {
    .name = "connect", .usage = usage_connect, .option = take_connect_opt,
    .flags = CONNECT_FLAGS, .n_flags = 4, .words = CONNECT_WORDS, .n_words = 4,
};

/* Parses the options into *o. Sets *done after --help (the usage printed, exit status 0) and
 * after a bad option, device string or pairing of them (one line said why, exit status 2). */
static argil_err_t parse_opts(int argc, char **argv, connect_opts_t *o, bool *done,
                              int *exit_status)
{
    connect_parse_t cp = {.seen = {false, false, NULL}};
    cp.o.device = "usb";
    cp.o.out_dir = "out";
    cp.o.global_solve = PEER_SOLVE_SPRINGS; /* connect's default (peer_cfg_default) */
    cp.o.knot_ratio = 1;
    host_tool_default(&cp.o.host_tool);
    cp.o.journal = true;
    cp.o.autosave_s = 1.0f;
    cp.o.undo_mb = SESSION_UNDO_MB_DEFAULT;
    argil_err_t e = cli_parse(&CONNECT_CLI, &cp, argc, argv, done, exit_status);
    *o = cp.o;
    if (*done)
        return e;
    *done = true;
    *exit_status = 2;
    e = check_model_opts(o, cp.seen.solve_given, cp.seen.strength_given, cp.seen.host_opt);
    if (e != ARGIL_OK)
        return e;
    link_spec_t spec;
    const link_spec_err_t pe = link_spec_parse(o->device, &spec);
    if (pe != LINK_SPEC_OK) {
        fprintf(stderr, "argil connect: bad device '%s': %s\n", o->device,
                link_spec_err_text(pe));
        return ARGIL_ERR_ARG;
    }
    if (o->key_file && spec.kind != LINK_KIND_UDP) {
        fprintf(stderr, "argil connect: --key is for udp: devices (USB is a cable to one board "
                        "and the sim board is in this process: neither needs a key)\n");
        return ARGIL_ERR_ARG;
    }
    *done = false;
    return ARGIL_OK;
}

/* The tool the board is sent first: touch, 4 mm, the board's own force limits. */
static void default_tool(msg_tool_t *t)
{
    memset(t, 0, sizeof(*t));
    t->kind = TOOL_TOUCH;
    t->flags = TOOL_FLAG_ISO;
    t->radius_m = 0.004f;
    t->axis[2] = 1.0f;
    t->alpha = 12000.0f;
    t->contact_stiffness_n_per_m = 800.0f;
    t->max_force_n = 3.3f;
    t->iso = 0.5f;
    t->model_scale = 1.0f;
}

/* Opens the CSV (as a .tmp file renamed at the end); one line into err on failure. */
static argil_err_t open_csv(conn_solver_t *s, const char *path, char *tmp, size_t tmp_len, char *err,
                            size_t err_len)
{
    snprintf(tmp, tmp_len, "%s.tmp", path);
    s->csv = fopen(tmp, "wb");
    if (!s->csv) {
        snprintf(err, err_len, "%s: cannot create: %s", tmp, strerror(errno));
        return ARGIL_ERR_IO;
    }
    fprintf(s->csv, "time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state,tool,buttons,contact,"
                    "sculpting,tick,board_time_s,compute_us,deadline_misses,window_version\n");
    return ARGIL_OK;
}

/* Why a UDP board may stay silent to this host, for the "no answer" lines. */
static const char *udp_key_hint(const connect_opts_t *o)
{
    if (strncmp(o->device, "udp:", 4) != 0)
        return "";
    return o->key_file ? "; a board answers a host with --key only when started with --key and "
                         "the same key file (a board without a key refuses tagged datagrams)"
                       : "; a board started with --key answers only a host given the same key "
                         "file: --key FILE";
}

/* The summary's words on the link's authentication. */
static const char *link_auth_summary(const connect_opts_t *o, conn_t *c)
{
    static char text[160];
    if (strncmp(o->device, "udp:", 4) != 0)
        return "no key needed (one host on the cable)";
    if (!o->key_file)
        return "no key (unauthenticated UDP)";
    snprintf(text, sizeof(text), "key %s, datagrams with a bad tag %u", o->key_file,
             atomic_load(&c->pub.auth_refused));
    return text;
}

/* The link's authentication says the session cannot go on (one line on stderr, true): a keyed
 * host that hears only datagrams with no valid tag (the board has another key, or none) for
 * 1 s, or an --arm session on a board that refuses to arm without a key. A keyless host that
 * hears nothing from a UDP board for 2 s is told once what a keyed board needs. */
static bool link_refusal_ends(conn_solver_t *s, const connect_opts_t *o, double elapsed_s,
                              bool *udp_hinted, bool tty)
{
    const char *nl = tty ? "\n" : "";
    const uint32_t refused = atomic_load_explicit(&s->c->pub.auth_refused, memory_order_relaxed);
    const uint32_t rx = atomic_load_explicit(&s->c->pub.frames_rx, memory_order_relaxed);
    if (o->key_file && refused > 0 && rx == 0 && elapsed_s >= 1.0) {
        fprintf(stderr, "%sargil connect: %s: %u datagrams from the board carried no valid tag "
                "for the key in %s: start argil-board with --key and the same key file\n", nl,
                o->device, refused, o->key_file);
        return true;
    }
    if (o->arm && s->peer.last_rt.link.arm_refused > 0) {
        fprintf(stderr, "%sargil connect: the board refuses to arm over UDP without a link key: "
                "start argil-board with --key FILE (argil keygen FILE) and give connect the same "
                "--key FILE, or start it with --insecure\n", nl);
        return true;
    }
    if (!*udp_hinted && rx == 0 && elapsed_s >= 2.0 && strncmp(o->device, "udp:", 4) == 0) {
        fprintf(stderr, "%sargil connect: no answer from %s yet (is argil-board running there?)%s\n",
                nl, o->device, udp_key_hint(o));
        *udp_hinted = true;
    }
    return false;
}

/* One connect session from its options to its summary: what the steps below share. */
typedef struct {
    connect_opts_t o;
    bool tty;                       /* stderr is a terminal: the status line redraws in place */
    conn_t *c;
    conn_solver_t *s;
    msg_tool_t board_tool;          /* the tool the board was sent */
    char csv_path[4096], csv_tmp[4200];
    bool interrupted;               /* Ctrl-C or SIGTERM ended the session */
    char journal_err[1024];         /* why the autosave journal stopped ("": it did not) */
    double ran_s;                   /* from the solver loop's start to the link thread's end */
    uint32_t frames_rx;             /* frames the link took in over the whole session */
    size_t triangles;               /* in the final.ply written */
} connect_session_t;

/* The solver loop's own state: its clock, when to say HELLO and arm again, the last status. */
typedef struct {
    uint64_t last_us, next_us, status_at_us;
    uint64_t last_hello_us, last_rearm_us;
    bool hello_wanted, rearm_pending;
    uint32_t hello_period_us;
    uint32_t seen_resyncs, restarts_seen, rx_at_status, tx_at_status;
    uint32_t windows_at_last;
    /* What the host knew when the link was lost (for the re-arm rule). */
    uint32_t faults_at_loss, faults_seen;
    bool loss_by_transport, bad_before_loss;
    bool udp_hinted;
} conn_loop_t;

/* Sets up the rings and opens the link (keyed with --key); when it cannot, one line says why
 * (ARGIL_ERR_ARG: a bad key file). */
static argil_err_t connect_open_link(connect_session_t *cs)
{
    conn_t *c = cs->c;
    const connect_opts_t *o = &cs->o;
    char err[1024] = "";
    c->rx_store = malloc(CONNECT_RX_RING_BYTES);
    c->tx_store = malloc(CONNECT_TX_RING_BYTES);
    if (!c->rx_store || !c->tx_store ||
        spsc_init(&c->rx, c->rx_store, CONNECT_RX_RING_BYTES) != ARGIL_OK ||
        spsc_init(&c->tx, c->tx_store, CONNECT_TX_RING_BYTES) != ARGIL_OK) {
        fprintf(stderr, "argil connect: out of memory\n");
        return ARGIL_ERR_NOMEM;
    }
    link_key_t key;
    if (o->key_file && !link_crypto_init()) {
        fprintf(stderr, "argil connect: libsodium cannot start (no random source?)\n");
        return ARGIL_ERR_STATE;
    }
    if (o->key_file && link_key_file_load(o->key_file, &key, err, sizeof(err)) != LINK_KEY_OK) {
        fprintf(stderr, "argil connect: %s\n", err);
        return ARGIL_ERR_ARG;
    }
    const argil_err_t lo =
        link_open_keyed(&c->link, o->device, o->key_file ? key.k : NULL, err, sizeof(err));
    link_crypto_wipe(&key, sizeof(key));
    if (lo != ARGIL_OK)
        fprintf(stderr, "argil connect: %s\n", err);
    return lo;
}

/* The host's clay, a sphere just below the arm's workspace centre (device = model), and the
 * peer on it; when it cannot, one line says why and nothing is left to free. */
static argil_err_t connect_clay_open(connect_session_t *cs)
{
    conn_solver_t *s = cs->s;
    arm_desc_t arm_desc;
    arm_desc_default(&arm_desc);
    const vec3_t centre = arm_workspace_centre(&arm_desc);
    const int32_t dims[3] = {CONNECT_GRID_EDGE, CONNECT_GRID_EDGE, CONNECT_GRID_EDGE};
    const float half = 0.5f * (float)(CONNECT_GRID_EDGE - 1) * CONNECT_SPACING_M;
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    pc.adaptive_region = true; /* real time: a slow solve narrows its region, never the board */
    pc.global_solve = cs->o.global_solve;
    pc.knot_ratio = cs->o.knot_ratio;
    /* The sphere is in the grid before the peer starts: the B-spline model is fitted to the
     * grid as peer_init finds it (an empty grid gave an empty model, whose solve then emptied
     * the clay inside every window it stepped). */
    argil_err_t e =
        grid_init(&s->grid, dims, CONNECT_SPACING_M, vec3_sub(centre, vec3(half, half, half)));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil connect: out of memory for the clay\n");
        return e;
    }
    grid_fill_sphere(&s->grid, vec3_sub(centre, vec3(0, 0, CONNECT_CLAY_BELOW_M)),
                     CONNECT_CLAY_RADIUS_M);
    if ((e = peer_init(&s->peer, &pc, &s->grid, ring_send, on_telemetry, s)) != ARGIL_OK) {
        fprintf(stderr, "argil connect: out of memory for the clay\n");
        grid_free(&s->grid);
    }
    return e;
}

/* Frees the clay, its peer and its undo; a journal still open keeps its files (the end was not
 * clean). */
static void connect_clay_close(conn_solver_t *s)
{
    if (s->journaling)
        journal_close(&s->journal); /* keeps its files: the end was not clean */
    session_undo_free(&s->undo);
    peer_free(&s->peer);
    grid_free(&s->grid);
}

/* Gives the peer the host tool and the board's tool, asks it to arm the board with --arm and
 * sets up undo; a refused host tool is said in one line. */
static argil_err_t connect_tools_init(connect_session_t *cs)
{
    conn_solver_t *s = cs->s;
    const connect_opts_t *o = &cs->o;
    const argil_err_t e = peer_set_host_tool(&s->peer, &o->host_tool);
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil connect: the host tool was refused (needs the B-spline model)\n");
        return e;
    }
    default_tool(&cs->board_tool);
    if (o->host_tool_set)
        cs->board_tool.kind = TOOL_CARVE; /* the host tool acts while the board's carve is held */
    peer_set_tool(&s->peer, &cs->board_tool);
    if (o->arm)
        peer_request_arm(&s->peer);
    /* Undo: off with the springs (their grid keeps no history) or --undo-mb 0 (the summary
     * says so; a request is refused with that reason). */
    (void)session_undo_init(&s->undo, s->peer.gs ? &s->peer.gs->field : NULL,
                            (size_t)o->undo_mb << 20);
    s->stdin_open = true;
    return ARGIL_OK;
}

/* Closes the telemetry CSV of a session that did not run and removes it. */
static void connect_csv_discard(connect_session_t *cs)
{
    fclose(cs->s->csv);
    unlink(cs->csv_tmp);
}

/* Creates the output directory, the telemetry CSV and (unless --no-journal) the autosave
 * journal; when it cannot, one line says why and no CSV is left open. */
static argil_err_t connect_files_open(connect_session_t *cs)
{
    conn_solver_t *s = cs->s;
    const connect_opts_t *o = &cs->o;
    char err[1024] = "";
    argil_err_t e = make_dir(o->out_dir);
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil connect: %s: cannot create directory: %s\n", o->out_dir,
                strerror(errno));
        return e;
    }
    if (o->telemetry)
        snprintf(cs->csv_path, sizeof(cs->csv_path), "%s", o->telemetry);
    else
        snprintf(cs->csv_path, sizeof(cs->csv_path), "%s/telemetry.csv", o->out_dir);
    e = open_csv(s, cs->csv_path, cs->csv_tmp, sizeof(cs->csv_tmp), err, sizeof(err));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil connect: %s\n", err);
        return e;
    }
    if (o->journal) {
        e = peer_journal_open(&s->journal, o->out_dir, &s->grid, o->autosave_s,
                              CONNECT_CHECKPOINT_S, err, sizeof(err));
        if (e != ARGIL_OK) {
            fprintf(stderr, "argil connect: %s\n", err);
            connect_csv_discard(cs);
            return e;
        }
        s->journaling = true;
    }
    return ARGIL_OK;
}

/* From here on Ctrl-C and SIGTERM end the session at the solver's next step, not the process. */
static void connect_catch_signals(void)
{
    g_connect_stop = 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_stop_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

/* Takes in what the link thread received: a loss marker asks for HELLO again (and notes what
 * the host knew for the re-arm rule), a board HELLO ends the asking, every frame goes to the
 * peer. */
static void solver_take_frames(conn_solver_t *s, conn_loop_t *loop)
{
    static uint8_t frame[PROTO_FRAME_MAX];
    size_t n;
    while (spsc_pop(&s->c->rx, frame, sizeof(frame), &n) == ARGIL_OK) {
        if (n == 1) { /* the link thread's loss marker */
            loop->loss_by_transport = frame[0] != 0;
            loop->faults_at_loss = s->peer.stats.faults;
            loop->bad_before_loss = s->have_tm && (s->last_state == SAFETY_FAULT ||
                                                   s->last_state == SAFETY_ESTOP);
            /* Say HELLO until the board answers: a restarted board, or one whose session
             * ended, serves no host until one does (it is silent to us until then). */
            loop->hello_wanted = true;
            loop->last_hello_us = 0;
            loop->hello_period_us = CONNECT_HELLO_PERIOD_US;
            continue;
        }
        if (n > PROTO_HEADER_SIZE && frame[5] == MSG_HELLO && frame[12] == PROTO_ROLE_BOARD) {
            s->board_hellos++;
            loop->hello_wanted = false;
        }
        peer_receive(&s->peer, frame, n);
    }
}

/* Keeps the board in session with this host: HELLO again (backing off) after a reconnection
 * or a restarted board, and with --arm (arm) arm it again after it lost the host. */
static void solver_keep_session(conn_solver_t *s, conn_loop_t *loop, bool arm)
{
    /* Resynchronise after a reconnection or a restarted board (its tick went back). */
    const uint32_t r = atomic_load_explicit(&s->c->pub.resyncs, memory_order_relaxed);
    if (r != loop->seen_resyncs || s->board_restarts != loop->restarts_seen) {
        loop->seen_resyncs = r;
        loop->restarts_seen = s->board_restarts;
        loop->hello_wanted = true;
        loop->last_hello_us = 0;
        loop->hello_period_us = CONNECT_HELLO_PERIOD_US;
        loop->rearm_pending = arm;
    }
    /* The board says it lost the host (this host stalled, or the link dropped and came
     * back before our silence timeout): as after a reconnection, arm again. */
    if (s->peer.stats.faults != loop->faults_seen) {
        loop->faults_seen = s->peer.stats.faults;
        if (s->peer.stats.last_fault_code == FAULT_HOST_LOST)
            loop->rearm_pending = arm;
    }
    if (loop->hello_wanted && s->now_us - loop->last_hello_us >= loop->hello_period_us) {
        (void)peer_send_hello(&s->peer, "argil connect");
        loop->last_hello_us = s->now_us;
        if (loop->hello_period_us < CONNECT_HELLO_PERIOD_MAX_US)
            loop->hello_period_us *= 2u;
    }
    /* A link loss faulted the board (host lost): the person asked for --arm, so arm again
     * once the board has its new window. Any other fault stays latched. The board reports
     * a fault once, and over USB that FAULT frame is dropped while unplugged: when none
     * arrived since the loss, the loss was the transport's own (both directions dead for
     * longer than the board's host timeout) and the board was not faulted before it, the
     * fault can only be host lost. */
    if (loop->rearm_pending && s->have_tm) {
        const uint8_t bs = s->peer.last_tm.state;
        const bool heard = s->peer.stats.faults != loop->faults_at_loss;
        const bool host_lost = heard ? s->peer.stats.last_fault_code == FAULT_HOST_LOST
                                     : loop->loss_by_transport && !loop->bad_before_loss;
        if (bs == SAFETY_ACTIVE || bs == SAFETY_ARMED) {
            loop->rearm_pending = false; /* armed again (an IDLE board is armed by the peer) */
        } else if (bs == SAFETY_FAULT && host_lost && s->peer.have_current &&
                   !loop->hello_wanted &&
                   s->now_us - loop->last_rearm_us >= CONNECT_REARM_PERIOD_US) {
            (void)peer_send_command(&s->peer, PROTO_CMD_ARM);
            loop->last_rearm_us = s->now_us;
        }
    }
}

/* Advances the host model by the time since the last step (at most 50 ms), works on undo and
 * redo requests, journals the edits and starts timing a window that went out. */
static void solver_step(connect_session_t *cs, conn_loop_t *loop, double elapsed_s)
{
    conn_solver_t *s = cs->s;
    uint64_t dt_us = s->now_us - loop->last_us;
    if (dt_us > 50000u)
        dt_us = 50000u; /* after a stall, do not replay time */
    if (dt_us > 0) {
        /* a press starts a stroke; the last one's diff goes a slice a tick */
        session_undo_observe(&s->undo, &s->peer, (uint32_t)dt_us);
        peer_tick(&s->peer, (uint32_t)dt_us);
        loop->last_us = s->now_us;
    }
    undo_commands(s, cs->tty);
    if (s->journaling) {
        char err[1024] = "";
        bool stop_now = false;
        if (peer_journal_step(&s->journal, &s->journal_steps, &s->peer, elapsed_s, &stop_now,
                              err, sizeof(err)) != ARGIL_OK) {
            /* The person keeps sculpting; the end says the journal broke (exit 1). */
            fprintf(stderr, "%sargil connect: autosave journal stopped: %s\n",
                    cs->tty ? "\n" : "", err);
            snprintf(cs->journal_err, sizeof(cs->journal_err), "%s", err);
            journal_close(&s->journal);
            s->journaling = false;
        }
    }
    if (s->peer.stats.windows_sent != loop->windows_at_last) {
        loop->windows_at_last = s->peer.stats.windows_sent;
        s->rtt_version = s->peer.current.version;
        s->rtt_t0_us = s->now_us;
        s->rtt_pending = true;
    }
}

/* Runs the solver every 1 ms until --seconds (ARGIL_OK), Ctrl-C or SIGTERM (ARGIL_OK,
 * cs->interrupted) or until the link's authentication ends the session (ARGIL_ERR_STATE, one
 * line said why). */
static argil_err_t connect_loop(connect_session_t *cs)
{
    conn_solver_t *s = cs->s;
    conn_t *c = cs->c;
    const connect_opts_t *o = &cs->o;
    s->t0_us = mono_us();
    conn_loop_t loop;
    memset(&loop, 0, sizeof(loop));
    loop.last_us = s->t0_us;
    loop.next_us = s->t0_us;
    loop.status_at_us = s->t0_us + 1000000u;
    loop.hello_wanted = true;
    loop.hello_period_us = CONNECT_HELLO_PERIOD_US;
    for (;;) {
        s->now_us = mono_us();
        const double elapsed_s = (double)(s->now_us - s->t0_us) * 1e-6;
        if (g_connect_stop) {
            cs->interrupted = true;
            return ARGIL_OK;
        }
        if (o->seconds > 0 && elapsed_s >= o->seconds)
            return ARGIL_OK;
        solver_take_frames(s, &loop);
        solver_keep_session(s, &loop, o->arm);
        solver_step(cs, &loop, elapsed_s);
        if (link_refusal_ends(s, o, elapsed_s, &loop.udp_hinted, cs->tty))
            return ARGIL_ERR_STATE;
        if (s->now_us >= loop.status_at_us) {
            const uint32_t rx = atomic_load(&c->pub.frames_rx);
            const uint32_t tx = atomic_load(&c->pub.frames_tx);
            if (!o->quiet)
                status_line(s, cs->tty, elapsed_s, rx - loop.rx_at_status,
                            tx - loop.tx_at_status);
            loop.rx_at_status = rx;
            loop.tx_at_status = tx;
            loop.status_at_us += 1000000u;
        }
        loop.next_us += 1000u;
        if (loop.next_us + 20000u < s->now_us)
            loop.next_us = s->now_us; /* fell far behind: do not try to catch up */
        const struct timespec ts = {(time_t)(loop.next_us / 1000000u),
                                    (long)(loop.next_us % 1000000u) * 1000L};
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
    }
}

/* Tells the board we are going, stops the link thread (lt) and takes in its last frames; notes
 * how long the session ran and how many frames came in. */
static void connect_stop(connect_session_t *cs, pthread_t lt)
{
    conn_solver_t *s = cs->s;
    conn_t *c = cs->c;
    static uint8_t frame[PROTO_FRAME_MAX];
    /* Tell the board we are going: END disarms (forces off at once, not after the host-lost
     * fade) and ends our session, so the next host need not wait for it to lapse. */
    if (s->have_tm)
        (void)peer_send_command(&s->peer, PROTO_CMD_END);
    atomic_store_explicit(&c->stop, true, memory_order_release);
    pthread_join(lt, NULL);
    /* Frames the link thread took in after the solver stopped reading. */
    size_t n;
    while (spsc_pop(&c->rx, frame, sizeof(frame), &n) == ARGIL_OK)
        if (n > 1) /* not a loss marker */
            peer_receive(&s->peer, frame, n);
    if (cs->tty && !cs->o.quiet)
        fputc('\n', stderr);
    cs->ran_s = (double)(mono_us() - s->t0_us) * 1e-6;
    cs->frames_rx = atomic_load(&c->pub.frames_rx);
}

/* Writes the telemetry, the clay's surface and the model; a clean end (e: how the session
 * ended, ARGIL_OK) removes the journal. Returns e, else the first file that could not be
 * written, or ARGIL_ERR_IO when the journal had stopped. */
static argil_err_t connect_write_files(connect_session_t *cs, argil_err_t e)
{
    conn_solver_t *s = cs->s;
    char err[1024] = "";
    int bad = fflush(s->csv) != 0 || fsync(fileno(s->csv)) != 0;
    bad |= fclose(s->csv) != 0;
    s->csv = NULL;
    if (bad || rename(cs->csv_tmp, cs->csv_path) != 0) {
        fprintf(stderr, "argil connect: %s: cannot write: %s\n", cs->csv_path, strerror(errno));
        e = e != ARGIL_OK ? e : ARGIL_ERR_IO;
    }
    const argil_err_t we = write_model(&s->grid, &s->peer.host_tool, cs->o.out_dir,
                                       s->journaling ? s->journal.seq : 0u, &cs->triangles, err,
                                       sizeof(err));
    if (we != ARGIL_OK) {
        fprintf(stderr, "argil connect: %s\n", err);
        e = e != ARGIL_OK ? e : we;
    }
    /* A clean end: the files are whole, so the journal is no longer needed. */
    if (s->journaling && e == ARGIL_OK) {
        s->journaling = false;
        if ((e = journal_finish(&s->journal, err, sizeof(err))) != ARGIL_OK)
            fprintf(stderr, "argil connect: %s\n", err);
    }
    if (cs->journal_err[0] != '\0' && e == ARGIL_OK)
        e = ARGIL_ERR_IO;
    return e;
}

/* Prints the session's summary on stdout: link, board, protocol, solve, tool, undo, files and
 * journal. */
static void connect_summary(const connect_session_t *cs)
{
    const connect_opts_t *o = &cs->o;
    conn_t *c = cs->c;
    const conn_solver_t *s = cs->s;
    const uint32_t rx_drop = atomic_load(&c->rx.dropped);
    printf("argil connect: %s for %.1f s%s\n", o->device, cs->ran_s,
           cs->interrupted ? " (interrupted)" : "");
    printf("  link                %s; frames in %u, out %u; receive errors %u, send errors "
           "%u, reconnects %u, frames dropped %u; %s\n",
           link_state_name((link_state_t)atomic_load(&c->pub.state)), cs->frames_rx,
           atomic_load(&c->pub.frames_tx), atomic_load(&c->pub.errors_rx),
           atomic_load(&c->pub.errors_tx), atomic_load(&c->pub.reconnects),
           rx_drop + atomic_load(&c->pub.tx_dropped), link_auth_summary(o, c));
    printf("  board               %s; ACTIVE entered %u times; board HELLOs %u; restarts "
           "seen %u; deadline misses %u; peak force %.3f N\n",
           s->have_tm ? safety_state_name((safety_state_t)s->last_state) : "never heard",
           s->active_entries, s->board_hellos, s->board_restarts, s->deadline_misses,
           (double)s->peak_force_n);
    const proto_link_counts_t *l = &s->peer.last_rt.link;
    if (s->peer.stats.rt_stats_frames > 0)
        printf("  board link          host sessions %u; host frames refused: wrong source "
               "%u, no session %u, duplicate %u, stale %u, decode errors %u, bad tag %u, "
               "bad nonce %u; ARM refused %u\n",
               l->sessions, l->wrong_source, l->no_session, l->duplicate, l->stale,
               l->decode_errors, l->bad_mac, l->bad_nonce, l->arm_refused);
    else
        printf("  board link          no RT_STATS report from the board\n");
    printf("  protocol            telemetry rows %u (%.0f per s); decode errors %u; windows "
           "sent %u; impulse frames %u; faults %u%s%s%s\n",
           s->csv_rows, cs->ran_s > 0 ? s->csv_rows / cs->ran_s : 0.0,
           s->peer.stats.decode_errors, s->peer.stats.windows_sent,
           s->peer.stats.impulse_frames, s->peer.stats.faults,
           s->peer.stats.faults ? " (last: " : "",
           s->peer.stats.faults
               ? safety_fault_name((fault_code_t)s->peer.stats.last_fault_code)
               : "",
           s->peer.stats.faults ? ")" : "");
    double med = 0, p99 = 0, mx = 0;
    peer_solve_times_ms(&s->peer, &med, &p99, &mx);
    printf("  global solve        %s, %u steps, CPU time per step median %.2f ms, 99th "
           "percentile %.2f ms, max %.2f ms; region narrowed %u times (margin %d..%d "
           "samples)\n",
           cli_global_solve_text(o->global_solve), s->peer.stats.solves, med, p99, mx,
           s->peer.sched.shrinks, (int)s->peer.sched.margin_min, SOLVE_MARGIN_MAX);
    if (o->global_solve == PEER_SOLVE_BSPLINE)
        printf("  knots               %d sample%s per knot span\n", o->knot_ratio,
               o->knot_ratio == 1 ? "" : "s");
    char mirror[8], strength[48] = "";
    const host_tool_t *t = &s->peer.host_tool;
    const bool carve = cs->board_tool.kind == TOOL_CARVE;
    host_mirror_name(t->mirror, mirror);
    if (host_action_has_strength(t->action))
        snprintf(strength, sizeof(strength), ", strength %g per s", (double)t->strength);
    printf("  tool                board %s; host action %s, shape %s, mirror %s%s%s\n",
           carve ? "carve" : "touch", host_action_name(t->action), host_shape_name(t->shape),
           mirror, strength, carve ? " (while stylus button 1 is held)" : " (idle)");
    if (s->rtt_samples > 0)
        printf("  window round trip   last %.1f ms, worst %.1f ms (%u windows)\n", s->rtt_ms,
               s->rtt_worst_ms, s->rtt_samples);
    if (s->undo.on)
        printf("  undo                %u stroke%s recorded (%u undone, %u redone, %u refused), "
               "%.1f KiB held of %u MiB; recording CPU time per tick median %.2f ms, max "
               "%.2f ms\n",
               s->undo.stats.steps, s->undo.stats.steps == 1 ? "" : "s", s->undo.stats.undos,
               s->undo.stats.redos, s->undo.stats.refused,
               (double)session_undo_bytes(&s->undo) / 1024.0, o->undo_mb,
               session_undo_work_median_ms(&s->undo), s->undo.stats.max_work_ms);
    else
        printf("  undo                %s\n", s->undo.off_reason);
    printf("  files               %s (%u rows), %s/final.ply (%zu triangles), %s/model.argil\n",
           cs->csv_path, s->csv_rows, o->out_dir, cs->triangles, o->out_dir);
    const journal_stats_t *js = &s->journal.stats;
    if (cs->journal_err[0] != '\0')
        printf("  autosave journal    STOPPED: %s\n", cs->journal_err);
    else if (o->journal)
        printf("  autosave journal    %u edits journaled, %.1f KiB, %u fsyncs, %u "
               "checkpoints, %.1f ms of work; %s\n",
               js->records, (double)js->bytes / 1024.0, js->syncs, js->checkpoints,
               s->journal_steps.real_s * 1e3,
               s->journaling ? "KEPT (the end was not clean): 'argil recover' restores"
                             : "removed at this clean end");
}

/* The session on the clay: the tools, the files, the link thread and the solver loop, then the
 * files written and the summary; the exit status into *exit_status. */
static argil_err_t connect_run(connect_session_t *cs, int *exit_status)
{
    const connect_opts_t *o = &cs->o;
    argil_err_t e = connect_tools_init(cs);
    if (e == ARGIL_OK)
        e = connect_files_open(cs);
    if (e != ARGIL_OK)
        return cmd_end(exit_status, 1, e);
    connect_catch_signals();
    pthread_t lt;
    if (pthread_create(&lt, NULL, link_thread, cs->c) != 0) {
        fprintf(stderr, "argil connect: cannot start the link thread\n");
        connect_csv_discard(cs);
        return cmd_end(exit_status, 1, ARGIL_ERR_STATE);
    }
    e = connect_loop(cs);
    connect_stop(cs, lt);
    e = connect_write_files(cs, e);
    if (!o->quiet)
        connect_summary(cs);
    if (cs->frames_rx == 0 && e == ARGIL_OK) {
        fprintf(stderr, "argil connect: the board never answered on %s%s\n", o->device,
                udp_key_hint(o));
        e = ARGIL_ERR_IO;
    }
    return cmd_end(exit_status, e != ARGIL_OK ? 1 : cs->interrupted ? 130 : 0, e);
}

/* argil connect: a live session with a board until --seconds or Ctrl-C. */
argil_err_t cmd_connect(int argc, char **argv, int *exit_status)
{
    connect_session_t cs;
    memset(&cs, 0, sizeof(cs));
    bool done, go_on = true;
    argil_err_t e = parse_opts(argc, argv, &cs.o, &done, exit_status);
    if (done)
        return e;
    if (cs.o.journal) {
        e = recover_offer(cs.o.out_dir, cs.o.discard_journal, isatty(STDIN_FILENO) != 0, &go_on,
                          exit_status);
        if (!go_on)
            return e;
    }
    cs.tty = isatty(STDERR_FILENO);
    cs.c = calloc(1, sizeof(*cs.c));
    cs.s = calloc(1, sizeof(*cs.s));
    if (!cs.c || !cs.s) {
        free(cs.c);
        free(cs.s);
        fprintf(stderr, "argil connect: out of memory\n");
        return cmd_end(exit_status, 1, ARGIL_ERR_NOMEM);
    }
    cs.s->c = cs.c;
    e = connect_open_link(&cs);
    /* A bad key file or device string is a usage error (2); the link not opening, the work's. */
    int status = e == ARGIL_ERR_ARG || e == ARGIL_ERR_PARSE ? 2 : 1;
    if (e == ARGIL_OK) {
        status = 1;
        e = connect_clay_open(&cs);
        if (e == ARGIL_OK) {
            e = connect_run(&cs, &status);
            connect_clay_close(cs.s);
        }
        link_close(&cs.c->link);
    }
    free(cs.c->rx_store);
    free(cs.c->tx_store);
    free(cs.c);
    free(cs.s);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    return cmd_end(exit_status, status, e);
}
