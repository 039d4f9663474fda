/* argil wire protocol v2: the frames that cross between board and host (USB bulk or UDP).
 * A frame is header + payload + CRC-32C, little-endian, encoded field by field.
 * Byte-level layout and golden vectors: docs/protocol.md. */
#ifndef ARGIL_PROTO_H
#define ARGIL_PROTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "argil_limits.h"

#define PROTO_MAGIC 0x4C475241u        /* bytes 'A' 'R' 'G' 'L' on the wire */
#define PROTO_VERSION 3u
#define PROTO_HEADER_SIZE 12u          /* magic u32, version u8, type u8, length u16, seq u32 */
#define PROTO_CRC_SIZE 4u              /* CRC-32C of header + payload */
#define PROTO_FRAME_MAX 1024u          /* no frame is larger: a WINDOW chunk fits in 1 KiB */
#define PROTO_PAYLOAD_MAX (PROTO_FRAME_MAX - PROTO_HEADER_SIZE - PROTO_CRC_SIZE)
#define PROTO_IMPULSE_MAX 124u         /* impulse entries in one IMPULSE frame */
#define PROTO_WINDOW_CHUNK_SAMPLES 224u /* samples per WINDOW chunk (the last may hold fewer) */
#define PROTO_WINDOW_CHANNELS_MAX 2u  /* density, and optionally per-node spring stiffness */
#define PROTO_WINDOW_CHUNKS_MAX                                                                   \
    ((PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX + PROTO_WINDOW_CHUNK_SAMPLES - 1u) /    \
     PROTO_WINDOW_CHUNK_SAMPLES)
#define PROTO_NAME_LEN 16u

/* Which rule a frame broke. Every decoder error is distinct so tests and logs can say why. */
typedef enum {
    PROTO_OK = 0,
    PROTO_ERR_TRUNCATED = -1,  /* fewer bytes than the header or its declared length needs */
    PROTO_ERR_OVERSIZE = -2,   /* declared payload length above PROTO_PAYLOAD_MAX */
    PROTO_ERR_MAGIC = -3,      /* the first four bytes are not 'ARGL' */
    PROTO_ERR_CRC = -4,        /* CRC-32C does not match */
    PROTO_ERR_VERSION = -5,    /* protocol version not PROTO_VERSION */
    PROTO_ERR_TYPE = -6,       /* unknown message type */
    PROTO_ERR_PAYLOAD = -7,    /* payload length does not match its type's layout */
    PROTO_ERR_VALUE = -8,      /* a field out of range: NaN/Inf, zero spacing, count too high */
    PROTO_ERR_CHUNK = -9,      /* WINDOW chunk inconsistent with itself or with its siblings */
    PROTO_ERR_NOSPACE = -10    /* encode: the output buffer is too small */
} proto_err_t;

typedef enum {
    MSG_HELLO = 1,
    MSG_HEARTBEAT = 2,
    MSG_TELEMETRY = 3,
    MSG_IMPULSE = 4,
    MSG_WINDOW = 5,
    MSG_TOOL = 6,
    MSG_FAULT = 7,
    MSG_RT_STATS = 8
} msg_type_t;
#define MSG_TYPE_LAST MSG_RT_STATS

typedef enum { PROTO_ROLE_BOARD = 1, PROTO_ROLE_HOST = 2 } proto_role_t;

/* HELLO: sent by each side when a link (re)starts; the host answers with the window and tool. */
typedef struct {
    uint8_t role;            /* proto_role_t */
    uint8_t drives;          /* joints the board drives (ARGIL_DRIVES) */
    uint16_t window_max;     /* largest window edge the sender accepts, samples */
    uint16_t tick_hz;        /* board loop rate; 0 from the host */
    char name[PROTO_NAME_LEN]; /* sender's name and build, NUL-padded, not necessarily terminated */
} msg_hello_t;

