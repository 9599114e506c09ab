/*
 * sc_doppler.h: colour Doppler and pulsed-wave (spectral) Doppler, synthesised from a flow model
 * of the case's vessels, computed in the B-scan's own pass (a line hook of sc_bscan).
 *
 * Flow model, built once per case (sc_doppler_attach_volume, at case load): for each flowing
 * vessel label (vein, artery) the label voxels' centroid and principal axis (a straight
 * centreline: phantom vessels are tubes; a curved real vessel gets its best straight fit) and
 * an effective lumen radius R = sqrt(2 mean r^2) (exact for a round tube). Thrombus is not
 * blood: it never flows. Per frame the velocity at a lumen sample, along the centreline, is
 *     v = sign * V(t) * (1 - (r/R)^2)            (Poiseuille profile, r from the axis at rest)
 * with V(t) pulsatile for arteries (systolic peak, diastolic floor, one cardiac cycle of the
 * phase input) and phasic for veins (respiratory modulation of the respiratory phase input).
 * The phases are inputs (sc_doppler_set_phase, e.g. from the pulsation model) or, by default,
 * advanced here from the def's heart and breathing rates (sc_doppler_advance).
 *
 * Colour: inside the colour box, each sample whose label in the deformed configuration is a
 * flowing lumen (a vein squeezed shut has no lumen samples left, hence no colour) gets the
 * velocity toward the probe along the steered colour beam, v_b = -v . beam (cos theta), wrapped
 * into [-Vn, Vn) where Vn = c PRF / (4 f0) is the scale's Nyquist velocity (aliasing), zeroed
 * below the wall filter (c wall_hz / (2 f0)) and where the colour gain leaves the lumen edge
 * (weak, slow blood) below the colour threshold. Sent as signed bytes v_b / Vn * 127 per sample
 * (0: no colour) with the display's colour_line op; the sink maps them to red (toward) / blue
 * (away) (sc_doppler_colour_rgb, the map of a scanner).
 * Spectrum: the samples of the pulsed-wave gate (line and depth range of the def) give a
 * velocity histogram over SC_DOPPLER_SPECTRUM_BINS bins of [-Vn, Vn) (aliased, wall-filtered),
 * each sample spread by a triangular kernel (spectral broadening: a floor plus a share of its
 * speed, from the aperture), with a deterministic speckle-like modulation; log-compressed to
 * bytes over 40 dB: one scrolling column per frame, no FFT. The doppler record (box, scale,
 * gate, spectrum) closes the colour of a frame (display op doppler, before frame_end).
 *
 * Memory: all state in the caller's sc_doppler (about 1 KB + bins; stated by
 * sizeof(sc_doppler)). Never allocates, never calls the OS. One writer. Deterministic: float32,
 * fixed order, the spectrum's modulation is a hash of the frame number and bin.
 */
#ifndef SC_DOPPLER_H
#define SC_DOPPLER_H

#include <stdint.h>

#include "sc_bscan.h"
#include "sc_config.h"
#include "sc_hal_display.h"
#include "sc_labels.h"
#include "sc_volume.h"

/* Flow model of one vessel label (rest configuration, volume frame, mm). */
typedef struct sc_doppler_vessel {
    uint8_t valid;     /* 1: the label is in the case and has an axis */
    float centre_mm[3];
    float axis[3];     /* unit, oriented with its largest component positive */
    float radius_mm;   /* effective lumen radius */
    uint32_t voxels;   /* label voxels seen (subsampled) */
} sc_doppler_vessel;

typedef struct sc_doppler_def {
    uint32_t enabled;       /* 0: no colour, no spectrum, nothing sent */
    /* colour box, fractions of the image: lateral [u0, u1), depth [v0, v1), 0..1, u0 < u1 */
    float box_u0, box_u1, box_v0, box_v1;
    float steer_deg;        /* colour beam steering in the image plane, [-30, 30] */
    float prf_hz;           /* pulse repetition frequency: the scale, [100, 20000] */
    float f0_mhz;           /* Doppler transmit frequency, [1, 15] */
    float wall_hz;          /* wall filter cut-off (Doppler shift), [0, prf/4] */
    float gain_db;          /* colour gain, [-30, 30]: lower gain loses the slow lumen edge */
    /* pulsed-wave gate: lateral fraction and depth range in mm */
    float gate_u, gate_depth_mm, gate_len_mm; /* u in [0, 1]; depth > 0; len in [0.5, 20] */
    /* flow */
    float artery_peak_mm_s;     /* systolic peak at the centreline, [0, 3000] */
    float artery_floor_mm_s;    /* end-diastolic floor, [0, peak] */
    float vein_mean_mm_s;       /* venous centreline velocity, [0, 1000] */
    float vein_resp_fraction;   /* respiratory modulation, [0, 1] */
    float heart_rate_bpm;       /* own cardiac clock when no phase is given, [20, 240] */
    float resp_rate_bpm;        /* own breathing clock, [4, 60] */
    float artery_sign, vein_sign; /* +1/-1: flow along / against the vessel's oriented axis */
} sc_doppler_def;

