/* fuzz_sc_case_crcfix.c: the case loader past its CRCs. A mutated case image almost never
 * carries valid CRCs, so the plain target (fuzz_sc_case) mostly exercises the framing; this
 * one first repairs the image the way a careful attacker would (file size, every section's
 * payload CRC and header CRC, the file header's CRC, wherever the framing lets it find them)
 * and then loads it both ways the engine does: whole (sc_case_load) and in bounded slices
 * (sc_case_check_begin/step/finish, as a case switch runs), checking that the two accept
 * exactly the same images and describe them the same way.
 * Input: the case image; its first byte's low bits also pick the slice budget. */
#include <stdlib.h>
#include <string.h>

#include "sc_case.h"
#include "sc_crc32.h"
#include "sc_err.h"
#include "sc_fuzz.h"
#include "sc_fuzz_case_seed.h"
#include "sc_labels.h"

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t rd64(const uint8_t *p)
{
    return (uint64_t)rd32(p) | (uint64_t)rd32(p + 4) << 32;
}

static void wr32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) {
        p[i] = (uint8_t)(v >> (8 * i));
    }
}

static void wr64(uint8_t *p, uint64_t v)
{
    wr32(p, (uint32_t)v);
    wr32(p + 4, (uint32_t)(v >> 32));
}

/* Offsets of docs/case-format.md: file header (size at 16, section count at 24, CRC at 60),
 * section headers (payload size at 8, payload CRC at 16, header CRC at 60). */
static void repair(uint8_t *b, size_t size)
{
    if (size < SC_CASE_HEADER_SIZE) {
        return;
    }
    wr64(b + 16, size);
    const uint32_t count = rd32(b + 24);
    uint64_t off = SC_CASE_HEADER_SIZE;
    for (uint32_t i = 0; i < count && i < SC_CASE_MAX_SECTIONS; i++) {
        if (size - off < SC_CASE_SECTION_HEADER_SIZE) {
            break;
        }
        uint8_t *h = b + off;
        const uint64_t psize = rd64(h + 8);
        const uint64_t avail = size - off - SC_CASE_SECTION_HEADER_SIZE;
        if (psize <= avail) {
            wr32(h + 16, sc_crc32(h + SC_CASE_SECTION_HEADER_SIZE, (size_t)psize));
        }
        wr32(h + 60, sc_crc32(h, 60));
        if (psize > avail) {
            break;
        }
        off = (off + SC_CASE_SECTION_HEADER_SIZE + psize + 63u) & ~(uint64_t)63u;
        if (off >= size) {
            break;
        }
    }
    wr32(b + 60, sc_crc32(b, 60));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *b = malloc(size ? size : 1u);
    SC_FUZZ_CHECK(b != NULL);
    memcpy(b, data, size);
    repair(b, size);

    static sc_case whole, sliced;
    memset(&whole, 0xA5, sizeof whole);
    memset(&sliced, 0x5A, sizeof sliced);
    const int rc = sc_case_load(b, size, &whole);
    SC_FUZZ_CHECK(rc <= 0);

    sc_case_check k;
    const size_t budget = size ? ((size_t)1u << (data[0] & 15u)) : 1u;
    int rs = sc_case_check_begin(&k, b, size);
    uint32_t steps = 0;
    while (rs == 0) {
        rs = sc_case_check_step(&k, budget);
        SC_FUZZ_CHECK(++steps <= size / budget + 2u * SC_CASE_MAX_SECTIONS + 4u);
    }
    if (rs == 1) {
        rs = sc_case_check_finish(&k, &sliced);
    }
    SC_FUZZ_CHECK(rs <= 0);
    /* the two accept exactly the same images (the error of a bad one may differ) */
    SC_FUZZ_CHECK((rc == SC_OK) == (rs == SC_OK));
    if (rc == SC_OK) {
        const sc_volume *v = &whole.volume;
        const uint64_t n = (uint64_t)v->dim[0] * v->dim[1] * v->dim[2];
        SC_FUZZ_CHECK(n == whole.voxel_count && n <= SC_MAX_VOLUME_VOXELS);
        SC_FUZZ_CHECK(v->voxels >= b && v->voxels + n <= b + size);
        SC_FUZZ_CHECK(v->labels >= b && v->labels + n <= b + size);
        for (uint64_t i = 0; i < n; i++) {
            SC_FUZZ_CHECK(v->labels[i] < whole.material_count);
        }
        SC_FUZZ_CHECK(whole.case_id == sliced.case_id);
        SC_FUZZ_CHECK(whole.voxel_count == sliced.voxel_count);
        SC_FUZZ_CHECK(whole.material_count == sliced.material_count);
        SC_FUZZ_CHECK(sliced.volume.voxels == v->voxels && sliced.volume.labels == v->labels);
        SC_FUZZ_CHECK(memcmp(whole.volume.dim, sliced.volume.dim, sizeof v->dim) == 0);
        SC_FUZZ_CHECK(whole.mesh.nx == sliced.mesh.nx && whole.mesh.ny == sliced.mesh.ny &&
                      whole.mesh.nz == sliced.mesh.nz);
        SC_FUZZ_CHECK(strcmp(whole.name, sliced.name) == 0);
        SC_FUZZ_CHECK(strlen(whole.name) < SC_CASE_NAME_LEN);
        SC_FUZZ_CHECK(whole.mesh.nx <= SC_MAX_MESH_NX && whole.mesh.ny <= SC_MAX_MESH_NY &&
                      whole.mesh.nz <= SC_MAX_MESH_NZ);
    }
    free(b);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    return sc_fuzz_case_seed(i, buf, cap);
}