/* Commands the host may carry in a HEARTBEAT. */
typedef enum {
    PROTO_CMD_NONE = 0,
    PROTO_CMD_ARM = 1,       /* IDLE → ARMED → ACTIVE, or re-arm after ESTOP / FAULT */
    PROTO_CMD_DISARM = 2,    /* back to IDLE, drives off */
    PROTO_CMD_END = 3        /* disarm, and end this host's session: the board serves no one
                              * until a host says HELLO */
} proto_cmd_t;
#define PROTO_CMD_LAST PROTO_CMD_END

/* HEARTBEAT: both ways, at least every 10 ms; its absence for the timeout is a fault. */
typedef struct {
    uint64_t time_us;        /* sender's clock */
    uint32_t window_version; /* host: newest window sent; board: window in use */
    uint32_t impulse_seq;    /* host: newest impulse batch applied; board: newest sent */
    uint8_t command;         /* proto_cmd_t, host → board only */
} msg_heartbeat_t;

/* TELEMETRY: board → host every tick. Positions and forces are in model space. */
typedef struct {
    uint64_t time_us;
    uint32_t tick;
    uint8_t state;           /* board safety state (firmware/core/safety.h) */
    uint8_t tool_kind;       /* tool_kind_t in use */
    uint8_t buttons;         /* bit 0: stylus button 1, bit 1: button 2 */
    uint8_t flags;           /* bit 0: in contact, bit 1: sculpting */
    float pos_m[3];
    float vel_m_s[3];
    float force_n[3];        /* force rendered to the hand */
    uint32_t window_version;
    uint32_t compute_ns;     /* this tick's compute time */
    uint32_t deadline_misses;/* since boot */
} msg_telemetry_t;

typedef struct {
    uint32_t node;           /* linear index x + nx*(y + ny*z) in the window of window_version */
    float impulse_ns;        /* ∫ f dt on that node's density axis, N·s */
} proto_impulse_t;

/* IMPULSE: board → host a few hundred times a second: accumulated node impulses. */
typedef struct {
    uint32_t window_version;
    uint32_t impulse_seq;    /* increases by one per IMPULSE frame */
    uint16_t count;          /* ≤ PROTO_IMPULSE_MAX */
    proto_impulse_t entries[PROTO_IMPULSE_MAX];
} msg_impulse_t;

/* WINDOW: host → board, one chunk of a versioned local density window.
 * The window's sample array is channels × dims[0]*dims[1]*dims[2] floats: the densities (x
 * fastest), then, when channels = 2, each node's spring stiffness in the same order. Chunk i
 * holds samples [i*PROTO_WINDOW_CHUNK_SAMPLES, …) of that array. */
typedef struct {
    uint32_t version;
    uint16_t chunk_index;
    uint16_t chunk_count;
    uint8_t dims[3];         /* samples per axis, 2 … ARGIL_WINDOW_MAX */
    uint8_t channels;        /* 1: density only (uniform stiffness below); 2: + per-node stiffness */
    float origin_m[3];       /* model-space position of sample (0,0,0) */
    float spacing_m;         /* > 0 */
    float iso;               /* iso-value of the surface */
    float node_mass;         /* density-spring material, uniform over the window */
    float stiffness;
    float damping;
    float plastic_rate_hz;   /* how fast rest densities follow the current ones (0 = elastic) */
    uint32_t impulse_seq;    /* newest IMPULSE batch the host had applied when it extracted this */
    uint32_t first_sample;
    uint16_t sample_count;
    float samples[PROTO_WINDOW_CHUNK_SAMPLES];
} msg_window_t;

typedef enum {
    TOOL_TOUCH = 0,          /* feel the iso-surface (any iso-value: flag TOOL_FLAG_ISO) */
    TOOL_PUSH = 1,           /* lower density along the tool's path once the clay yields (dent) */
    TOOL_PULL = 2,           /* raise density along the path from the grab point (bulge) */
    TOOL_CARVE = 3,          /* host-side geometric removal; the board renders a drag */
    TOOL_PROBE = 4,          /* feel local stiffness as viscosity (Hua & Qin §6.1) */
    TOOL_ROPE = 5            /* grab the nearest mass points and pull on a spring (Virtual Clay) */
} tool_kind_t;
#define TOOL_KIND_COUNT 6

