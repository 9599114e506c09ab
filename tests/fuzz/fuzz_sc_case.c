/* fuzz_sc_case.c: the case loader accepts or refuses any byte image, never crashes, and an
 * accepted case always satisfies the invariants the engine relies on. */
#include <string.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_fuzz.h"
#include "sc_fuzz_case_seed.h"
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
    /* an accepted DRIV is a drive the lumens take as it is */
    SC_FUZZ_CHECK(c.drive.present <= 1u);
    SC_FUZZ_CHECK(!c.drive.present ||
                  (sc_lumen_drive_validate(&c.drive.d) == SC_OK && c.drive.d.valsalva == 0u));
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    return sc_fuzz_case_seed(i, buf, cap);
}
