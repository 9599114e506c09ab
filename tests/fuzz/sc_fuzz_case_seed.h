/* sc_fuzz_case_seed.h: small valid case images as seeds for the case-loader targets. */
#ifndef SC_FUZZ_CASE_SEED_H
#define SC_FUZZ_CASE_SEED_H

#include <stddef.h>
#include <stdint.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_labels.h"

/* Seed i (0..3): a valid case of a 6^3 (i = 3: 3 x 5 x 2) volume, 4 or 2 labels, varied mesh,
 * spacing, origin and materials (all load: tools/fuzz-seeds.sh writes them as the corpus);
 * seeds 1 and 3 carry the optional DRIV section (the patient's vessel drive). */
static size_t sc_fuzz_case_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 3u) {
        return 0;
    }
    enum { D = 6 };
    static uint8_t vox[D * D * D], lab[D * D * D];
    for (uint32_t k = 0; k < D * D * D; k++) {
        vox[k] = (uint8_t)(k * 7u);
        lab[k] = (uint8_t)(k % (i == 2u ? 2u : 4u));
    }
    sc_case_def def = sc_case_default_def();
    def.name = i ? "fuzz-seed-b" : "fuzz-seed";
    def.description = i == 1u ? "" : "fuzz seed";
    const uint32_t dims[3] = {i == 3u ? 3u : D, i == 3u ? 5u : D, i == 3u ? 2u : D};
    def.volume = (sc_volume){.dim = {dims[0], dims[1], dims[2]},
                             .spacing_mm = {1.0f, i == 1u ? 0.5f : 1.0f, 1.0f},
                             .origin_mm = {0.0f, 0.0f, i == 2u ? -3.0f : 0.0f},
                             .voxels = vox,
                             .labels = lab};
    def.material_count = i == 2u ? 2u : SC_LABEL_COUNT;
    for (uint32_t m = 0; m < def.material_count; m++) {
        def.materials[m].e_pa = 10000.0f * (float)(m + 1u);
        def.materials[m].poisson = 0.45f;
        def.materials[m].density_kg_m3 = 1000.0f;
    }
    def.mesh = (sc_mesh_def){.nx = 3u + (i & 1u), .ny = 3, .nz = 3u + (i >> 1u),
                             .origin_mm = {0.5f, 0.5f, 0.5f},
                             .size_mm = {i == 3u ? 1.0f : 2.0f, i == 3u ? 1.0f : 2.0f,
                                         i == 3u ? 0.5f : 1.0f}};
    size_t out = 0;
    if (sc_case_write(&def, buf, cap, &out) != SC_OK) {
        return 0;
    }
    if (i & 1u) {
        sc_lumen_drive d = sc_lumen_drive_default();
        d.heart_rate_bpm = i == 1u ? 90.0f : 0.0f;
        d.wave = (uint8_t)(i == 3u ? SC_LUMEN_WAVE_SINE : SC_LUMEN_WAVE_ARTERIAL);
        uint8_t p[SC_CASE_DRIVE_SIZE];
        if (sc_case_drive_encode(&d, p) != SC_OK ||
            sc_case_append_section(buf, cap, &out, SC_CASE_TAG_DRIV_U32, p, sizeof p) != SC_OK) {
            return 0;
        }
    }
    return out;
}

#endif /* SC_FUZZ_CASE_SEED_H */