/* How a sculpting tool samples its path (Hua & Qin §6.1). */
typedef enum {
    TOOL_SHAPE_POINT = 0,    /* one path: the tool tip's */
    TOOL_SHAPE_CURVE = 1,    /* a segment of length_m along axis, centred on the tip */
    TOOL_SHAPE_AREA = 2      /* a square of side length_m normal to axis, centred on the tip */
} tool_shape_t;
#define TOOL_SHAPE_COUNT 3

/* The distance filter β that spreads a path's force over the nodes near it. */
typedef enum {
    BETA_CONSTANT = 0,
    BETA_GAUSSIAN = 1,
    BETA_SPHERICAL = 2,
    BETA_CYLINDRICAL = 3,
    BETA_CONICAL = 4
} beta_filter_t;
#define BETA_FILTER_COUNT 5

#define TOOL_FLAG_ISO 0x01u  /* touch renders the iso-surface at `iso`, not the window's */

/* TOOL: host → board, the active tool, its gains and the device-to-model transform. */
typedef struct {
    uint8_t kind;            /* tool_kind_t */
    uint8_t shape;           /* tool_shape_t */
    uint8_t filter;          /* beta_filter_t */
    uint8_t flags;           /* TOOL_FLAG_* */
    float radius_m;          /* > 0: tool sphere, and β's support */
    float length_m;          /* ≥ 0: curve length or area side */
    float axis[3];           /* tool axis in model space, unit length (curve/area orientation) */
    float alpha;             /* ≥ 0: sculpting gain of Hua & Qin eq. 7 */
    float contact_stiffness_n_per_m; /* ≥ 0 */
    float max_force_n;       /* > 0 */
    float iso;               /* iso-value felt with TOOL_FLAG_ISO, 0 … 1 */
    float yield_force_n;     /* ≥ 0: contact force at which push starts to flow the clay */
    float friction;          /* ≥ 0: Coulomb coefficient limiting the contact point's slide */
    float probe_gain;        /* ≥ 0: probe viscosity, N·s/m per unit stiffness */
    float rope_stiffness_n_per_m; /* ≥ 0 */
    float model_scale;       /* model = scale * device + offset; > 0 */
    float model_offset_m[3];
} msg_tool_t;

/* FAULT: board → host when the board enters FAULT or ESTOP. */
typedef struct {
    uint64_t time_us;
    uint16_t code;           /* fault_code_t of firmware/core/safety.h */
    uint8_t state;
    uint32_t detail;
} msg_fault_t;

#define PROTO_RT_HIST_BINS 12u      /* histogram bins of RT_STATS (firmware/core/rt_stats.h) */

/* The host frames the board refused since it started, by reason (RT_STATS: the first six from
 * version 2, the last three from version 3). */
typedef struct {
    uint32_t decode_errors;  /* refused by the decoder: CRC, torn frame, garbage, a bad field */
    uint32_t wrong_source;   /* from an address other than the session host's (UDP) */
    uint32_t no_session;     /* no host session to belong to (no HELLO yet, or after an END) */
    uint32_t duplicate;      /* a sequence number the session already accepted (replay) */
    uint32_t stale;          /* a sequence number older than the session's window */
    uint32_t sessions;       /* host sessions started (host HELLOs accepted) */
    uint32_t bad_mac;        /* UDP datagrams whose tag did not verify (a wrong key, a forgery, no
                              * tag to a keyed board, or a tag to a board without a key) */
    uint32_t bad_nonce;      /* UDP datagrams with a valid tag but another session's nonce */
    uint32_t arm_refused;    /* ARM commands refused: UDP without a key and without --insecure */
} proto_link_counts_t;

/* RT_STATS: board → host once a second (and when the board stops): the fast loop's deadline
 * statistics since it started. All times in ns. */
