/* sc_case.c: case file v1 loader and writer, see sc_case.h and docs/case-format.md. */
#include "sc_case.h"

#include <math.h>
#include <string.h>

#include "sc_crc32.h"
#include "sc_err.h"
#include "sc_le.h"

static int all_zero(const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (p[i] != 0u) {
            return 0;
        }
    }
    return 1;
}

static uint64_t align_up(uint64_t v)
{
    return (v + (SC_CASE_ALIGN - 1u)) & ~(uint64_t)(SC_CASE_ALIGN - 1u);
}

/* File header layout (offsets). */
enum {
    HDR_MAGIC = 0,
    HDR_VERSION = 8,
    HDR_HEADER_SIZE = 12,
    HDR_FILE_SIZE = 16,
    HDR_SECTION_COUNT = 24,
    HDR_FLAGS = 28,
    HDR_RESERVED = 32,
    HDR_CRC = 60
};
/* Section header layout (offsets). */
enum { SEC_TAG = 0, SEC_FLAGS = 4, SEC_SIZE = 8, SEC_CRC = 16, SEC_RESERVED = 20, SEC_HCRC = 60 };

_Static_assert(HDR_CRC + 4 == SC_CASE_HEADER_SIZE, "file header layout");
_Static_assert(SEC_HCRC + 4 == SC_CASE_SECTION_HEADER_SIZE, "section header layout");

/* Voxel count of dims with an overflow-safe product and the config limits. */
static int dims_voxels(const uint32_t dim[3], uint64_t *count)
{
    uint64_t n = 1;
    for (int a = 0; a < 3; a++) {
        if (dim[a] == 0u || dim[a] > SC_MAX_VOLUME_DIM) {
            return SC_ERR_CASE_DIMS;
        }
        /* n <= SC_MAX_VOLUME_VOXELS before the multiply and dim <= SC_MAX_VOLUME_DIM < 2^32:
         * checked division keeps this safe for any limit values. */
        if (n > (uint64_t)SC_MAX_VOLUME_VOXELS / dim[a]) {
            return SC_ERR_CASE_DIMS;
        }
        n *= dim[a];
    }
    if (n > (uint64_t)SC_MAX_VOLUME_VOXELS || n > (uint64_t)SIZE_MAX) {
        return SC_ERR_CASE_DIMS;
    }
    *count = n;
    return SC_OK;
}

static int text_ok(const uint8_t *p, size_t n, int multiline)
{
    size_t len = 0;
    while (len < n && p[len] != 0u) {
        uint8_t ch = p[len];
        int ok = ch >= 0x20u && ch != 0x7Fu;
        if (multiline && (ch == (uint8_t)'\n' || ch == (uint8_t)'\t')) {
            ok = 1;
        }
        if (!ok) {
            return 0;
        }
        len++;
    }
    if (len == n) {
        return 0; /* no terminating NUL */
    }
    return all_zero(p + len, n - len);
}

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

static void rd_xform(const uint8_t *p, sc_xform *x)
{
    for (int i = 0; i < 9; i++) {
        x->r[i] = sc_le_rd_f32(p + 4 * i);
    }
    for (int i = 0; i < 3; i++) {
        x->t_mm[i] = sc_le_rd_f32(p + 36 + 4 * i);
    }
}

static void wr_xform(uint8_t *p, const sc_xform *x)
{
    for (int i = 0; i < 9; i++) {
        sc_le_wr_f32(p + 4 * i, x->r[i]);
    }
    for (int i = 0; i < 3; i++) {
        sc_le_wr_f32(p + 36 + 4 * i, x->t_mm[i]);
    }
}

sc_case_def sc_case_default_def(void)
{
    sc_case_def d;
    memset(&d, 0, sizeof d);
    d.name = "";
    d.description = "";
    d.orientation[0] = 1.0f;
    d.orientation[4] = 1.0f;
    d.orientation[8] = 1.0f;
    d.mesh = sc_mesh_default_def();
    d.image_to_probe = sc_xform_identity();
    d.tracker_to_patient = sc_xform_identity();
    return d;
}

