/*
 * sc_psf.h: speckle as a scanner forms it: a scatterer field fixed in the rest configuration,
 * convolved with the beam's point spread function in image space (issue 15 item 2).
 *
 * The B-scan synthesis (sc_bscan.c) knows, for every sample of a scan line, the rest position
 * it images (the mesh carries it through the deformation). At that position this pass draws a
 * complex scatterer amplitude from a hashed lattice fixed in the rest configuration (so the
 * speckle deforms with the tissue), its cells one sample deep and one line wide in x and z and
 * the slice thickness in elevation (y), interpolated linearly along y: the speckle decorrelates
 * as the probe moves out of plane by about the slice thickness. The lattice assumes the case's
 * convention (probe along +z, lines along x, elevation y at rest).
 * The line's echo amplitude (the displayed grey of the volume, acoustics applied, turned back
 * into a linear amplitude) times the scatterer is then convolved, as I/Q (complex baseband), in
 * the image's own axes, so a tilted probe's speckle is still long across its beam:
 *  - axial: the pulse's Gaussian envelope, -6 dB fractional bandwidth B at centre frequency f:
 *    FWHM = c 0.8825 / (2 B f) (a Gaussian's time-bandwidth product 4 ln 2 / pi, c = 1.54 mm/us);
 *  - lateral, per depth band: transmit focus fixed at focus_mm, receive dynamically focused:
 *    w_rx = lambda F (F = focus / aperture), w_tx(z) = w_rx sqrt(1 + ((z - focus) / z_R)^2) with
 *    z_R half the depth of field 7.1 lambda F^2, two-way w = (w_tx^-2 + w_rx^-2)^-1/2: narrowest
 *    at the focus (w_rx / sqrt 2), w_rx far from it.
 * The envelope |I + jQ| is log-compressed back to grey: fully developed speckle, mean / std of
 * the envelope 1.91; the mean intensity is the volume's (so the mean of the log image lies
 * 2.51 dB below the voxel's grey, as with the phantom builder's baked speckle). Pixels at 0 (air) stay 0. What a line hook (colour Doppler, the needle)
 * drew stays as it drew it.
 *
 * Lateral convolution needs the lines beside: the pass holds SC_PSF_RING lines in flight and a
 * line leaves SC_PSF_MAX_LAT_HALF lines after it was computed (sc_psf_line_ready); the frame
 * still streams every line in order.
 *
 * Memory: the caller's sc_psf (SC_PSF_RING lines of I, Q, two grey planes and the taps'
 * weights per sample: about 93 KiB with 512 samples). Never allocates, never calls the OS. Deterministic (float32, fixed order,
 * hashed scatterers). Threads: one writer. Compile-time switch SC_BSCAN_PSF (config/sc_config.h).
 */
#ifndef SC_PSF_H
#define SC_PSF_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_scan_geom.h"

#ifndef SC_PSF_MAX_LAT_HALF
#define SC_PSF_MAX_LAT_HALF 6u /* lateral kernel half-width, lines */
#endif
#ifndef SC_PSF_MAX_AX_HALF
#define SC_PSF_MAX_AX_HALF 6u /* axial kernel half-width, samples */
#endif
#define SC_PSF_RING  (2u * SC_PSF_MAX_LAT_HALF + 1u)
#define SC_PSF_BANDS 32u /* depth bands of the lateral kernel */

typedef struct sc_psf_def {
    float fractional_bw; /* -6 dB fractional bandwidth of the pulse, [0.2, 1.5] */
    float aperture_mm;   /* active aperture, [1, 60] */
    float slice_mm;      /* elevational extent (slice thickness), [0.1, 10] */
    uint32_t seed;       /* scatterer field */
} sc_psf_def;

/* The kernels' widths as set up, for the record and the tests (mm, amplitude FWHM). */
typedef struct sc_psf_widths {
    float axial_fwhm_mm;
    float lateral_fwhm_focus_mm;
    float lateral_fwhm_mm[SC_PSF_BANDS]; /* per depth band */
    float band_depth_mm[SC_PSF_BANDS];   /* band centre depth */
} sc_psf_widths;

