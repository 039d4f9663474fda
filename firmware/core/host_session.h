/* The board's host session: which host frames may act. A host's HELLO starts a session; every
 * frame of it must carry a sequence number not seen before and not older than the newest 64
 * (a sliding window as in IPsec and DTLS anti-replay, RFC 4303 §3.4.3, RFC 6347 §4.1.2.6). A
 * session lapses when its host's heartbeats stop for the host timeout, and ends on its END
 * command. The transport (UDP) binds the session's host address from the same state. */
#ifndef ARGIL_HOST_SESSION_H
#define ARGIL_HOST_SESSION_H

#include <stdbool.h>
#include <stdint.h>

#define HOST_SESSION_WINDOW 64u        /* sequence numbers remembered behind the newest */

typedef enum {
    HOST_SESSION_NONE = 0,   /* no host: only a host HELLO is accepted */
    HOST_SESSION_LIVE = 1,   /* serving one host */
    HOST_SESSION_LAPSED = 2  /* its host went quiet for the timeout: it may carry on (its numbers
                              * still checked), and any host's HELLO starts a new session */
} host_session_state_t;

typedef enum {
    HOST_FRAME_ACCEPT = 0,
    HOST_FRAME_NEW_SESSION = 1, /* accepted: a HELLO that (re)started the session */
    HOST_FRAME_NO_SESSION = -1, /* not a HELLO, and no session to belong to */
    HOST_FRAME_DUPLICATE = -2,  /* its sequence number was accepted before (replay, duplicate) */
    HOST_FRAME_STALE = -3       /* older than the window: too late to tell, refused */
} host_frame_verdict_t;

typedef struct {
    host_session_state_t state;
    uint32_t epoch;          /* sessions started since boot */
    uint32_t newest_seq;     /* newest sequence number accepted */
    uint64_t seen;           /* bit k: newest_seq − k was accepted */
    uint32_t silence_us;     /* since the host's last accepted HELLO or heartbeat */
} host_session_t;

void host_session_init(host_session_t *s);

/* Decides whether a decoded host frame with sequence number seq may act, and records it.
 * hello: a host HELLO (starts a session when none is live); alive: a HELLO or a heartbeat
 * (restarts the silence clock). */
host_frame_verdict_t host_session_admit(host_session_t *s, bool hello, bool alive, uint32_t seq);

/* Ends the session (the host's END command): the board serves no one until a HELLO. */
void host_session_end(host_session_t *s);

/* Advances the silence clock by dt_us; returns true in the call in which the session lapsed. */
bool host_session_process(host_session_t *s, uint32_t dt_us, uint32_t timeout_us);

#endif