/* ---- writer ------------------------------------------------------------------------------ */
static uint64_t def_voxels(const sc_case_def *def)
{
    uint64_t n = 1;
    for (int a = 0; a < 3; a++) {
        if (def->volume.dim[a] == 0u) {
            return 0;
        }
        if (n > UINT64_MAX / 4u / def->volume.dim[a]) {
            return 0;
        }
        n *= def->volume.dim[a];
    }
    return n;
}

static uint64_t payload_sizes(const sc_case_def *def, uint64_t sizes[SC_CASE_SECTION_COUNT])
{
    uint64_t nvox = def_voxels(def);
    sizes[0] = SC_CASE_INFO_SIZE;
    sizes[1] = SC_CASE_GRID_SIZE;
    sizes[2] = nvox;
    sizes[3] = nvox;
    sizes[4] =
        SC_CASE_MATL_HEAD_SIZE + (uint64_t)def->material_count * SC_CASE_MATERIAL_RECORD_SIZE;
    sizes[5] = SC_CASE_MESH_SIZE;
    sizes[6] = SC_CASE_XFRM_SIZE;
    if (nvox == 0u) {
        return 0;
    }
    uint64_t total = SC_CASE_HEADER_SIZE;
    for (unsigned s = 0; s < SC_CASE_SECTION_COUNT; s++) {
        total = align_up(total + SC_CASE_SECTION_HEADER_SIZE + sizes[s]);
    }
    return total;
}

size_t sc_case_encoded_size(const sc_case_def *def)
{
    if (def == NULL) {
        return 0;
    }
    uint64_t sizes[SC_CASE_SECTION_COUNT];
    uint64_t total = payload_sizes(def, sizes);
    if (total > (uint64_t)SIZE_MAX) {
        return 0;
    }
    return (size_t)total;
}

static void write_text(uint8_t *p, size_t n, const char *s)
{
    memset(p, 0, n);
    size_t len = strlen(s);
    memcpy(p, s, len);
}

