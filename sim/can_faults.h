/* CAN fault injection between the simulated drives and the board, at frame level and in both
 * directions: frames dropped with a probability (deterministic PRNG with a seed), frames
 * delayed, bus-off (the device goes silent, the board gets SocketCAN error frames), a drive's
 * heartbeat stopped, an encoder jump (TPDO position offset). Lockstep: time is passed in. */
#ifndef ARGIL_CAN_FAULTS_H
#define ARGIL_CAN_FAULTS_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/argil_limits.h"
#include "shared/canopen.h"

#define CAN_FAULTS_HELD_MAX 256u   /* frames in flight per direction while delayed */
#define CAN_FAULTS_ID_MASK 0x7FFu  /* 11-bit CAN ids: frames are counted per id */

typedef struct {
    int64_t due_us;
    can_frame_t f;
} can_held_t;

typedef struct {
    can_held_t q[CAN_FAULTS_HELD_MAX];
    uint32_t n;
} can_held_queue_t;

typedef struct {
    uint32_t drop_ppm;             /* probability of dropping a frame, parts per million */
    uint32_t seed;                 /* the drop's seed */
    uint32_t frames_seen[2][CAN_FAULTS_ID_MASK + 1u]; /* per direction (0: to the board) and id,
                                      frames since the drop began */
    int64_t delay_us;              /* frames are held this long, both directions */
    bool bus_off;                  /* the device side is off the bus: nothing flows */
    bool bus_off_frame_due;        /* the board still has to get the bus-off error frame */
    bool restart_frame_due;        /* … or the "restarted" one */
    bool heartbeat_stopped[ARGIL_DRIVES];
    int32_t encoder_offset_counts[ARGIL_DRIVES];
    can_held_queue_t held_to_board;
    can_held_queue_t held_from_board;
    uint32_t dropped_to_board;
    uint32_t dropped_from_board;
    uint32_t silenced;             /* frames lost to bus-off */
    uint32_t heartbeats_suppressed;
    uint32_t held_overflow;        /* frames dropped because the delay queue was full */
    uint32_t error_frames_sent;
} can_faults_t;

/* No faults: every frame passes at once. */
void can_faults_init(can_faults_t *cf);

/* Drops each frame, either direction, with probability ppm / 1e6: whether the n-th frame of a
 * CAN id is lost depends only on (seed, direction, id, n) (0 is taken as seed 1), so a seed
 * loses the same frames in SIL and on a bus. ppm 0 stops dropping. */
void can_faults_set_drop(can_faults_t *cf, uint32_t ppm, uint32_t seed);

/* Holds every frame, either direction, for delay_us; 0 releases the held frames at the next
 * call in their order. */
void can_faults_set_delay(can_faults_t *cf, int64_t delay_us);

/* Bus-off: from now on nothing passes either way and the board's next batch starts with a
 * bus-off error frame (CAN_ERR_FLAG | CAN_ERR_BUSOFF). */
void can_faults_bus_off(can_faults_t *cf);

/* The controller is back: a CAN_ERR_RESTARTED error frame, then frames flow again. */
void can_faults_bus_restart(can_faults_t *cf);

/* Stops (on = false) or resumes the heartbeat of drive node 1..3. */
void can_faults_heartbeat(can_faults_t *cf, int node, bool on);

/* From now on drive node 1..3 reports its position offset by a further counts. */
void can_faults_encoder_jump(can_faults_t *cf, int node, int32_t counts);

/* Device → board: in (the drives' frames of this tick) becomes out at now_us. */
void can_faults_to_board(can_faults_t *cf, const can_batch_t *in, can_batch_t *out,
                         int64_t now_us);

/* Board → device: in (the board's frames) becomes out at now_us. */
void can_faults_from_board(can_faults_t *cf, const can_batch_t *in, can_batch_t *out,
                           int64_t now_us);

#endif
