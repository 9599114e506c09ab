/*
 * sc_hs_faults.h: fault injection plans for a whole engine on the host simulator (sc-hostsim
 * --faults, the fault-injection integration tests).
 *
 * A plan is a comma-separated list:
 *   drop=PPM corrupt=PPM dup=PPM reorder=PPM delay=NS   random bus faults (sc_hs_can.h), per
 *                                                        frame sent, parts per million
 *   random=START_S:END_S     the random faults only in [START, END) (default: the whole run)
 *   busoff=START_S:DUR_S     the controller is bus-off: sends fail, error frames to every node
 *   silence=START_S:DUR_S    the tracker sends nothing
 *   flood=START_S:DUR_S      a foreign node fills the bus: frames of ids outside the protocol
 *                            (0x095, 0x096, 0x097, 0x09D, 0x09E, 0x09F, 0x103, 0x104,
 *                            0x111, 0x555, 0x7FF)
 *                            at the bus's capacity, bitrate / 111 bits per 8-byte classic frame
 *                            (500 kbit/s: 4,504 frames/s); the bus is modelled without
 *                            arbitration, i.e. the protocol's own frames keep their slots, as
 *                            they do on a real bus against a lower-priority flood
 *   linkdown=START_S:DUR_S   the display link is down (every display call refused)
 *   bitrate=BPS              the flood's bus bitrate (default 500000)
 * Times are virtual seconds from the first frame; episodes may overlap and repeat (at most
 * SC_HS_FAULTS_MAX_EPISODES).
 *
 * A run applies the plan before each engine frame and, after it, measures per episode: the
 * raise edges of the episode's health fault bit (SC_FAULT_CAN_BUS_OFF, TRACKER_TIMEOUT,
 * DISPLAY_LINK; none for a flood, TRACKER_DATA for the random window), the frames from the
 * episode's end until the engine recovered (tracked again, the fault bit clear, a complete
 * display frame again), and what was injected. Deterministic on the virtual clock. Never
 * allocates.
 */
#ifndef SC_HS_FAULTS_H
#define SC_HS_FAULTS_H

#include <stddef.h>
#include <stdint.h>

#include "sc_hs_rig.h"

#define SC_HS_FAULTS_MAX_EPISODES 16u
#define SC_HS_FLOOD_FRAME_BITS    111u /* 8-byte classic frame, 11-bit id, without stuffing */

typedef enum sc_hs_episode_kind {
    SC_HS_EP_BUS_OFF = 0,
    SC_HS_EP_SILENCE,
    SC_HS_EP_FLOOD,
    SC_HS_EP_LINK_DOWN,
    SC_HS_EP_RANDOM,
    SC_HS_EP_KIND_COUNT
} sc_hs_episode_kind;

typedef struct sc_hs_episode {
    sc_hs_episode_kind kind;
    uint64_t start_ns, end_ns; /* virtual time from the run's start */
    /* results */
    uint8_t started, ended;
    uint32_t edges_at_start; /* health raise edges of the episode's fault bit */
    uint32_t edges;          /* raise edges since the start (during the episode + recovery) */
    int32_t recover_frames;  /* frames after the end until recovered (1: the first frame
                              * after the clearing had recovered); -1: not (yet) */
    uint32_t frames_since_end;
    uint32_t untracked_frames; /* frames without a valid pose while the episode ran */
    uint64_t injected;         /* flood frames sent, display calls refused, sends refused */
    uint64_t filtered_at_start;
    uint64_t refused_at_start; /* peer sends refused before the episode */
    uint64_t display_refused_at_start;
    uint64_t filtered; /* flood: frames the engine's acceptance filters kept out */
    uint64_t frames_at_start, complete_at_end;
} sc_hs_episode;

typedef struct sc_hs_fault_plan {
    sc_hs_can_faults random;
    uint64_t random_start_ns, random_end_ns;
    uint32_t bitrate;
    sc_hs_episode ep[SC_HS_FAULTS_MAX_EPISODES];
    uint32_t n;
} sc_hs_fault_plan;

/* Parses a plan (grammar above) into p (cleared first). 0, or -1 with a reason in why. */
int sc_hs_fault_plan_parse(const char *spec, sc_hs_fault_plan *p, char *why, size_t why_len);
const char *sc_hs_episode_kind_name(sc_hs_episode_kind k);

typedef struct sc_hs_fault_run {
    sc_hs_fault_plan plan;
    sc_hs_rig *rig;
    uint64_t t0_ns; /* virtual time of the run's start */
    int flood_node; /* bus node of the flooding stranger, -1: none */
    sc_can_dev flood_dev;
    uint64_t flood_sent;
    uint32_t flood_seq;
    uint8_t silent;         /* a silence episode is running: tracker frames are discarded */
    uint64_t silenced;      /* tracker frames discarded */
    uint64_t tx_refused_at; /* peer sends refused so far (bus-off) */
} sc_hs_fault_run;

/* Binds a plan to a rig whose engine runs from now (rig clock). Adds the flooding node when
 * the plan floods. 0 or SC_ERR_NO_SPACE (no free bus node). */
int sc_hs_fault_run_init(sc_hs_fault_run *r, const sc_hs_fault_plan *plan, sc_hs_rig *rig);
/* Before the engine frame released at release_ns (rig clock): applies every episode's state
 * at that time and sends the flood frames due since the last call. O(episodes + flood). */
void sc_hs_fault_run_before(sc_hs_fault_run *r, uint64_t release_ns);
/* After that frame: results bookkeeping. O(episodes). */
void sc_hs_fault_run_after(sc_hs_fault_run *r, uint64_t release_ns);
/* A tracker frame: 1 when a silence episode discards it (counted). */
int sc_hs_fault_run_silenced(sc_hs_fault_run *r);

#endif /* SC_HS_FAULTS_H */