int sc_case_write(const sc_case_def *def, uint8_t *buf, size_t cap, size_t *out_size)
{
    if (def == NULL || buf == NULL || out_size == NULL || def->name == NULL ||
        def->description == NULL || def->volume.voxels == NULL || def->volume.labels == NULL ||
        def->material_count > SC_MAX_LABELS) {
        return SC_ERR_INVALID_ARG;
    }
    if (strlen(def->name) >= SC_CASE_NAME_LEN ||
        strlen(def->description) >= SC_CASE_DESCRIPTION_LEN) {
        return SC_ERR_CASE_TEXT;
    }
    uint64_t sizes[SC_CASE_SECTION_COUNT];
    uint64_t total = payload_sizes(def, sizes);
    if (total == 0u || total > (uint64_t)SIZE_MAX) {
        return SC_ERR_OVERFLOW;
    }
    if ((uint64_t)cap < total) {
        return SC_ERR_NO_SPACE;
    }
    static const uint32_t tags[SC_CASE_SECTION_COUNT] = {
        SC_CASE_TAG_INFO, SC_CASE_TAG_GRID, SC_CASE_TAG_VOXL, SC_CASE_TAG_LABL,
        SC_CASE_TAG_MATL, SC_CASE_TAG_MESH, SC_CASE_TAG_XFRM};
    memset(buf, 0, (size_t)total);

    memcpy(buf + HDR_MAGIC, SC_CASE_MAGIC, SC_CASE_MAGIC_LEN);
    sc_le_wr_u32(buf + HDR_VERSION, SC_CASE_VERSION);
    sc_le_wr_u32(buf + HDR_HEADER_SIZE, SC_CASE_HEADER_SIZE);
    sc_le_wr_u64(buf + HDR_FILE_SIZE, total);
    sc_le_wr_u32(buf + HDR_SECTION_COUNT, SC_CASE_SECTION_COUNT);
    sc_le_wr_u32(buf + HDR_CRC, sc_crc32(buf, HDR_CRC));

    size_t off = SC_CASE_HEADER_SIZE;
    for (unsigned s = 0; s < SC_CASE_SECTION_COUNT; s++) {
        uint8_t *h = buf + off;
        uint8_t *p = h + SC_CASE_SECTION_HEADER_SIZE;
        size_t n = (size_t)sizes[s];
        switch (s) {
        case 0:
            write_text(p, SC_CASE_NAME_LEN, def->name);
            write_text(p + SC_CASE_NAME_LEN, SC_CASE_DESCRIPTION_LEN, def->description);
            break;
        case 1:
            for (int a = 0; a < 3; a++) {
                sc_le_wr_u32(p + 4 * a, def->volume.dim[a]);
                sc_le_wr_f32(p + 16 + 4 * a, def->volume.spacing_mm[a]);
                sc_le_wr_f32(p + 28 + 4 * a, def->volume.origin_mm[a]);
            }
            for (int i = 0; i < 9; i++) {
                sc_le_wr_f32(p + 40 + 4 * i, def->orientation[i]);
            }
            sc_le_wr_u32(p + 76, def->imaging_flags);
            sc_le_wr_f32(p + 12, def->usable_depth_mm);
            break;
        case 2:
            memcpy(p, def->volume.voxels, n);
            break;
        case 3:
            memcpy(p, def->volume.labels, n);
            break;
        case 4:
            sc_le_wr_u32(p, def->material_count);
            for (uint32_t m = 0; m < def->material_count; m++) {
                uint8_t *r = p + SC_CASE_MATL_HEAD_SIZE + m * SC_CASE_MATERIAL_RECORD_SIZE;
                sc_le_wr_f32(r, def->materials[m].e_pa);
                sc_le_wr_f32(r + 4, def->materials[m].poisson);
                sc_le_wr_f32(r + 8, def->materials[m].density_kg_m3);
            }
            break;
        case 5:
            sc_le_wr_f32(p + 0, def->mesh.origin_mm[0]);
            sc_le_wr_f32(p + 4, def->mesh.origin_mm[1]);
            sc_le_wr_f32(p + 8, def->mesh.origin_mm[2]);
            sc_le_wr_f32(p + 12, def->mesh.size_mm[0]);
            sc_le_wr_f32(p + 16, def->mesh.size_mm[1]);
            sc_le_wr_f32(p + 20, def->mesh.size_mm[2]);
            sc_le_wr_u32(p + 24, def->mesh.nx);
            sc_le_wr_u32(p + 28, def->mesh.ny);
            sc_le_wr_u32(p + 32, def->mesh.nz);
            break;
        default:
            wr_xform(p, &def->image_to_probe);
            wr_xform(p + 48, &def->tracker_to_patient);
            break;
        }
        sc_le_wr_u32(h + SEC_TAG, tags[s]);
        sc_le_wr_u64(h + SEC_SIZE, sizes[s]);
        sc_le_wr_u32(h + SEC_CRC, sc_crc32(p, n));
        sc_le_wr_u32(h + SEC_HCRC, sc_crc32(h, SEC_HCRC));
        off = (size_t)align_up((uint64_t)off + SC_CASE_SECTION_HEADER_SIZE + sizes[s]);
    }
    *out_size = (size_t)total;
    return SC_OK;
}

/* ---- loader ------------------------------------------------------------------------------ */
typedef struct section_ref {
    const uint8_t *p;
    uint64_t size;
} section_ref;

static int tag_index(uint32_t tag)
{
    switch (tag) {
    case SC_CASE_TAG_INFO:
        return 0;
    case SC_CASE_TAG_GRID:
        return 1;
    case SC_CASE_TAG_VOXL:
        return 2;
    case SC_CASE_TAG_LABL:
        return 3;
    case SC_CASE_TAG_MATL:
        return 4;
    case SC_CASE_TAG_MESH:
        return 5;
    case SC_CASE_TAG_XFRM:
        return 6;
    default:
        return -1;
    }
}

/* Walk the sections: framing, CRCs, padding, presence. With chk == NULL every payload CRC is
 * checked here; otherwise only the headers are, and every section's payload and expected CRC
 * is recorded in chk for sc_case_check_step(). */
