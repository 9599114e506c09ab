/* fuzz_sc_case.c: the case loader accepts or refuses any byte image, never crashes, and an
 * accepted case always satisfies the invariants the engine relies on. */
#include <string.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_fuzz.h"
#include "sc_labels.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_case c;
    memset(&c, 0xA5, sizeof(c));
    int rc = sc_case_load(data, size, &c);
    if (rc != SC_OK) {
        SC_FUZZ_CHECK(rc < 0);
        return 0;
    }
    const sc_volume *v = &c.volume;
    uint64_t n = (uint64_t)v->dim[0] * v->dim[1] * v->dim[2];
    SC_FUZZ_CHECK(n == c.voxel_count && n <= SC_MAX_VOLUME_VOXELS);
    SC_FUZZ_CHECK(v->voxels >= data && v->voxels + n <= data + size);
    SC_FUZZ_CHECK(v->labels >= data && v->labels + n <= data + size);
    for (uint64_t i = 0; i < n; i++) {
        SC_FUZZ_CHECK(v->labels[i] < c.material_count);
    }
    SC_FUZZ_CHECK(c.mesh.nx <= SC_MAX_MESH_NX && c.mesh.ny <= SC_MAX_MESH_NY &&
                  c.mesh.nz <= SC_MAX_MESH_NZ);
    SC_FUZZ_CHECK(strlen(c.name) < SC_CASE_NAME_LEN);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 1u) {
        return 0;
    }
    enum { D = 6 };
    static uint8_t vox[D * D * D], lab[D * D * D];
    for (uint32_t k = 0; k < D * D * D; k++) {
        vox[k] = (uint8_t)(k * 7u);
        lab[k] = (uint8_t)(k % 4u);
    }
    sc_case_def def = sc_case_default_def();
    def.name = i ? "fuzz-seed-b" : "fuzz-seed";
    def.description = "fuzz seed";
    def.volume = (sc_volume){.dim = {D, D, D},
                             .spacing_mm = {1.0f, 1.0f, 1.0f},
                             .origin_mm = {0.0f, 0.0f, 0.0f},
                             .voxels = vox,
                             .labels = lab};
    def.material_count = SC_LABEL_COUNT;
    for (uint32_t m = 0; m < SC_LABEL_COUNT; m++) {
        def.materials[m].e_pa = 10000.0f;
        def.materials[m].poisson = 0.45f;
        def.materials[m].density_kg_m3 = 1000.0f;
    }
    def.mesh = (sc_mesh_def){.nx = 3, .ny = 3, .nz = 3,
                             .origin_mm = {0.5f, 0.5f, 0.5f},
                             .size_mm = {4.0f, 4.0f, 4.0f}};
    size_t out = 0;
    if (sc_case_write(&def, buf, cap, &out) != SC_OK) {
        return 0;
    }
    return out;
}
