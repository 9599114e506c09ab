/*
 * sc_trkemu.h: the tracker emulator's generator (host code, used by sc-tracker-emu and by
 * tests that feed the host simulator's bus in-process).
 *
 * Scripted probe motions in the tracker frame, sampled at rate_hz, encoded with the core codec
 * (sc_canproto: 3 classic frames or 1 FD frame per sample, one E2E counter per sample), with
 * faults injected on command. The probe frame follows sc_pose.h (x along the aperture, y
 * elevation, z along the beam); base_q orients it (default beam pointing down, -Z).
 *
 * Scripts (skin contact point P, hover height H, press depth D along -Z):
 *   press  hover 0.5 s, descend to P - D in 1 s, hold 1 s, rise in 1 s, hover 0.5 s; repeat
 *   sweep  at depth D, x moves P.x -L/2 .. +L/2 and back, triangular, period T (across the neck)
 *   rock   at depth D, tilt about the probe's y axis by A sin(2 pi t / T)
 *   lift   descend 1 s, hold 1 s, rise in 0.5 s, then silence (nothing sent) to the end
 *   csv    rows "t_s,x_mm,y_mm,z_mm,qw,qx,qy,qz[,force_n]", linear interpolation, nlerp
 * Contact force (when force_valid): force_n_per_mm * penetration below P.z, else 0.
 *
 * Faults, each every `period` samples from start_s on (0 = off); counted in injected[]:
 *   bad-crc       one payload bit of one frame of the sample flipped after protection
 *   counter-jump  the counter skips 5 ahead (beyond the receiver's max delta of 3)
 *   repeat        the sample is sent twice with the same counter (byte for byte: the
 *                 receiver counts a duplicate, not an error)
 *   silence       nothing sent for silence_ms (longer than the 100 ms timeout by default)
 *   implausible   cycles: quaternion norm 1.5, position outside the workspace, a 100 mm jump
 */
#ifndef SC_TRKEMU_H
#define SC_TRKEMU_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sc_canproto.h"

typedef enum sc_emu_script {
    SC_EMU_PRESS = 0,
    SC_EMU_SWEEP,
    SC_EMU_ROCK,
    SC_EMU_LIFT,
    SC_EMU_CSV,
    SC_EMU_SCRIPT_COUNT
} sc_emu_script;

typedef enum sc_emu_fault_kind {
    SC_EMU_F_BAD_CRC = 0,
    SC_EMU_F_COUNTER_JUMP,
    SC_EMU_F_REPEAT,
    SC_EMU_F_SILENCE,
    SC_EMU_F_IMPLAUSIBLE,
    SC_EMU_F_COUNT
} sc_emu_fault_kind;

typedef struct sc_emu_fault {
    sc_emu_fault_kind kind;
    uint32_t period; /* every period-th sample; 0 = off */
    double start_s;
} sc_emu_fault;

typedef struct sc_emu_row {
    double t_s;
    float pos_mm[3];
    float q[4];
    float force_n; /* < 0: not given */
} sc_emu_row;

#define SC_EMU_MAX_FAULTS 8u
#define SC_EMU_MAX_FRAMES 8u /* frames one sample may produce (repeat doubles them) */

typedef struct sc_emu_def {
    sc_emu_script script;
    double rate_hz;
    double duration_s;
    int fd;
    float point_mm[3];
    float hover_mm;
    float depth_mm;
    float length_mm;
    double period_s;
    float angle_deg;
    float base_q[4];
    float force_n_per_mm;
    int force_valid;
    double silence_ms;
    sc_emu_fault faults[SC_EMU_MAX_FAULTS];
    size_t n_faults;
    const sc_emu_row *rows; /* csv script */
    size_t n_rows;
} sc_emu_def;

/* Defaults: press at (0, 0, 0), hover 30 mm, depth 10 mm, sweep 60 mm, period 4 s, rock 15
 * degrees, 100 Hz, 10 s, classic frames, beam down (q = 0, 1, 0, 0), 0.5 N/mm, silence 300 ms. */
sc_emu_def sc_emu_default_def(void);

typedef struct sc_emu {
    sc_emu_def def;
    uint64_t sample; /* next sample index */
    uint8_t counter; /* next E2E counter */
    uint64_t silent_until_ns;
    uint32_t implausible_variant;
    uint64_t injected[SC_EMU_F_COUNT];
    uint64_t samples_sent;
    uint64_t frames_sent;
    uint64_t samples_silent; /* samples not sent (silence, lift) */
} sc_emu;

