/*
 * sc_needle.h: the tracked needle in the B-scan, and its punctures.
 *
 * The needle is a straight shaft from its skin entry (tip - depth * dir) to its tip, in the
 * volume frame. Each frame it is carried to the image frame; the part of the shaft inside the
 * beam's elevational slab (|y| <= elev_half_mm, the beam's thickness across the image plane)
 * is drawn, projected on the plane, as a bright line of the shaft's radius: in plane the whole
 * shaft (a line, with reverberation: fading copies of it deeper along the beam, strongest when
 * the shaft is across the beam), out of plane only where it crosses the slab (a bright dot).
 * Drawing runs in the B-scan's pass (a line hook) on the displayed samples.
 *
 * Punctures: the label at the tip in the deformed configuration (read from the scan line that
 * passes nearest the tip when the tip is inside the slab; else the case's label map at the tip,
 * rigid) decides whether the tip is in a vessel lumen; each entry into a vein or an artery lumen
 * counts once (the tip must leave the lumen to count again); an artery entry is flagged.
 *
 * Memory: the caller's sc_needle (about 150 bytes). Never allocates, never calls the OS.
 * Deterministic.
 */
#ifndef SC_NEEDLE_H
#define SC_NEEDLE_H

#include <stdint.h>

#include "sc_bscan.h"
#include "sc_pose.h"
#include "sc_volume.h"

typedef struct sc_needle_def {
    float radius_mm;         /* drawn half-width of the shaft, (0, 2] (18 G: 0.6 mm) */
    float elev_half_mm;      /* half the beam's elevational thickness, (0, 5] */
    float reverb_spacing_mm; /* reverberation: distance between the shaft's echoes, (0, 5] */
    uint32_t reverb_count;   /* echoes below the shaft, 0..8 */
} sc_needle_def;

typedef struct sc_needle_status {
    uint8_t present;          /* a tracked needle this frame */
    uint8_t tip_label;        /* label at the tip (SC_LABEL_*), 0 without a needle */
    uint8_t tip_label_deformed; /* 1: read from the scan line (deformed), 0: rigid map */
    uint8_t last_puncture;    /* label of the last lumen entry, 0 none */
    uint32_t vein_punctures, artery_punctures;
    uint32_t drawn_pixels;    /* samples the needle brightened this frame */
    uint8_t in_plane;         /* the whole inserted shaft lies within the slab */
} sc_needle_status;

typedef struct sc_needle {
    sc_needle_def def;
    /* input: volume frame */
    uint8_t present;
    float tip_mm[3], dir[3], depth_mm;
    /* this frame, image frame: the visible part of the shaft, projected (x, z) */
    uint8_t visible;
    float e0x, e0z, e1x, e1z;
    float spec;          /* reverberation strength: the shaft across the beam 1 .. along it 0 */
    float tip_img[3];
    float tip_best_d2;   /* nearest sample to the tip so far this frame */
    uint8_t tip_line_label;
    uint8_t prev_label;
    sc_needle_status status;
} sc_needle;

/* 0.6 mm, slab 1 mm half thickness, echoes every 1 mm, 4 echoes. */
sc_needle_def sc_needle_default_def(void);

/* Validate and reset (no needle, no punctures). O(1). Errors: SC_ERR_INVALID_ARG,
 * SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_needle_init(sc_needle *n, const sc_needle_def *def);

/* The needle this frame (volume frame; dir unit, hub to tip) or none (present 0). O(1). Non-
 * finite input counts as none. */
void sc_needle_set(sc_needle *n, int present, const float tip_mm[3], const float dir[3],
                   float depth_mm);

/* Prepare the frame for the image pose img2vol (image frame -> volume frame). O(1). */
void sc_needle_frame_begin(sc_needle *n, const sc_xform *img2vol);

/* Draw into one computed scan line and watch the tip (call from the B-scan's line hook).
 * O(samples * (1 + reverb_count)) for lines that pass the shaft, O(1) for the others. */
void sc_needle_line(sc_needle *n, const sc_bscan_line_view *v);

/* After the frame: the tip's label (the scan line's, or the volume's label map) and the
 * punctures. Returns 1 when the tip entered a vein or artery lumen this frame, else 0. O(1). */
int sc_needle_frame_end(sc_needle *n, const sc_volume *v);

const sc_needle_status *sc_needle_status_get(const sc_needle *n);

#endif /* SC_NEEDLE_H */
