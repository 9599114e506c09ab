/*
 * sc_socketcan.h: an sc_can_dev (hal/sc_hal_can.h) over Linux SocketCAN (CAN_RAW).
 *
 * - Opens a CAN_RAW socket bound to a named interface (vcan0, can0), non-blocking; works
 *   unprivileged (CAN_RAW needs no capability, only an interface that is up).
 * - CAN FD when the interface's MTU is CANFD_MTU (CAN_RAW_FD_FRAMES), classic otherwise;
 *   sending an FD frame on a classic interface answers SC_ERR_NOT_SUPPORTED.
 * - Kernel acceptance filters from sc_can_set_filters() (CAN_RAW_FILTER, at most
 *   SC_CAN_MAX_FILTERS); error frames enabled (CAN_RAW_ERR_FILTER: bus-off, controller
 *   problems, protocol, restarted) and delivered as SC_CAN_FLAG_ERR frames whose id holds
 *   SC_CAN_ERRF_* classes; they also drive the state get_state() reports.
 * - Kernel receive time stamps (SO_TIMESTAMPING software rx, else SO_TIMESTAMPNS), taken by the
 *   kernel on CLOCK_REALTIME and converted to CLOCK_MONOTONIC (the HAL clock's base) with one
 *   offset (sc_socketcan_tsconv) that is estimated at open and held until CLOCK_REALTIME is
 *   stepped, so that frames the kernel stamped in order keep their order. (A fresh offset per
 *   frame from two clock reads added the time between the reads to each stamp; a preemption
 *   there, 139 us measured in the HIL VM, put frames 96 us apart out of order, issue #19.)
 * - Kernel drops (SO_RXQ_OVFL) counted in sc_can_counters.rx_dropped.
 * The engine takes at most SC_CAN_RX_BURST_MAX frames per frame through recv (non-blocking);
 * sonocomp puts sc_can_rxmb.h's receive mailboxes in front of the node (the socket drained at
 * each receive, commands first, the newest poses win), so a command never waits behind a
 * stall's worth of queued tracker frames.
 *
 * Syscalls live behind sc_socketcan_sys (open/filter/recv/send/close/read_clocks), so the logic
 * (frame conversion, error mapping, state, filters, time stamp conversion) is unit-tested with a
 * fake; sc_socketcan_sys_posix() is the real one. Thread rules: one thread per node. Never
 * allocates.
 */
#ifndef SC_SOCKETCAN_H
#define SC_SOCKETCAN_H

#include <stddef.h>
#include <stdint.h>

#include "sc_config.h"
#include "sc_hal_can.h"

/* A raw frame as the kernel sees it: struct canfd_frame layout, can_id with CAN_*_FLAG bits. */
typedef struct sc_socketcan_raw {
    uint32_t can_id;
    uint8_t len;
    uint8_t flags; /* CANFD_* */
    uint8_t res0, res1;
    uint8_t data[64];
} sc_socketcan_raw;

typedef struct sc_socketcan_rawfilter {
    uint32_t can_id;
    uint32_t can_mask;
} sc_socketcan_rawfilter;

/* One reading of the two clocks, back to back: CLOCK_MONOTONIC, CLOCK_REALTIME, CLOCK_MONOTONIC
 * (ns). The REALTIME value was read at a MONOTONIC time inside [mono_before_ns, mono_after_ns],
 * so MONOTONIC - REALTIME lies in [mono_before_ns - real_ns, mono_after_ns - real_ns]: the
 * bracket's width bounds the error whatever delayed the reads (preemption, an interrupt). */
typedef struct sc_socketcan_clocks {
    uint64_t mono_before_ns, real_ns, mono_after_ns;
} sc_socketcan_clocks;

/* CLOCK_REALTIME -> CLOCK_MONOTONIC for kernel stamps. MONOTONIC - REALTIME only changes when
 * REALTIME is stepped (settimeofday, clock_settime, adjtimex ADJ_SETOFFSET, a leap second):
 * NTP's frequency slewing moves both clocks alike. So the offset is estimated once and held;
 * a reading whose bracket cannot contain the held offset proves a step and re-estimates it.
 * Between estimates the conversion adds a constant: stamps in order stay in order. Frames
 * stamped before a step but read after it are off by the step (the stamp does not say on
 * which side it was taken); steps are counted. 32 bytes. */
typedef struct sc_socketcan_tsconv {
    int64_t offset_ns;       /* MONOTONIC - REALTIME, held between estimates */
    uint64_t uncertainty_ns; /* half the width of the bracket the offset came from */
    uint32_t steps;          /* REALTIME steps detected after the first estimate */
    int valid;               /* 0 until an estimate succeeded: stamps convert to 0 (unknown) */
} sc_socketcan_tsconv;