static int load_sections(const uint8_t *bytes, size_t size, section_ref sec[SC_CASE_SECTION_COUNT],
                         uint32_t *case_id, sc_case_check *chk)
{
    if (size < SC_CASE_MAGIC_LEN) {
        return SC_ERR_CASE_TRUNCATED;
    }
    if (memcmp(bytes, SC_CASE_MAGIC, SC_CASE_MAGIC_LEN) != 0) {
        return SC_ERR_CASE_MAGIC;
    }
    if (size < SC_CASE_HEADER_SIZE) {
        return SC_ERR_CASE_TRUNCATED;
    }
    if (sc_le_rd_u32(bytes + HDR_CRC) != sc_crc32(bytes, HDR_CRC)) {
        return SC_ERR_CASE_CRC;
    }
    if (sc_le_rd_u32(bytes + HDR_VERSION) != SC_CASE_VERSION) {
        return SC_ERR_CASE_VERSION;
    }
    if (sc_le_rd_u32(bytes + HDR_HEADER_SIZE) != SC_CASE_HEADER_SIZE) {
        return SC_ERR_CASE_SECTION;
    }
    if (sc_le_rd_u32(bytes + HDR_FLAGS) != 0u ||
        !all_zero(bytes + HDR_RESERVED, HDR_CRC - HDR_RESERVED)) {
        return SC_ERR_CASE_RESERVED;
    }
    const uint64_t file_size = sc_le_rd_u64(bytes + HDR_FILE_SIZE);
    if (file_size > (uint64_t)size) {
        return SC_ERR_CASE_TRUNCATED;
    }
    if (file_size < (uint64_t)size || (file_size % SC_CASE_ALIGN) != 0u) {
        return SC_ERR_CASE_SIZE; /* trailing bytes after the last section, or odd size */
    }
    const uint32_t count = sc_le_rd_u32(bytes + HDR_SECTION_COUNT);
    if (count < SC_CASE_SECTION_COUNT || count > SC_CASE_MAX_SECTIONS) {
        return SC_ERR_CASE_SECTION;
    }
    if (chk != NULL) {
        chk->sec_count = count;
    }
    for (unsigned s = 0; s < SC_CASE_SECTION_COUNT; s++) {
        sec[s].p = NULL;
        sec[s].size = 0;
    }
    /* the id hashes the headers without their own CRC fields: a CRC run over data followed by
     * its CRC ends in a constant residue, which would make every id equal */
    uint32_t id = sc_crc32_update(SC_CRC32_INIT, bytes, HDR_CRC);
    uint64_t off = SC_CASE_HEADER_SIZE;
    for (uint32_t i = 0; i < count; i++) {
        if (file_size - off < SC_CASE_SECTION_HEADER_SIZE) {
            return SC_ERR_CASE_TRUNCATED;
        }
        const uint8_t *h = bytes + off;
        if (sc_le_rd_u32(h + SEC_HCRC) != sc_crc32(h, SEC_HCRC)) {
            return SC_ERR_CASE_CRC;
        }
        id = sc_crc32_update(id, h, SEC_HCRC);
        if (sc_le_rd_u32(h + SEC_FLAGS) != 0u ||
            !all_zero(h + SEC_RESERVED, SEC_HCRC - SEC_RESERVED)) {
            return SC_ERR_CASE_RESERVED;
        }
        const uint64_t psize = sc_le_rd_u64(h + SEC_SIZE);
        const uint64_t avail = file_size - off - SC_CASE_SECTION_HEADER_SIZE;
        if (psize > avail) {
            return SC_ERR_CASE_TRUNCATED;
        }
        const uint8_t *p = h + SC_CASE_SECTION_HEADER_SIZE;
        if (chk != NULL) {
            chk->sec_off[i] = off + SC_CASE_SECTION_HEADER_SIZE;
            chk->sec_size[i] = psize;
            chk->sec_crc[i] = sc_le_rd_u32(h + SEC_CRC);
        } else if (sc_le_rd_u32(h + SEC_CRC) != sc_crc32(p, (size_t)psize)) {
            return SC_ERR_CASE_CRC;
        }
        /* padding up to the next 64-byte boundary: present and zero */
        uint64_t end = off + SC_CASE_SECTION_HEADER_SIZE + psize;
        uint64_t next = align_up(end);
        if (next > file_size) {
            return SC_ERR_CASE_TRUNCATED;
        }
        if (!all_zero(bytes + end, (size_t)(next - end))) {
            return SC_ERR_CASE_RESERVED;
        }
        int idx = tag_index(sc_le_rd_u32(h + SEC_TAG));
        if (idx >= 0) {
            if (sec[idx].p != NULL) {
                return SC_ERR_CASE_SECTION; /* duplicated */
            }
            sec[idx].p = p;
            sec[idx].size = psize;
        } /* unknown tags: CRC-checked and skipped (forward compatible additions) */
        off = next;
    }
    if (off != file_size) {
        return SC_ERR_CASE_SIZE; /* bytes after the declared sections */
    }
    for (unsigned s = 0; s < SC_CASE_SECTION_COUNT; s++) {
        if (sec[s].p == NULL) {
            return SC_ERR_CASE_SECTION; /* missing */
        }
    }
    *case_id = sc_crc32_final(id);
    return SC_OK;
}

