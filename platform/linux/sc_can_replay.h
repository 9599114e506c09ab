/*
 * sc_can_replay.h: a CAN device (hal/sc_hal_can.h) that plays a `candump -l` log in real time.
 *
 * For hosts without SocketCAN: `sonocomp --can-replay FILE` receives the tracker emulator's
 * frames from its log (sc-tracker-emu --log FILE) instead of a bus.
 *
 * - Open: the whole log is read with the sc_candump reader into malloc'd memory (open time
 *   only; malformed lines are refused and counted by the reader, see rejected / last_reject).
 * - Clock: the replay starts at the first recv() (the frame loop's first poll, after the case
 *   has loaded), at start = now(). recv() then returns the next frame in file order whose log
 *   time offset from the log's first frame is <= now - start, else SC_ERR_WOULD_BLOCK. A
 *   frame's ts_ns is start + its offset (when it would have arrived on a bus). A time stamp
 *   earlier than the first frame's counts as offset 0 (file order is kept).
 * - At the end of the log recv() answers SC_ERR_WOULD_BLOCK forever (the tracker then times
 *   out: "probe lifted").
 * - send() accepts every valid frame and counts it (the frames go nowhere); an invalid
 *   length/flag combination is SC_ERR_INVALID_ARG.
 *
 * Threads: one device, one thread. recv/send are O(1) and never allocate.
 */
#ifndef SC_CAN_REPLAY_H
#define SC_CAN_REPLAY_H

#include <stddef.h>
#include <stdint.h>

#include "sc_candump.h"
#include "sc_hal_can.h"

/* A monotonic clock in nanoseconds; ctx is the caller's. */
typedef uint64_t (*sc_can_replay_now_fn)(void *ctx);

typedef struct sc_can_replay {
    sc_can_frame *frames; /* malloc'd at open; ts_ns holds the offset from the first frame */
    size_t count;
    size_t next;
    sc_can_replay_now_fn now;
    void *now_ctx;
    int started;
    uint64_t start_ns;
    uint64_t sent;                 /* frames accepted by send() */
    uint64_t received;             /* frames handed out by recv() */
    uint64_t duration_ns;          /* offset of the last frame */
    uint32_t lines;                /* lines read from the log */
    uint32_t rejected;             /* malformed lines refused */
    uint32_t last_reject_line;     /* line of the last refused line, 0 when none */
    sc_candump_reject last_reject; /* its reason */
} sc_can_replay;

/* Reads the log at path. now: the clock (NULL: sc_rt_now_ns, CLOCK_MONOTONIC). Returns 0;
 * SC_ERR_NOT_FOUND when the file cannot be opened (errno kept); SC_ERR_IO on a read error;
 * SC_ERR_PARSE when the log holds no valid frame; SC_ERR_NO_SPACE when memory runs out.
 * O(log size); allocates (open time only). */
int sc_can_replay_open(sc_can_replay *r, const char *path, sc_can_replay_now_fn now, void *now_ctx);
/* The hal device; r must outlive it. */
sc_can_dev sc_can_replay_dev(sc_can_replay *r);
/* 1 when every frame has been handed out. */
int sc_can_replay_done(const sc_can_replay *r);
/* Frees the frames; safe on a zeroed or closed replay. */
void sc_can_replay_close(sc_can_replay *r);

#endif /* SC_CAN_REPLAY_H */