typedef struct sc_doppler_status {
    uint32_t frame_no;
    uint32_t colour_pixels;   /* samples given colour this frame */
    uint32_t aliased_pixels;  /* of those, |v_b| above the Nyquist velocity (wrapped) */
    uint32_t filtered_pixels; /* lumen samples the wall filter or the gain left uncoloured */
    float gate_velocity_mm_s; /* model velocity toward the probe at the gate centre; 0 outside */
    float gate_peak_mm_s;     /* velocity of the spectrum's strongest bin (bin centre) */
    uint8_t gate_in_lumen;    /* the gate's centre sample is in a flowing lumen */
    uint32_t display_errors;  /* colour_line / doppler calls refused (other than absent ops) */
} sc_doppler_status;

typedef struct sc_doppler {
    sc_doppler_def def;
    sc_doppler_vessel vessel[SC_LABEL_COUNT]; /* only VEIN and ARTERY are used */
    float voxel_mm[3], origin_mm[3];          /* of the attached volume */
    uint8_t attached;
    /* flow state */
    float cardiac_phase, resp_phase; /* [0, 1) */
    uint8_t phase_external;          /* set by sc_doppler_set_phase this frame */
    float v_artery_mm_s, v_vein_mm_s; /* centreline speeds of this frame */
    /* this frame */
    const sc_display_dev *display;
    uint32_t frame_no;
    uint16_t box_l0, box_l1, box_k0, box_k1, gate_line, gate_k0, gate_k1;
    float steer_s, steer_c; /* sin, cos of the steering */
    float nyq_mm_s, wall_mm_s, gain_lin;
    int8_t colour[SC_MAX_SCAN_SAMPLES];
    float hist[SC_DOPPLER_SPECTRUM_BINS];
    uint8_t spectrum[SC_DOPPLER_SPECTRUM_BINS];
    sc_doppler_status status;
} sc_doppler;

/* Defaults: on, box over the middle (u 0.25..0.75, v 0.05..0.7), no steering, PRF 4 kHz at
 * 5 MHz (Vn 308 mm/s), wall 100 Hz (15 mm/s), gain 0 dB, gate at the image centre 20 mm deep,
 * 2 mm long; carotid-like 800 mm/s systolic, 200 mm/s diastolic; jugular-like 150 mm/s with
 * 50 % respiratory modulation; 72 bpm, 15 breaths/min; artery +1, vein -1 (opposite flows). */
sc_doppler_def sc_doppler_default_def(void);

/* Validate def (ranges above, all finite). O(1). Errors: SC_ERR_INVALID_ARG (NULL),
 * SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_doppler_def_validate(const sc_doppler_def *def);

/* Validate and set def, forget the vessel model, phases to 0. O(1). Errors as validate; on
 * error d is not usable. */
int sc_doppler_init(sc_doppler *d, const sc_doppler_def *def);

/* Change settings between frames (box, steering, scale, gain, gate, flow); the vessel model
 * stays. O(1). Errors as validate; on error the previous settings stay. */
int sc_doppler_set_def(sc_doppler *d, const sc_doppler_def *def);

/* Build the vessel model from the case's label map (at case load, outside the frame): a
 * strided pass over at most SC_DOPPLER_MAX_SCAN_VOXELS voxels. A volume without labels leaves
 * no vessel (no colour). O(that bound). Errors: SC_ERR_INVALID_ARG (NULL, no voxels). */
#ifndef SC_DOPPLER_MAX_SCAN_VOXELS
#define SC_DOPPLER_MAX_SCAN_VOXELS (1u << 18)
#endif
int sc_doppler_attach_volume(sc_doppler *d, const sc_volume *v);

/* Set the cardiac and respiratory phases ([0, 1), wrapped) of the next frame, e.g. from the
 * pulsation model; sc_doppler_advance then leaves them as set. O(1). Errors: SC_ERR_INVALID_ARG,
 * SC_ERR_NOT_FINITE. */
int sc_doppler_set_phase(sc_doppler *d, float cardiac_phase, float resp_phase);

/* Advance the own clocks by dt_s (unless a phase was set for this frame) and compute this
 * frame's centreline speeds. O(1). Never fails (NULL or non-finite dt: nothing happens). */
void sc_doppler_advance(sc_doppler *d, float dt_s);

/* Prepare a frame: box and gate in lines/samples of this scan geometry, and install the line
 * hook on b (off: the hook is removed). The colour lines and the doppler record then leave
 * through display during sc_bscan_frame. O(1). Errors: SC_ERR_INVALID_ARG (NULL). */
int sc_doppler_frame_begin(sc_doppler *d, sc_bscan *b, const sc_display_dev *display,
                           uint32_t frame_no);

/* The line hook (installed by sc_doppler_frame_begin): O(samples + bins) per line. */
void sc_doppler_line_hook(void *ctx, const sc_bscan_line_view *view);

/* Flow velocity along the vessel (signed, mm/s, volume frame vector in out) at a rest position
 * (voxel units) for a label, this frame. Returns 1 in a flowing lumen, 0 elsewhere. O(1). */
int sc_doppler_velocity_at(const sc_doppler *d, uint8_t label, const float p_vox[3],
                           float out_mm_s[3]);

/* The scanner's colour map: a colour byte (signed, as sent) to RGB: red/yellow toward the
 * probe, blue/cyan away, brighter with speed. O(1). */
void sc_doppler_colour_rgb(int8_t value, uint8_t rgb[3]);

const sc_doppler_status *sc_doppler_status_get(const sc_doppler *d);

#endif /* SC_DOPPLER_H */