static int material_ok(const sc_case_material *m)
{
    return isfinite(m->e_pa) && m->e_pa >= SC_CASE_MIN_E_PA && m->e_pa <= SC_CASE_MAX_E_PA &&
           isfinite(m->poisson) && m->poisson >= 0.0f && m->poisson < 0.5f &&
           isfinite(m->density_kg_m3) && m->density_kg_m3 >= SC_CASE_MIN_DENSITY &&
           m->density_kg_m3 <= SC_CASE_MAX_DENSITY;
}

/* every coordinate of v within the plausible extent */
static int within_extent(const float v[3])
{
    for (int a = 0; a < 3; a++) {
        if (!(fabsf(v[a]) <= SC_CASE_MAX_EXTENT_MM)) {
            return 0;
        }
    }
    return 1;
}

static uint8_t label_max(const uint8_t *lab, uint64_t n)
{
    /* one pass, max reduction (branch-free inner loop) */
    uint8_t maxl = 0;
    for (uint64_t i = 0; i < n; i++) {
        maxl = lab[i] > maxl ? lab[i] : maxl;
    }
    return maxl;
}

/* The semantic checks over framed sections whose payload CRCs are verified. max_label < 0:
 * the label pass runs here (O(voxels)); else it was done by the caller. */
static int parse_case(const section_ref sec[SC_CASE_SECTION_COUNT], uint32_t case_id,
                      int max_label, sc_case *out)
{
    int rc;
    sc_case c;
    memset(&c, 0, sizeof c);

    /* INFO */
    if (sec[0].size != SC_CASE_INFO_SIZE) {
        return SC_ERR_CASE_SIZE;
    }
    if (!text_ok(sec[0].p, SC_CASE_NAME_LEN, 0) ||
        !text_ok(sec[0].p + SC_CASE_NAME_LEN, SC_CASE_DESCRIPTION_LEN, 1)) {
        return SC_ERR_CASE_TEXT;
    }
    c.name = (const char *)sec[0].p;
    c.description = (const char *)(sec[0].p + SC_CASE_NAME_LEN);

    /* GRID */
    const uint8_t *g = sec[1].p;
    if (sec[1].size != SC_CASE_GRID_SIZE) {
        return SC_ERR_CASE_SIZE;
    }
    if ((sc_le_rd_u32(g + 76) & ~SC_CASE_IMAGING_KNOWN) != 0u) {
        return SC_ERR_CASE_RESERVED;
    }
    c.imaging_flags = sc_le_rd_u32(g + 76);
    c.usable_depth_mm = sc_le_rd_f32(g + 12); /* formerly reserved zero: 0 = not stated */
    if (!isfinite(c.usable_depth_mm) || c.usable_depth_mm < 0.0f ||
        (c.usable_depth_mm > 0.0f && !(c.usable_depth_mm >= SC_CASE_MIN_DEPTH_MM &&
                                       c.usable_depth_mm <= SC_CASE_MAX_DEPTH_MM))) {
        return SC_ERR_CASE_DEPTH;
    }
    for (int a = 0; a < 3; a++) {
        c.volume.dim[a] = sc_le_rd_u32(g + 4 * a);
        c.volume.spacing_mm[a] = sc_le_rd_f32(g + 16 + 4 * a);
        c.volume.origin_mm[a] = sc_le_rd_f32(g + 28 + 4 * a);
    }
    for (int i = 0; i < 9; i++) {
        c.orientation[i] = sc_le_rd_f32(g + 40 + 4 * i);
    }
    rc = dims_voxels(c.volume.dim, &c.voxel_count);
    if (rc != SC_OK) {
        return rc;
    }
    for (int a = 0; a < 3; a++) {
        if (!isfinite(c.volume.spacing_mm[a]) || !(c.volume.spacing_mm[a] > 0.0f) ||
            c.volume.spacing_mm[a] > SC_CASE_MAX_SPACING_MM) {
            return SC_ERR_CASE_SPACING;
        }
    }
    if (!finite3(c.volume.origin_mm) || !within_extent(c.volume.origin_mm)) {
        return SC_ERR_CASE_TRANSFORM;
    }
    {
        float far_corner[3];
        for (int a = 0; a < 3; a++) {
            far_corner[a] = c.volume.origin_mm[a] +
                            c.volume.spacing_mm[a] * (float)(c.volume.dim[a] - 1u);
        }
        if (!within_extent(far_corner)) {
            return SC_ERR_CASE_TRANSFORM;
        }
    }
    sc_xform orient = sc_xform_identity();
    memcpy(orient.r, c.orientation, sizeof orient.r);
    if (!sc_xform_is_rigid(&orient, SC_CASE_RIGID_TOL)) {
        return SC_ERR_CASE_TRANSFORM;
    }

    /* VOXL, LABL */
    if (sec[2].size != c.voxel_count || sec[3].size != c.voxel_count) {
        return SC_ERR_CASE_SIZE;
    }
    c.volume.voxels = sec[2].p;
    c.volume.labels = sec[3].p;

    /* MATL */
    const uint8_t *mt = sec[4].p;
    if (sec[4].size < SC_CASE_MATL_HEAD_SIZE) {
        return SC_ERR_CASE_SIZE;
    }
    c.material_count = sc_le_rd_u32(mt);
    if (sc_le_rd_u32(mt + 4) != 0u) {
        return SC_ERR_CASE_RESERVED;
    }
    if (c.material_count == 0u || c.material_count > SC_MAX_LABELS) {
        return SC_ERR_CASE_MATERIAL;
    }
    if (sec[4].size !=
        SC_CASE_MATL_HEAD_SIZE + (uint64_t)c.material_count * SC_CASE_MATERIAL_RECORD_SIZE) {
        return SC_ERR_CASE_SIZE;
    }
    for (uint32_t m = 0; m < c.material_count; m++) {
        const uint8_t *r = mt + SC_CASE_MATL_HEAD_SIZE + m * SC_CASE_MATERIAL_RECORD_SIZE;
        c.materials[m].e_pa = sc_le_rd_f32(r);
        c.materials[m].poisson = sc_le_rd_f32(r + 4);
        c.materials[m].density_kg_m3 = sc_le_rd_f32(r + 8);
        if (sc_le_rd_u32(r + 12) != 0u) {
            return SC_ERR_CASE_RESERVED;
        }
        if (!material_ok(&c.materials[m])) {
            return SC_ERR_CASE_MATERIAL;
        }
    }
    /* every label inside the table */
    {
        const uint32_t maxl = max_label >= 0 ? (uint32_t)max_label
                                             : label_max(c.volume.labels, c.voxel_count);
        if (maxl >= c.material_count) {
            return SC_ERR_CASE_LABEL;
        }
    }

    /* XFRM */
    if (sec[6].size != SC_CASE_XFRM_SIZE) {
        return SC_ERR_CASE_SIZE;
    }
    rd_xform(sec[6].p, &c.image_to_probe);
    rd_xform(sec[6].p + 48, &c.tracker_to_patient);
    if (!sc_xform_is_rigid(&c.image_to_probe, SC_CASE_RIGID_TOL) ||
        !sc_xform_is_rigid(&c.tracker_to_patient, SC_CASE_RIGID_TOL) ||
        !within_extent(c.image_to_probe.t_mm) || !within_extent(c.tracker_to_patient.t_mm)) {
        return SC_ERR_CASE_TRANSFORM;
    }
    /* patient p = O v  =>  v = O^T p: fold the orientation into the registration */
    sc_xform orient_inv = sc_xform_inverse(&orient);
    c.tracker_to_volume = sc_xform_compose(&orient_inv, &c.tracker_to_patient);

    /* MESH */
    const uint8_t *mp = sec[5].p;
    if (sec[5].size != SC_CASE_MESH_SIZE) {
        return SC_ERR_CASE_SIZE;
    }
    if (sc_le_rd_u32(mp + 36) != 0u) {
        return SC_ERR_CASE_RESERVED;
    }
    for (int a = 0; a < 3; a++) {
        c.mesh.origin_mm[a] = sc_le_rd_f32(mp + 4 * a);
        c.mesh.size_mm[a] = sc_le_rd_f32(mp + 12 + 4 * a);
    }
    c.mesh.nx = sc_le_rd_u32(mp + 24);
    c.mesh.ny = sc_le_rd_u32(mp + 28);
    c.mesh.nz = sc_le_rd_u32(mp + 32);
    if (c.mesh.nx < 2u || c.mesh.nx > SC_MAX_MESH_NX || c.mesh.ny < 2u ||
        c.mesh.ny > SC_MAX_MESH_NY || c.mesh.nz < 2u || c.mesh.nz > SC_MAX_MESH_NZ) {
        return SC_ERR_CASE_MESH_NODES;
    }
    for (int a = 0; a < 3; a++) {
        const float lo = c.volume.origin_mm[a];
        const float extent = c.volume.spacing_mm[a] * (float)(c.volume.dim[a] - 1u);
        const float hi = lo + extent;
        /* float round-off of the builder's box arithmetic: 1e-4 of the extent, >= 1 um */
        const float tol = fmaxf(1.0e-3f, 1.0e-4f * extent);
        const float b0 = c.mesh.origin_mm[a];
        const float b1 = b0 + c.mesh.size_mm[a];
        if (!isfinite(b0) || !isfinite(c.mesh.size_mm[a]) || !(c.mesh.size_mm[a] > 0.0f) ||
            !isfinite(b1) || b0 < lo - tol || b1 > hi + tol) {
            return SC_ERR_CASE_MESH_BOX;
        }
    }

    c.case_id = case_id;
    *out = c;
    return SC_OK;
}