typedef struct sc_psf {
    sc_psf_def def;
    uint32_t lines_n, samples_n;
    uint32_t ax_half;
    float ax_w[2u * SC_PSF_MAX_AX_HALF + 1u];
    uint32_t band_k0[SC_PSF_BANDS + 1u];
    uint32_t lat_half[SC_PSF_BANDS];
    float lat_w[SC_PSF_BANDS][SC_PSF_RING];
    uint32_t lat_max;                                       /* largest half-width */
    _Alignas(64) float lat_wk[SC_PSF_RING][SC_MAX_SCAN_SAMPLES]; /* tap j's weight per sample */
    float amp[256];      /* grey -> linear amplitude */
    float out_a, out_b;  /* grey = out_a log2(|z|^2) + out_b */
    float cell_mm[3];    /* scatterer lattice cell */
    float cell_inv[3];   /* this frame: voxel units -> cells */
    sc_psf_widths widths;
    /* lines in flight, slot = line % SC_PSF_RING */
    _Alignas(64) float re[SC_PSF_RING][SC_MAX_SCAN_SAMPLES];
    _Alignas(64) float im[SC_PSF_RING][SC_MAX_SCAN_SAMPLES];
    uint8_t tissue[SC_PSF_RING][SC_MAX_SCAN_SAMPLES]; /* grey before the line hook */
    uint8_t hooked[SC_PSF_RING][SC_MAX_SCAN_SAMPLES]; /* grey after it */
    /* the line being filled: scatterers (I, Q), padded by the axial half-width */
    _Alignas(64) float sre[SC_MAX_SCAN_SAMPLES + 2u * SC_PSF_MAX_AX_HALF];
    _Alignas(64) float sim[SC_MAX_SCAN_SAMPLES + 2u * SC_PSF_MAX_AX_HALF];
} sc_psf;

/* Defaults: B = 0.5, an 8 mm aperture (F 2.5 at a 20 mm focus), 1 mm slice, seed 1. */
sc_psf_def sc_psf_default_def(void);

/* Validate def and build the kernels for this scan geometry, transmit focus (mm below the
 * face), centre frequency and displayed dynamic range. O(samples + bands * ring). Never
 * allocates. Errors: SC_ERR_INVALID_ARG (NULL), SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_psf_setup(sc_psf *p, const sc_psf_def *def, const sc_scan_def *scan,
                 const sc_scan_geom *geom, float focus_mm, float frequency_mhz,
                 float dynamic_range_db);

/* Start a frame on a volume of this voxel spacing (mm). O(1). */
void sc_psf_frame_begin(sc_psf *p, const float spacing_mm[3]);

/* Scatterers of samples [k0, k1) of the line being filled, at rest positions a + k b (voxel
 * units). Call for spans covering the line, then sc_psf_line_in. O(k1 - k0). */
void sc_psf_span(sc_psf *p, uint32_t k0, uint32_t k1, const float a[3], const float b[3]);

/* Line l's grey (before any line hook): echo x scatterers, axially convolved, into the ring.
 * O(samples * axial taps). */
void sc_psf_line_in(sc_psf *p, uint32_t l, const uint8_t *grey);

/* Line l's grey after the line hook (what it drew is kept). O(samples). */
void sc_psf_line_hooked(sc_psf *p, uint32_t l, const uint8_t *grey);

/* After line `last_in` went in: the line that may now leave, or -1 (none yet). Call repeatedly
 * after the last line of a frame until it answers -1 to flush. O(1). */
int32_t sc_psf_line_ready(const sc_psf *p, uint32_t last_in, uint32_t next_out);

/* Line m's speckled grey into out (samples_n bytes): lateral convolution and envelope (uses
 * the span scratch: call between sc_psf_line_in and the next line's spans). O(samples *
 * lateral taps). */
void sc_psf_line_out(sc_psf *p, uint32_t m, uint8_t *out);

#endif /* SC_PSF_H */
