/*
 * sc_acoustics.h: beam-dependent acoustics along one scan line, in the deformed configuration.
 *
 * The B-scan synthesis (sc_bscan.c) fills a line with the case volume's values at each pixel's
 * rest position and the rest label there, pixel by pixel along the beam as it now runs through
 * the deformed tissue. This pass then walks the line from the probe face down and applies what
 * the pulse meets on its way, per label (the acoustic table below, kept apart from the
 * mechanical materials table):
 * - attenuation: the echo of depth d has crossed everything above it twice; its loss is the
 *   sum of 2 alpha(label) f ds over the pixels above (alpha in dB/cm/MHz, f the centre
 *   frequency), so bone (20 dB/cm/MHz) casts a shadow and a blood-filled lumen (0.15) leaves
 *   the tissue below it brighter than beside it (posterior enhancement);
 * - interfaces: where the label changes, the intensity reflection R = ((Z2 - Z1)/(Z2 + Z1))^2
 *   of the impedance mismatch is an echo at the interface (shown at 10 log10 R dB below white)
 *   and the transmitted part (1 - R) crosses it twice (none at SC_LABEL_OUTSIDE: coupling gel,
 *   or the tissue continued beyond the case volume);
 * - scattering: a per-label offset (dB) on the volume's echogenicity (0 keeps the volume's);
 * - time-gain compensation as on a scanner: the loss of average soft tissue (alpha_ref) is
 *   given back with depth, so uniform tissue stays uniform and only departures from it show.
 * All of it follows the beam: tilt the probe and the shadow turns with it. For cases whose
 * volume already holds these effects (real-patient volumes, the baked phantoms) the pass is off
 * (sc_bscan_def.acoustics).
 *
 * Values are displayed grey levels (the display's dynamic range maps dB to 0..255), so the pass
 * works on the finished line in place. Pixels at 0 (air above the skin) stay 0.
 *
 * Memory: the caller's sc_acoustics (about 0.7 KiB). Never allocates, never calls the OS.
 * Deterministic: the tables are computed in float32 once (sc_acoustics_init) and held in Q16
 * fixed point (1/65536 grey level); the pass along a line is integer arithmetic, so its bytes
 * are the same in every build and it works per run of one label (the loss at a run's sample i
 * is the loss at its start plus i steps, exactly), not as a float chain per sample.
 */
#ifndef SC_ACOUSTICS_H
#define SC_ACOUSTICS_H

#include <stdint.h>

#include "sc_labels.h"

/* Acoustic properties of one label. */
typedef struct sc_acoustic_props {
    float atten_db_cm_mhz; /* attenuation coefficient, [0, 100] */
    float impedance_mrayl; /* characteristic acoustic impedance, [0.1, 20] */
    float scatter_db;      /* offset on the volume's echogenicity, [-60, 60] */
} sc_acoustic_props;

typedef struct sc_acoustics_def {
    sc_acoustic_props label[SC_LABEL_COUNT];
    float frequency_mhz;       /* centre frequency, [1, 30] */
    float ref_atten_db_cm_mhz; /* what the automatic TGC gives back, [0, 10] */
} sc_acoustics_def;

/* Table values are clamped to this many Q16 units (4096 grey levels): a per-sample loss, an
 * interface loss or a scattering offset that large leaves what it touches black (or white)
 * either way, and the 32-bit tables and the per-run arithmetic cannot overflow. */
#define SC_ACOU_Q_LIMIT (INT32_C(1) << 28)

/* Precomputed per line sample, in Q16 grey levels (value x 65536, rounded). */
typedef struct sc_acoustics {
    int32_t atten_q[SC_LABEL_COUNT]; /* two-way loss per sample, minus the TGC's (even) */
    int32_t scatter_q[SC_LABEL_COUNT];
    int32_t trans_q[SC_LABEL_COUNT][SC_LABEL_COUNT]; /* two-way transmission loss at a->b */
    int32_t echo_q[SC_LABEL_COUNT][SC_LABEL_COUNT];  /* interface echo a->b (0: none) */
} sc_acoustics;

/* Soft-tissue values at 7.5 MHz from Duck, "Physical properties of tissue" (1990) and Szabo,
 * "Diagnostic ultrasound imaging" (2004), table 4.x, picked inside their ranges: fat 0.6
 * dB/cm/MHz and 1.38 MRayl, muscle 0.7 and 1.70, skin 0.8 and 1.60, blood 0.15 and 1.61,
 * nerve 0.9 and 1.65, thrombus 0.5 and 1.66, cortical bone 20 and 7.8; outside (coupling gel,
 * and the tissue continued beyond the case volume) as average soft tissue, 0.65 and 1.63,
 * which is also the TGC's reference. */
sc_acoustics_def sc_acoustics_default_def(void);

/* Validate def and fill the tables for a line of samples sample_mm apart shown over
 * dynamic_range_db. O(labels^2). Never allocates.
 * Errors: SC_ERR_NOT_FINITE, SC_ERR_RANGE (a value outside its range above, sample_mm or
 * dynamic_range_db not positive). On error a is unchanged. */
int sc_acoustics_init(sc_acoustics *a, const sc_acoustics_def *def, float sample_mm,
                      float dynamic_range_db);

/* Apply the pass to one line in place: out[k] the displayed value, lab[k] its label (values
 * >= SC_LABEL_COUNT are read as SC_LABEL_OUTSIDE). O(n), per run of one label. Never
 * allocates. The portable run kernel (sc_acoustics_run_generic). */
void sc_acoustics_line(const sc_acoustics *a, const uint8_t *lab, uint8_t *out, uint32_t n);

/* The samples of a run of one label after its first, no interface among them: sample i
 * becomes shade(out[i], out[i] x 65536 + base - i step) (Q16; 0 stays 0; rounded to nearest,
 * halves up, saturated to 0..255). The caller keeps base - i step within +-2^29 over the run.
 * A variant of the x86-64-v3 level (sc_bscan_kern.h: sc_acoustics_run_selected) gives the
 * same bytes. */
typedef void (*sc_acoustics_run_fn)(uint8_t *restrict out, uint32_t len, int32_t base,
                                    int32_t step);
void sc_acoustics_run_generic(uint8_t *restrict out, uint32_t len, int32_t base, int32_t step);

/* sc_acoustics_line with the run kernel run. */
void sc_acoustics_line_k(const sc_acoustics *a, const uint8_t *lab, uint8_t *out, uint32_t n,
                         sc_acoustics_run_fn run);

#endif /* SC_ACOUSTICS_H */