int sc_case_load(const uint8_t *bytes, size_t size, sc_case *out)
{
    if (bytes == NULL || out == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    section_ref sec[SC_CASE_SECTION_COUNT];
    uint32_t case_id = 0;
    const int rc = load_sections(bytes, size, sec, &case_id, NULL);
    if (rc != SC_OK) {
        return rc;
    }
    sc_case c;
    const int prc = parse_case(sec, case_id, -1, &c);
    if (prc != SC_OK) {
        return prc;
    }
    const int src = sc_case_surf_find(bytes, size, &c.mesh, &c.surf);
    if (src != SC_OK) {
        return src;
    }
    const int drc = sc_case_drive_find(bytes, size, &c.drive);
    if (drc != SC_OK) {
        return drc;
    }
    *out = c;
    return SC_OK;
}

/* ---- the same validation in slices ------------------------------------------------------- */

int sc_case_check_begin(sc_case_check *k, const uint8_t *bytes, size_t size)
{
    if (k == NULL || bytes == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    memset(k, 0, sizeof *k);
    k->bytes = bytes;
    k->size = size;
    section_ref sec[SC_CASE_SECTION_COUNT];
    const int rc = load_sections(bytes, size, sec, &k->case_id, k);
    if (rc != SC_OK) {
        k->state = rc;
        return rc;
    }
    for (unsigned s = 0; s < SC_CASE_SECTION_COUNT; s++) {
        k->known_p[s] = sec[s].p;
        k->known_size[s] = sec[s].size;
    }
    k->labels = sec[3].p;
    k->label_count = sec[3].size;
    k->crc = SC_CRC32_INIT;
    return SC_OK;
}

int sc_case_check_step(sc_case_check *k, size_t budget_bytes)
{
    if (k == NULL || k->bytes == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (k->state != 0) {
        return k->state; /* finished (1) or failed (< 0): sticky */
    }
    size_t left = budget_bytes > 0u ? budget_bytes : 1u;
    /* payload CRCs, section by section */
    while (k->sec_index < k->sec_count && left > 0u) {
        const uint64_t n_sec = k->sec_size[k->sec_index];
        const uint64_t todo = n_sec - k->sec_done;
        const size_t n = todo < (uint64_t)left ? (size_t)todo : left;
        k->crc = sc_crc32_update(k->crc, k->bytes + k->sec_off[k->sec_index] + k->sec_done, n);
        k->sec_done += n;
        k->bytes_done += n;
        left -= n;
        if (k->sec_done == n_sec) {
            if (sc_crc32_final(k->crc) != k->sec_crc[k->sec_index]) {
                k->state = SC_ERR_CASE_CRC;
                return k->state;
            }
            k->sec_index++;
            k->sec_done = 0u;
            k->crc = SC_CRC32_INIT;
        }
    }
    /* then the label pass */
    while (k->sec_index == k->sec_count && k->label_done < k->label_count && left > 0u) {
        const uint64_t todo = k->label_count - k->label_done;
        const size_t n = todo < (uint64_t)left ? (size_t)todo : left;
        const uint8_t m = label_max(k->labels + k->label_done, n);
        k->label_max = m > k->label_max ? m : k->label_max;
        k->label_done += n;
        k->bytes_done += n;
        left -= n;
    }
    if (k->sec_index == k->sec_count && k->label_done == k->label_count) {
        k->state = 1;
    }
    return k->state;
}

int sc_case_check_finish(const sc_case_check *k, sc_case *out)
{
    if (k == NULL || out == NULL || k->bytes == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (k->state < 0) {
        return k->state;
    }
    if (k->state != 1) {
        return SC_ERR_STATE;
    }
    section_ref sec[SC_CASE_SECTION_COUNT];
    for (unsigned s = 0; s < SC_CASE_SECTION_COUNT; s++) {
        sec[s].p = k->known_p[s];
        sec[s].size = k->known_size[s];
    }
    sc_case c;
    const int prc = parse_case(sec, k->case_id, (int)k->label_max, &c);
    if (prc != SC_OK) {
        return prc;
    }
    const int src = sc_case_surf_find(k->bytes, k->size, &c.mesh, &c.surf);
    if (src != SC_OK) {
        return src;
    }
    const int drc = sc_case_drive_find(k->bytes, k->size, &c.drive);
    if (drc != SC_OK) {
        return drc;
    }
    *out = c;
    return SC_OK;
}

void sc_case_label_histogram(const sc_case *c, uint64_t counts[SC_MAX_LABELS])
{
    for (uint32_t l = 0; l < SC_MAX_LABELS; l++) {
        counts[l] = 0;
    }
    for (uint64_t i = 0; i < c->voxel_count; i++) {
        counts[c->volume.labels[i] % SC_MAX_LABELS]++;
    }
}

void sc_case_slot_init(sc_case_slot *s)
{
    memset(s, 0, sizeof *s);
}

int sc_case_slot_switch(sc_case_slot *s, const sc_storage_dev *dev, const char *name)
{
    if (s == NULL || dev == NULL || dev->ops == NULL || name == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const uint8_t *data = NULL;
    size_t size = 0;
    int rc = sc_storage_open(dev, name, &data, &size);
    if (rc == SC_OK) {
        sc_case c;
        rc = sc_case_load(data, size, &c);
        if (rc == SC_OK) {
            if (s->dev != NULL) {
                sc_storage_close(s->dev, s->data, s->size);
            }
            s->dev = dev;
            s->data = data;
            s->size = size;
            s->c = c;
            s->loaded = 1;
        } else {
            sc_storage_close(dev, data, size);
        }
    }
    s->last_error = rc;
    if (rc != SC_OK) {
        s->refused++;
    }
    return rc;
}

void sc_case_slot_close(sc_case_slot *s)
{
    if (s != NULL && s->dev != NULL) {
        sc_storage_close(s->dev, s->data, s->size);
    }
    if (s != NULL) {
        s->dev = NULL;
        s->data = NULL;
        s->size = 0;
        s->loaded = 0;
    }
}
