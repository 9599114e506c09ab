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
 * Memory: the caller's sc_acoustics (about 0.8 KiB). Never allocates, never calls the OS.
 * Deterministic (float32, one fixed order).
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

/* Precomputed per line sample (grey levels). */
typedef struct sc_acoustics {
    float atten_gl[SC_LABEL_COUNT]; /* two-way loss per sample, minus the TGC's */
    float scatter_gl[SC_LABEL_COUNT];
    float trans_gl[SC_LABEL_COUNT][SC_LABEL_COUNT]; /* two-way transmission loss at a->b */
    float echo_gl[SC_LABEL_COUNT][SC_LABEL_COUNT];  /* interface echo a->b (0: none) */
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
 * >= SC_LABEL_COUNT are read as SC_LABEL_OUTSIDE). O(n). Never allocates. */
void sc_acoustics_line(const sc_acoustics *a, const uint8_t *lab, uint8_t *out, uint32_t n);

#endif /* SC_ACOUSTICS_H */