typedef struct {
    uint64_t time_us;        /* board clock */
    uint32_t ticks;          /* ticks measured (in the simulation not those the machine
                              * preempted: docs/board.md, "Timing a simulated tick") */
    uint32_t period_ns;      /* loop period, > 0 */
    uint32_t wake_min_ns;    /* wake-up latency: min ≤ mean ≤ max */
    uint32_t wake_mean_ns;
    uint32_t wake_max_ns;
    uint32_t compute_min_ns; /* compute time of a tick: min ≤ mean ≤ max */
    uint32_t compute_mean_ns;
    uint32_t compute_max_ns;
    uint32_t overruns;       /* ticks whose latency + compute passed the period; ≤ ticks */
    uint32_t worst_streak;   /* longest run of overruns; ≤ overruns */
    uint32_t wake_hist[PROTO_RT_HIST_BINS];    /* wake-up latency histogram; sums to ticks */
    uint32_t compute_hist[PROTO_RT_HIST_BINS]; /* compute time histogram; sums to ticks */
    proto_link_counts_t link;                  /* host frames refused, by reason */
} msg_rt_stats_t;

typedef struct {
    uint8_t type;            /* msg_type_t */
    uint32_t seq;            /* from the frame header */
    union {
        msg_hello_t hello;
        msg_heartbeat_t heartbeat;
        msg_telemetry_t telemetry;
        msg_impulse_t impulse;
        msg_window_t window;
        msg_tool_t tool;
        msg_fault_t fault;
        msg_rt_stats_t rt_stats;
    } u;
} proto_msg_t;

/* Encodes msg as one frame with sequence seq into buf; *len gets the frame size.
 * Returns PROTO_ERR_NOSPACE when cap is too small, and for a message that would not decode
 * the error its decoding would give: PROTO_ERR_TYPE, PROTO_ERR_VALUE, or PROTO_ERR_CHUNK for
 * WINDOW chunk numbering (so nothing invalid is ever sent). */
proto_err_t proto_encode(const proto_msg_t *msg, uint32_t seq, uint8_t *buf, size_t cap,
                         size_t *len);

/* Decodes the frame at the start of buf[0..len). On PROTO_OK *frame_len is its size.
 * Never reads outside buf[0..len). */
proto_err_t proto_decode(const uint8_t *buf, size_t len, proto_msg_t *msg, size_t *frame_len);

/* A short English name of err, for logs. */
const char *proto_strerror(proto_err_t err);

/* Reassembles the chunks of one window version into caller-given storage. */
typedef struct {
    float *samples;          /* caller's storage */
    uint32_t capacity;       /* samples it holds */
    bool started;
    uint32_t version;
    uint16_t chunk_count;
    uint16_t received;       /* distinct chunks of this version seen */
    uint32_t got[(PROTO_WINDOW_CHUNKS_MAX + 31u) / 32u]; /* bitmap of chunks seen */
    msg_window_t head;       /* fields of the first chunk (samples unused) */
} window_asm_t;

void window_asm_init(window_asm_t *a, float *storage, uint32_t capacity);

/* Adds one decoded chunk. A newer version restarts assembly; an older one is refused.
 * Returns PROTO_ERR_CHUNK when the chunk disagrees with its siblings or does not fit; a
 * disagreeing sibling abandons that version (it never completes; the next version restarts). */
proto_err_t window_asm_feed(window_asm_t *a, const msg_window_t *chunk);

/* window_asm_feed for a chunk that proto_decode returned with PROTO_OK: the same result
 * without repeating the decoder's checks of its fields and samples (the board's 1 kHz tick
 * decodes up to two chunks). Any other chunk must go through window_asm_feed. */
proto_err_t window_asm_feed_decoded(window_asm_t *a, const msg_window_t *chunk);

/* True once every chunk of the current version has arrived. */
bool window_asm_complete(const window_asm_t *a);

/* Fills chunk number index of a window (header fields from head, samples from samples[])
 * the way window_asm_feed expects; returns PROTO_ERR_VALUE if index is out of range. */
proto_err_t window_chunk_fill(const msg_window_t *head, const float *samples, uint16_t index,
                              msg_window_t *chunk);

/* Number of chunks a window of channels × dims[0]*dims[1]*dims[2] samples takes; 0 when a dim
 * is outside 2 … ARGIL_WINDOW_MAX or channels outside 1 … PROTO_WINDOW_CHANNELS_MAX. */
uint16_t window_chunk_count(const uint8_t dims[3], uint8_t channels);

#endif
