/*
 * sc_hs_live.h: the host simulator's live mode (sc-hostsim --live), for the console on a host
 * without SocketCAN: the engine still runs on the virtual clock (its deadline and misses are
 * those of the simulated appliance, whatever the host does), but each frame is released at its
 * wall-clock time, CAN frames come in over UDP (sc_udpcan.h: the tracker emulator's poses, the
 * gateway's authenticated commands), scan lines go out over the UDP display link and the state
 * stream over UDP (or into a file), so the gateway and browsers see a running appliance.
 * Nothing the gateway or its clients do reaches the engine's frame except CAN frames.
 */
#ifndef SC_HS_LIVE_H
#define SC_HS_LIVE_H

#include <stdint.h>
#include <stdio.h>

#include "sc_can_rxmb.h"
#include "sc_hs_rig.h"
#include "sc_udp_display.h"
#include "sc_udp_state.h"
#include "sc_udpcan.h"

typedef struct sc_hs_live_def {
    int pace;                 /* release frames at wall-clock time */
    uint16_t can_port;        /* 0: no UDP CAN input */
    const char *state_target; /* "HOST:PORT" or NULL */
    const char *dlink_target; /* "HOST:PORT" or NULL */
    const char *state_file;   /* records, each as u16 length + bytes, or NULL */
} sc_hs_live_def;

typedef struct sc_hs_live {
    sc_hs_live_def def;
    sc_udpcan can;
    sc_udp_state state;
    sc_udp_display dlink;
    int have_dlink;
    FILE *state_fp;
    uint64_t state_file_records;
    sc_display_dev recorder; /* the rig's own display, teed */
    double wall0_s;
    uint64_t t0_ns;
    uint64_t can_injected, can_overruns;
    /* the controller's receive mailboxes between the socket and the engine's bus node
     * (sc_can_rxmb.h): the socket drained every frame, commands first, the newest poses */
    sc_can_rxmb rxmb;
    uint32_t drained_max;   /* most datagrams drained before one frame */
    uint64_t drain_limited; /* frames whose drain stopped at SC_HS_LIVE_DRAIN_MAX */
} sc_hs_live;

/* Datagrams drained from the CAN socket before one frame at most (at 76 bytes each, far more
 * than a 1 MB socket buffer's worth of seconds of a 100 Hz tracker). */
#ifndef SC_HS_LIVE_DRAIN_MAX
#define SC_HS_LIVE_DRAIN_MAX 4096u
#endif

/* Open the sockets and files of def and wire them into rig->hal (display tee, state device).
 * 0, or a negative sc_err with a message in err. */
int sc_hs_live_open(sc_hs_live *l, const sc_hs_live_def *def, sc_hs_rig *rig, char *err,
                    size_t cap);
/* Before each frame: wait for its wall-clock release (pace), then drain every UDP CAN frame
 * waiting (at most SC_HS_LIVE_DRAIN_MAX) into the receive mailboxes, stamped with the frame's
 * release time, and give the engine's bus node what the engine takes in one frame
 * (SC_CAN_RX_BURST_MAX, less what its queue still holds): commands first, then the oldest of
 * the newest stream frames the mailboxes kept. So a command waits at most one frame behind
 * tracker frames however slow the host runs the engine, and the poses the engine sees are the
 * newest; a pose frame the mailboxes overwrote is counted (summary) and reaches the engine's
 * E2E receiver as a counter gap. */
void sc_hs_live_before_frame(sc_hs_live *l, sc_hs_rig *rig, uint64_t release_ns);
/* SIGINT / SIGTERM received (installed by open). */
int sc_hs_live_stop(void);
void sc_hs_live_summary(const sc_hs_live *l, const sc_hs_rig *rig, FILE *f);
void sc_hs_live_close(sc_hs_live *l);

#endif /* SC_HS_LIVE_H */