/* The syscall adapter. Every op returns >= 0 or a negative sc_err; all ops are mandatory. */
typedef struct sc_socketcan_sys {
    /* Open a CAN_RAW socket on ifname, non-blocking, error frames enabled, time stamps on;
     * enable FD frames when the interface MTU allows: *fd_capable = 1. Returns a handle. */
    int (*open)(void *u, const char *ifname, int *fd_capable);
    int (*set_filters)(void *u, int h, const sc_socketcan_rawfilter *f, size_t n);
    /* One frame: 1 and *out filled, 0 when nothing waits (EAGAIN). *is_fd 1 for an FD frame;
     * *ts_ns the kernel's receive stamp on CLOCK_REALTIME (0 unknown: no stamp came with the
     * frame); *drops the kernel's drop counter (cumulative, unchanged when unknown). */
    int (*recv)(void *u, int h, sc_socketcan_raw *out, int *is_fd, uint64_t *ts_ns,
                uint32_t *drops);
    /* Send one frame: 0, SC_ERR_WOULD_BLOCK (queue full, ENOBUFS/EAGAIN), SC_ERR_IO. */
    int (*send)(void *u, int h, const sc_socketcan_raw *f, int is_fd);
    void (*close)(void *u, int h);
    /* One clock reading (sc_socketcan_clocks): 0, or SC_ERR_IO when a clock cannot be read. */
    int (*read_clocks)(void *u, sc_socketcan_clocks *out);
} sc_socketcan_sys;

/* The real adapter over socket(2) and friends. */
const sc_socketcan_sys *sc_socketcan_sys_posix(void);

typedef struct sc_socketcan {
    const sc_socketcan_sys *sys;
    void *sys_user;
    int handle;
    int fd_capable;
    sc_can_state state;
    sc_can_counters counters;
    uint32_t kernel_drops; /* last SO_RXQ_OVFL value seen */
    uint64_t rx_frames, rx_error_frames, tx_frames;
    uint32_t rx_unconvertible;  /* frames that could not be represented (counted, skipped) */
    sc_socketcan_tsconv tsconv; /* kernel stamps -> HAL clock; tsconv.steps counts REALTIME steps */
} sc_socketcan;

/* Opens the node (ifname at most 15 characters) and estimates the time stamp offset
 * (SC_SOCKETCAN_CLOCK_READINGS clock readings). SC_ERR_INVALID_ARG for a bad name, SC_ERR_IO
 * when the socket cannot be opened or bound (no such interface, no CAN in the kernel) or the
 * clocks cannot be read. O(SC_SOCKETCAN_CLOCK_READINGS). */
int sc_socketcan_open(sc_socketcan *s, const sc_socketcan_sys *sys, void *sys_user,
                      const char *ifname);
void sc_socketcan_close(sc_socketcan *s);
/* The HAL device over an open node (every op implemented). */
sc_can_dev sc_socketcan_dev(sc_socketcan *s);

/* Pure conversions, exposed for tests and for the candump reader/writer. */
/* Kernel frame -> HAL frame. SC_ERR_RANGE for a length the HAL cannot hold. */
int sc_socketcan_from_raw(const sc_socketcan_raw *r, int is_fd, sc_can_frame *out);
/* HAL frame -> kernel frame (error frames map back to CAN_ERR_* classes). *is_fd out. */
int sc_socketcan_to_raw(const sc_can_frame *f, sc_socketcan_raw *out, int *is_fd);
/* Linux error frame (can_id with CAN_ERR_* class bits, data[8]) -> SC_CAN_ERRF_* bits. */
uint32_t sc_socketcan_errf_from_linux(uint32_t can_id, const uint8_t data[8]);
/* HAL filter -> kernel filter (standard/extended distinguished through CAN_EFF_FLAG). */
sc_socketcan_rawfilter sc_socketcan_filter_to_raw(const sc_can_filter *f);

/* Time stamp conversion (sc_socketcan_tsconv), pure; the node drives it, tests reach it. */
/* Sets the offset from the narrowest of n readings (its bracket's midpoint). Readings whose
 * MONOTONIC values run backwards are ignored; when none is usable *c is left unchanged and
 * SC_ERR_INVALID_ARG returned. O(n). */
int sc_socketcan_tsconv_estimate(sc_socketcan_tsconv *c, const sc_socketcan_clocks *r, size_t n);
/* 1 when reading r cannot be reconciled with the held offset (REALTIME was stepped since the
 * estimate, by more than the two brackets' widths), else 0; 0 for an invalid *c or reading.
 * Never a false step: a wide (delayed) reading only detects less. O(1). */
int sc_socketcan_tsconv_stepped(const sc_socketcan_tsconv *c, const sc_socketcan_clocks *r);
/* A REALTIME kernel stamp on the MONOTONIC base: real_ns + offset, non-decreasing in real_ns
 * for a given *c. 0 (unknown) for real_ns 0, an invalid *c, or a result <= 0 (a stamp from
 * before boot, possible only around a step). O(1). */
uint64_t sc_socketcan_tsconv_to_mono(const sc_socketcan_tsconv *c, uint64_t real_ns);

#endif /* SC_SOCKETCAN_H */