/* 0, or SC_ERR_INVALID_ARG / SC_ERR_RANGE for a bad definition (rate, duration, csv rows). */
int sc_emu_init(sc_emu *e, const sc_emu_def *def);
/* The scripted pose at t_s (no faults). */
sc_pose_msg sc_emu_pose_at(const sc_emu_def *def, double t_s);
/* Frames of the next sample (0 when silent) into out[cap >= SC_EMU_MAX_FRAMES]; *t_ns the
 * sample time from the start. Returns the frame count, or SC_ERR_NOT_FOUND past the duration. */
int sc_emu_next(sc_emu *e, sc_can_frame *out, size_t cap, uint64_t *t_ns);

/* Time of the next sample from the start (ns). */
uint64_t sc_emu_next_time_ns(const sc_emu *e);

/* Hands every frame of every sample due at or before until_ns (time from the start) to
 * send(ctx, frame), samples in order, all frames of a sample before the next. Returns the
 * number of samples taken (a silent sample counts, with no frames), or SC_ERR_NOT_FOUND once
 * the script is over and nothing was taken. send's result is not looked at: a sender that
 * refuses a frame is a lost frame, which the receiver's counters show. */
typedef int (*sc_emu_send_fn)(void *ctx, const sc_can_frame *frame);
int sc_emu_feed(sc_emu *e, uint64_t until_ns, sc_emu_send_fn send, void *ctx);

/* Loads csv rows (comma separated, '#' comments and a header line allowed, times strictly
 * increasing; a line of 510 bytes at most, no NUL byte). 0, or SC_ERR_PARSE with *bad_line
 * set, SC_ERR_NO_SPACE above cap. */
int sc_emu_load_csv(FILE *fp, sc_emu_row *rows, size_t cap, size_t *n, size_t *bad_line);

const char *sc_emu_script_name(sc_emu_script s);
const char *sc_emu_fault_name(sc_emu_fault_kind k);
/* By name ("press", "bad-crc", ...): 0 or SC_ERR_NOT_FOUND. */
int sc_emu_script_from_name(const char *name, sc_emu_script *out);
int sc_emu_fault_from_name(const char *name, sc_emu_fault_kind *out);

/* ---- the tracked needle (issue 18): a second tool, its own frames (0x120..0x122) ----------
 * Script: from start_s the needle advances from its skin entry point along dir at speed_mm_s
 * until max_depth_mm, holds for hold_s, then withdraws at the same speed (and repeats). Its
 * samples carry their own E2E counter. Tracker frame = volume frame of the emulator's
 * registration (as the probe's point_mm). */
typedef struct sc_emu_needle_def {
    double rate_hz;       /* samples per second, (0, 1000] */
    double start_s;       /* insertion starts */
    float entry_mm[3];    /* skin entry point */
    float dir[3];         /* shaft direction, hub to tip (normalised by init) */
    float speed_mm_s;     /* (0, 200] */
    float max_depth_mm;   /* (0, 200] */
    double hold_s;        /* at full depth, >= 0 */
} sc_emu_needle_def;

typedef struct sc_emu_needle {
    sc_emu_needle_def def;
    uint64_t sample;
    uint8_t counter;
} sc_emu_needle;

/* 100 Hz from 0.5 s, entry (0, 0, 0), straight down, 10 mm/s to 25 mm, hold 1 s. */
sc_emu_needle_def sc_emu_needle_default_def(void);
/* 0, SC_ERR_INVALID_ARG / SC_ERR_RANGE / SC_ERR_NOT_FINITE for a bad definition. */
int sc_emu_needle_init(sc_emu_needle *n, const sc_emu_needle_def *def);
/* The scripted needle at t_s (depth 0 before the start). */
sc_needle_msg sc_emu_needle_at(const sc_emu_needle_def *def, double t_s);
/* The 3 frames of the next sample into out[cap >= 3]; *t_ns its time from the start. Returns
 * the frame count (3) or a negative error. */
int sc_emu_needle_next(sc_emu_needle *n, sc_can_frame *out, size_t cap, uint64_t *t_ns);

#endif /* SC_TRKEMU_H */
