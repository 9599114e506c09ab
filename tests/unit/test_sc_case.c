/* test_sc_case.c: case file v1: writer/loader round trip, orientation folding, and every kind
 * of corruption refused with its named error while the running case stays. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_case.h"
#include "sc_crc32.h"
#include "sc_err.h"
#include "sc_labels.h"

#define NX   16u
#define NY   12u
#define NZ   10u
#define NVOX (NX * NY * NZ)

static uint8_t g_vox[NVOX];
static uint8_t g_lab[NVOX];
static uint8_t g_buf[64u * 1024u];
static uint8_t g_bad[64u * 1024u];

static sc_case_def make_def(void)
{
    for (uint32_t i = 0; i < NVOX; i++) {
        g_vox[i] = (uint8_t)((i * 2654435761u) >> 24);
        g_lab[i] = (uint8_t)(i % SC_LABEL_COUNT);
    }
    sc_case_def d = sc_case_default_def();
    d.name = "unit-case";
    d.description = "test volume\nsecond line";
    d.volume.dim[0] = NX;
    d.volume.dim[1] = NY;
    d.volume.dim[2] = NZ;
    d.volume.spacing_mm[0] = 0.5f;
    d.volume.spacing_mm[1] = 0.25f;
    d.volume.spacing_mm[2] = 1.0f;
    d.volume.origin_mm[0] = -4.0f;
    d.volume.origin_mm[1] = 1.0f;
    d.volume.origin_mm[2] = 0.0f;
    d.volume.voxels = g_vox;
    d.volume.labels = g_lab;
    d.material_count = SC_LABEL_COUNT;
    for (uint32_t m = 0; m < SC_LABEL_COUNT; m++) {
        d.materials[m].e_pa = 1000.0f * (float)(m + 1u);
        d.materials[m].poisson = 0.45f;
        d.materials[m].density_kg_m3 = 1000.0f + (float)m;
    }
    d.mesh.nx = 8;
    d.mesh.ny = 4;
    d.mesh.nz = 5;
    d.mesh.origin_mm[0] = -3.0f;
    d.mesh.origin_mm[1] = 1.0f;
    d.mesh.origin_mm[2] = 0.0f;
    d.mesh.size_mm[0] = 4.0f;
    d.mesh.size_mm[1] = 2.75f; /* exactly the y extent: 11 * 0.25 */
    d.mesh.size_mm[2] = 9.0f;
    /* a probe calibration: 90 degrees about z, offset */
    d.image_to_probe = sc_xform_identity();
    d.image_to_probe.r[0] = 0.0f;
    d.image_to_probe.r[1] = -1.0f;
    d.image_to_probe.r[3] = 1.0f;
    d.image_to_probe.r[4] = 0.0f;
    d.image_to_probe.t_mm[2] = 2.5f;
    d.tracker_to_patient = sc_xform_identity();
    d.tracker_to_patient.t_mm[0] = 10.0f;
    d.tracker_to_patient.t_mm[1] = -20.0f;
    d.tracker_to_patient.t_mm[2] = 30.0f;
    return d;
}

static size_t write_def(const sc_case_def *d, uint8_t *buf)
{
    size_t n = 0;
    assert_int_equal(sc_case_write(d, buf, sizeof g_buf, &n), SC_OK);
    assert_int_equal(n, sc_case_encoded_size(d));
    return n;
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* Offset of the payload of the section with this tag (walks the file). */
static size_t payload_of(const uint8_t *b, uint32_t tag)
{
    size_t off = SC_CASE_HEADER_SIZE;
    uint32_t count = le32(b + 24);
    for (uint32_t i = 0; i < count; i++) {
        size_t psize = (size_t)le32(b + off + 8);
        if (le32(b + off) == tag) {
            return off + SC_CASE_SECTION_HEADER_SIZE;
        }
        off = (off + SC_CASE_SECTION_HEADER_SIZE + psize + 63u) & ~(size_t)63u;
    }
    fail_msg("section not found");
    return 0;
}

/* Recompute every CRC after a deliberate edit, so that the semantic check is what fails. */
static void reseal(uint8_t *b)
{
    put32(b + 60, sc_crc32(b, 60));
    size_t off = SC_CASE_HEADER_SIZE;
    uint32_t count = le32(b + 24);
    for (uint32_t i = 0; i < count; i++) {
        size_t psize = (size_t)le32(b + off + 8);
        put32(b + off + 16, sc_crc32(b + off + SC_CASE_SECTION_HEADER_SIZE, psize));
        put32(b + off + 60, sc_crc32(b + off, 60));
        off = (off + SC_CASE_SECTION_HEADER_SIZE + psize + 63u) & ~(size_t)63u;
    }
}

static void xform_equal(const sc_xform *a, const sc_xform *b)
{
    assert_memory_equal(a, b, sizeof *a);
}

static void round_trip_gives_identical_voxels_labels_transforms_and_text(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    assert_int_equal(n % SC_CASE_ALIGN, 0);
    sc_case c;
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
    assert_string_equal(c.name, "unit-case");
    assert_string_equal(c.description, "test volume\nsecond line");
    assert_memory_equal(c.volume.dim, d.volume.dim, sizeof d.volume.dim);
    assert_memory_equal(c.volume.spacing_mm, d.volume.spacing_mm, sizeof d.volume.spacing_mm);
    assert_memory_equal(c.volume.origin_mm, d.volume.origin_mm, sizeof d.volume.origin_mm);
    assert_int_equal(c.voxel_count, NVOX);
    assert_memory_equal(c.volume.voxels, g_vox, NVOX);
    assert_memory_equal(c.volume.labels, g_lab, NVOX);
    /* the view points into the bytes, it does not copy them */
    assert_true(c.volume.voxels > g_buf && c.volume.voxels < g_buf + n);
    assert_int_equal(((uintptr_t)(c.volume.voxels - g_buf)) % SC_CASE_ALIGN, 0);
    assert_int_equal(c.material_count, SC_LABEL_COUNT);
    assert_memory_equal(c.materials, d.materials, SC_LABEL_COUNT * sizeof d.materials[0]);
    assert_memory_equal(&c.mesh, &d.mesh, sizeof d.mesh);
    xform_equal(&c.image_to_probe, &d.image_to_probe);
    xform_equal(&c.tracker_to_patient, &d.tracker_to_patient);
    /* identity orientation: registration unchanged */
    xform_equal(&c.tracker_to_volume, &d.tracker_to_patient);
    /* the writer is deterministic: same def, same bytes, same id */
    size_t n2 = write_def(&d, g_bad);
    assert_int_equal(n2, n);
    assert_memory_equal(g_bad, g_buf, n);
    sc_case c2;
    assert_int_equal(sc_case_load(g_bad, n2, &c2), SC_OK);
    assert_int_equal(c2.case_id, c.case_id);
    /* one voxel more or less changes the id */
    g_vox[NVOX / 2u] ^= 1u;
    n2 = write_def(&d, g_bad);
    assert_int_equal(sc_case_load(g_bad, n2, &c2), SC_OK);
    assert_int_not_equal(c2.case_id, c.case_id);
    g_vox[NVOX / 2u] ^= 1u;
    uint64_t h[SC_MAX_LABELS];
    sc_case_label_histogram(&c, h);
    uint64_t sum = 0;
    for (uint32_t l = 0; l < SC_MAX_LABELS; l++) {
        sum += h[l];
    }
    assert_int_equal(sum, NVOX);
    assert_int_equal(h[SC_LABEL_VEIN],
                     (NVOX + SC_LABEL_COUNT - 1u - SC_LABEL_VEIN) / SC_LABEL_COUNT);
}

static void orientation_is_folded_into_the_registration(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    /* grid x axis along patient y, grid y along patient -x (90 degrees about z) */
    const float o[9] = {0.0f, -1.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f};
    memcpy(d.orientation, o, sizeof o);
    size_t n = write_def(&d, g_buf);
    sc_case c;
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
    assert_memory_equal(c.orientation, o, sizeof o);
    /* a tracker point maps to patient p, and the volume frame must give O v = p */
    const float pt[3] = {1.0f, 2.0f, 3.0f};
    float p[3], v[3];
    sc_xform_apply(&c.tracker_to_patient, pt, p);
    sc_xform_apply(&c.tracker_to_volume, pt, v);
    for (int r = 0; r < 3; r++) {
        float ov = o[r * 3 + 0] * v[0] + o[r * 3 + 1] * v[1] + o[r * 3 + 2] * v[2];
        assert_true(fabsf(ov - p[r]) < 1e-5f); /* exact rotation by 0/1 entries */
    }
}

static void truncation_at_every_length_including_section_boundaries_is_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    sc_case c;
    size_t boundaries = 0;
    for (size_t len = 0; len < n; len++) {
        assert_int_equal(sc_case_load(g_buf, len, &c), SC_ERR_CASE_TRUNCATED);
        boundaries += (len % SC_CASE_ALIGN) == 0u;
    }
    /* header + 7 section headers at least were among the cut points */
    assert_true(boundaries >= 8u);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
}

static int in_padding(const uint8_t *b, size_t n, size_t pos)
{
    size_t off = SC_CASE_HEADER_SIZE;
    while (off < n) {
        size_t end = off + SC_CASE_SECTION_HEADER_SIZE + (size_t)le32(b + off + 8);
        size_t next = (end + 63u) & ~(size_t)63u;
        if (pos >= end && pos < next) {
            return 1;
        }
        off = next;
    }
    return 0;
}

static void flipped_bit_anywhere_is_refused_by_crc_magic_or_padding_check(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    sc_case c;
    unsigned crc_hits = 0;
    for (size_t pos = 0; pos < n; pos++) {
        memcpy(g_bad, g_buf, n);
        g_bad[pos] ^= (uint8_t)(1u << (pos % 8u));
        int rc = sc_case_load(g_bad, n, &c);
        if (pos < SC_CASE_MAGIC_LEN) {
            assert_int_equal(rc, SC_ERR_CASE_MAGIC);
        } else if (in_padding(g_buf, n, pos)) {
            assert_int_equal(rc, SC_ERR_CASE_RESERVED);
        } else {
            if (rc != SC_ERR_CASE_CRC) {
                fail_msg("byte %zu: %s", pos, sc_err_name(rc));
            }
            crc_hits++;
        }
    }
    /* every payload byte and every header byte outside the magic was covered */
    assert_true(crc_hits >= 2u * NVOX + SC_CASE_INFO_SIZE);
}

static int load_patched_u32(size_t off, uint32_t v, size_t n)
{
    memcpy(g_bad, g_buf, n);
    put32(g_bad + off, v);
    reseal(g_bad);
    sc_case c;
    return sc_case_load(g_bad, n, &c);
}

static void dimensions_above_limits_or_overflowing_are_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    size_t grid = payload_of(g_buf, SC_CASE_TAG_GRID);
    const uint32_t bad[][3] = {
        {0u, NY, NZ},
        {NX, NY, 0u},
        {SC_MAX_VOLUME_DIM + 1u, 1u, 1u},
        {0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu}, /* product wraps 64-bit too */
        {65537u, 65536u, 1u},                    /* 32-bit product wraps to 65536 */
        {SC_MAX_VOLUME_DIM, SC_MAX_VOLUME_DIM, SC_MAX_VOLUME_DIM}, /* > SC_MAX_VOLUME_VOXELS */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        memcpy(g_bad, g_buf, n);
        for (int a = 0; a < 3; a++) {
            put32(g_bad + grid + 4u * (size_t)a, bad[i][a]);
        }
        reseal(g_bad);
        sc_case c;
        assert_int_equal(sc_case_load(g_bad, n, &c), SC_ERR_CASE_DIMS);
    }
    /* dims within limits but disagreeing with the voxel payload */
    assert_int_equal(load_patched_u32(grid, NX + 1u, n), SC_ERR_CASE_SIZE);
}

static void non_finite_or_non_positive_spacing_is_refused(void **state)
{
    (void)state;
    const float bad[] = {NAN, INFINITY, -INFINITY, 0.0f, -0.5f};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        for (int a = 0; a < 3; a++) {
            sc_case_def d = make_def();
            d.volume.spacing_mm[a] = bad[i];
            size_t n = write_def(&d, g_buf);
            sc_case c;
            assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_SPACING);
        }
    }
}

static void labels_outside_the_material_table_are_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    g_lab[NVOX - 1u] = (uint8_t)SC_LABEL_COUNT; /* one past the table, in the last voxel */
    size_t n = write_def(&d, g_buf);
    sc_case c;
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_LABEL);
    d = make_def();
    g_lab[0] = 255u;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_LABEL);
    /* a shorter table makes the existing labels invalid */
    d = make_def();
    d.material_count = SC_LABEL_BONE; /* label 8 present */
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_LABEL);
}

/* The sliced validation, run to the end with a budget per step; the steps it took in *steps. */
static int check_sliced(const uint8_t *b, size_t n, size_t budget, sc_case *out, uint32_t *steps)
{
    sc_case_check k;
    int rc = sc_case_check_begin(&k, b, n);
    *steps = 0;
    while (rc == 0) {
        rc = sc_case_check_step(&k, budget);
        (*steps)++;
    }
    if (rc < 0) {
        assert_int_equal(sc_case_check_step(&k, budget), rc); /* sticky */
        return rc;
    }
    return sc_case_check_finish(&k, out);
}

static void sliced_check_accepts_exactly_what_load_accepts_and_fills_the_same_view(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    const size_t n = write_def(&d, g_buf);
    sc_case whole, sliced;
    assert_int_equal(sc_case_load(g_buf, n, &whole), SC_OK);
    const size_t budgets[] = {1u, 7u, 4096u, 1u << 30};
    for (size_t i = 0; i < sizeof budgets / sizeof budgets[0]; i++) {
        uint32_t steps = 0;
        memset(&sliced, 0xA5, sizeof sliced);
        assert_int_equal(check_sliced(g_buf, n, budgets[i], &sliced, &steps), SC_OK);
        assert_memory_equal(&sliced, &whole, sizeof whole);
        /* each step did at most its budget: the payload bytes (and the labels) need this many */
        if (budgets[i] == 7u) {
            assert_true(steps >= (3u * NVOX) / 7u); /* voxels, labels, then the label pass */
        }
    }
    /* finish before the last step is a state error */
    sc_case_check k;
    assert_int_equal(sc_case_check_begin(&k, g_buf, n), SC_OK);
    assert_int_equal(sc_case_check_finish(&k, &sliced), SC_ERR_STATE);
    /* a flipped bit anywhere (every 13th byte) and every truncation: both refuse */
    for (size_t pos = 0; pos < n; pos += 13u) {
        memcpy(g_bad, g_buf, n);
        g_bad[pos] ^= (uint8_t)(1u << (pos % 8u));
        uint32_t steps = 0;
        const int a = sc_case_load(g_bad, n, &whole);
        const int b = check_sliced(g_bad, n, 1000u, &sliced, &steps);
        if (a == SC_OK || b == SC_OK) {
            fail_msg("byte %zu: load %s, sliced %s", pos, sc_err_name(a), sc_err_name(b));
        }
    }
    for (size_t len = 0; len < n; len += 61u) {
        uint32_t steps = 0;
        assert_true(check_sliced(g_buf, len, 1000u, &sliced, &steps) < 0);
    }
    /* a label outside the table, in the last voxel: found by the sliced label pass */
    g_lab[NVOX - 1u] = (uint8_t)SC_LABEL_COUNT;
    const size_t n2 = write_def(&d, g_buf);
    uint32_t steps = 0;
    assert_int_equal(check_sliced(g_buf, n2, 333u, &sliced, &steps), SC_ERR_CASE_LABEL);
}

static void physically_absurd_values_are_refused_by_name(void **state)
{
    (void)state;
    sc_case c;
    sc_case_def d = make_def();
    d.materials[SC_LABEL_VEIN].e_pa = 3e38f;
    size_t n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_MATERIAL);
    d = make_def();
    d.materials[SC_LABEL_FAT].density_kg_m3 = 1e9f;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_MATERIAL);
    d = make_def();
    d.volume.spacing_mm[1] = 1e30f;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_SPACING);
    d = make_def();
    d.tracker_to_patient.t_mm[2] = 3e38f;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_TRANSFORM);
    d = make_def();
    d.image_to_probe.t_mm[0] = -6000.0f;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_TRANSFORM);
    d = make_def();
    d.volume.origin_mm[0] = 4999.0f; /* the far corner is beyond 5 m */
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_TRANSFORM);
    /* the limits themselves pass */
    d = make_def();
    d.materials[SC_LABEL_BONE].e_pa = SC_CASE_MAX_E_PA;
    d.materials[SC_LABEL_VEIN].e_pa = SC_CASE_MIN_E_PA;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
}

static void invalid_materials_are_refused(void **state)
{
    (void)state;
    sc_case c;
    sc_case_def d = make_def();
    d.material_count = 0;
    size_t n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_MATERIAL);
    const sc_case_material bad[] = {
        {0.0f, 0.45f, 1000.0f}, {-5.0f, 0.45f, 1000.0f}, {NAN, 0.45f, 1000.0f},
        {1e4f, 0.5f, 1000.0f},  {1e4f, -0.1f, 1000.0f},  {1e4f, 0.3f, 0.0f},
        {1e4f, 0.3f, INFINITY},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        d = make_def();
        d.materials[3] = bad[i];
        n = write_def(&d, g_buf);
        assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_MATERIAL);
    }
    /* count above the limit (patched: the writer refuses it) */
    d = make_def();
    n = write_def(&d, g_buf);
    assert_int_equal(load_patched_u32(payload_of(g_buf, SC_CASE_TAG_MATL), SC_MAX_LABELS + 1u, n),
                     SC_ERR_CASE_MATERIAL);
}

static void mesh_box_outside_the_volume_is_refused(void **state)
{
    (void)state;
    /* volume x covers [-4, 3.5], y [1, 3.75], z [0, 9] */
    const float bad[][6] = {
        {-4.5f, 1.0f, 0.0f, 2.0f, 1.0f, 1.0f}, /* starts left of the volume */
        {0.0f, 1.0f, 0.0f, 3.6f, 1.0f, 1.0f},  /* ends right of it */
        {0.0f, 1.0f, 0.0f, 1.0f, 2.8f, 1.0f},  /* past the end in y */
        {0.0f, 1.0f, -0.1f, 1.0f, 1.0f, 1.0f}, /* above the top in z */
        {0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 9.5f},  /* below the bottom */
        {0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f},  /* empty */
        {0.0f, 1.0f, 0.0f, -1.0f, 1.0f, 1.0f}, /* negative size */
        {NAN, 1.0f, 0.0f, 1.0f, 1.0f, 1.0f},   {0.0f, 1.0f, 0.0f, 1.0f, INFINITY, 1.0f},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sc_case_def d = make_def();
        memcpy(d.mesh.origin_mm, &bad[i][0], 3 * sizeof(float));
        memcpy(d.mesh.size_mm, &bad[i][3], 3 * sizeof(float));
        size_t n = write_def(&d, g_buf);
        sc_case c;
        assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_MESH_BOX);
    }
    /* the whole volume is a valid box */
    sc_case_def d = make_def();
    const float whole[6] = {-4.0f, 1.0f, 0.0f, 7.5f, 2.75f, 9.0f};
    memcpy(d.mesh.origin_mm, &whole[0], 3 * sizeof(float));
    memcpy(d.mesh.size_mm, &whole[3], 3 * sizeof(float));
    size_t n = write_def(&d, g_buf);
    sc_case c;
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
}

static void mesh_node_counts_outside_limits_are_refused(void **state)
{
    (void)state;
    const uint32_t bad[][3] = {
        {SC_MAX_MESH_NX + 1u, 4u, 4u},
        {4u, SC_MAX_MESH_NY + 1u, 4u},
        {4u, 4u, SC_MAX_MESH_NZ + 1u},
        {1u, 4u, 4u},
        {4u, 0u, 4u},
        {0xFFFFFFFFu, 4u, 4u},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sc_case_def d = make_def();
        d.mesh.nx = bad[i][0];
        d.mesh.ny = bad[i][1];
        d.mesh.nz = bad[i][2];
        size_t n = write_def(&d, g_buf);
        sc_case c;
        assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_MESH_NODES);
    }
    sc_case_def d = make_def();
    d.mesh.nx = SC_MAX_MESH_NX;
    d.mesh.ny = SC_MAX_MESH_NY;
    d.mesh.nz = SC_MAX_MESH_NZ;
    size_t n = write_def(&d, g_buf);
    sc_case c;
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
}

static void non_finite_or_non_rigid_transforms_are_refused(void **state)
{
    (void)state;
    sc_case c;
    for (int which = 0; which < 2; which++) {
        for (int kind = 0; kind < 4; kind++) {
            sc_case_def d = make_def();
            sc_xform *x = which == 0 ? &d.image_to_probe : &d.tracker_to_patient;
            if (kind == 0) {
                x->t_mm[1] = NAN;
            } else if (kind == 1) {
                *x = sc_xform_identity();
                x->r[4] = 1.01f; /* scaled: not rigid */
            } else if (kind == 2) {
                *x = sc_xform_identity();
                x->r[8] = -1.0f; /* reflection, det -1 */
            } else {
                x->r[2] = INFINITY;
            }
            size_t n = write_def(&d, g_buf);
            assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_TRANSFORM);
        }
    }
    sc_case_def d = make_def();
    d.orientation[0] = 2.0f;
    size_t n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_TRANSFORM);
    d = make_def();
    d.volume.origin_mm[2] = NAN;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_TRANSFORM);
}

static void imaging_flags_round_trip_and_unknown_bits_are_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    sc_case c;
    size_t n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
    assert_int_equal(c.imaging_flags, 0u); /* the volume holds its acoustics */
    d.imaging_flags = SC_CASE_IMAGING_ENGINE_ACOUSTICS;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
    assert_int_equal(c.imaging_flags, SC_CASE_IMAGING_ENGINE_ACOUSTICS);
    /* a bit no engine knows yet: refused by name */
    const size_t grid = payload_of(g_buf, SC_CASE_TAG_GRID);
    put32(g_buf + grid + 76, SC_CASE_IMAGING_ENGINE_ACOUSTICS | 4u);
    reseal(g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_RESERVED);
}

static void usable_depth_round_trips_zero_means_not_stated_and_bad_values_are_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    sc_case c;
    size_t n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
    assert_true(fabsf(c.usable_depth_mm) < 1e-6f); /* a file of before the field: not stated */
    d.usable_depth_mm = 39.0f;
    n = write_def(&d, g_buf);
    assert_int_equal(sc_case_load(g_buf, n, &c), SC_OK);
    assert_true(fabsf(c.usable_depth_mm - 39.0f) < 1e-6f);
    static const float bad[] = {-1.0f, 4.9f, 500.5f, INFINITY, NAN};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        d.usable_depth_mm = bad[i];
        n = write_def(&d, g_buf);
        assert_int_equal(sc_case_load(g_buf, n, &c), SC_ERR_CASE_DEPTH);
    }
}

static void header_magic_version_and_section_table_errors_are_named(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    sc_case c;
    /* future version with a valid CRC */
    assert_int_equal(load_patched_u32(8, SC_CASE_VERSION + 1u, n), SC_ERR_CASE_VERSION);
    /* header size other than 64 */
    assert_int_equal(load_patched_u32(12, 128u, n), SC_ERR_CASE_SECTION);
    /* non-zero reserved header field */
    assert_int_equal(load_patched_u32(40, 1u, n), SC_ERR_CASE_RESERVED);
    /* section count too small */
    assert_int_equal(load_patched_u32(24, 3u, n), SC_ERR_CASE_SECTION);
    /* a required section renamed: missing (unknown tags are skipped) */
    size_t mesh_hdr = payload_of(g_buf, SC_CASE_TAG_MESH) - SC_CASE_SECTION_HEADER_SIZE;
    assert_int_equal(load_patched_u32(mesh_hdr, SC_CASE_TAG('Z', 'Z', 'Z', 'Z'), n),
                     SC_ERR_CASE_SECTION);
    /* a section tag duplicated */
    assert_int_equal(load_patched_u32(mesh_hdr, SC_CASE_TAG_GRID, n), SC_ERR_CASE_SECTION);
    /* wrong magic */
    memcpy(g_bad, g_buf, n);
    memcpy(g_bad, "PK\x03\x04zzzz", 8);
    assert_int_equal(sc_case_load(g_bad, n, &c), SC_ERR_CASE_MAGIC);
    /* trailing garbage after the last section */
    memcpy(g_bad, g_buf, n);
    memset(g_bad + n, 0, 64);
    assert_int_equal(sc_case_load(g_bad, n + 64u, &c), SC_ERR_CASE_SIZE);
    /* file size field larger than the bytes: truncated */
    memcpy(g_bad, g_buf, n);
    put32(g_bad + 16, (uint32_t)n + 64u);
    reseal(g_bad);
    assert_int_equal(sc_case_load(g_bad, n, &c), SC_ERR_CASE_TRUNCATED);
    assert_int_equal(sc_case_load(NULL, n, &c), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_case_load(g_buf, n, NULL), SC_ERR_INVALID_ARG);
}

static void unterminated_or_control_character_text_is_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    size_t info = payload_of(g_buf, SC_CASE_TAG_INFO);
    sc_case c;
    memcpy(g_bad, g_buf, n);
    memset(g_bad + info, 'A', SC_CASE_NAME_LEN); /* no NUL in the name field */
    reseal(g_bad);
    assert_int_equal(sc_case_load(g_bad, n, &c), SC_ERR_CASE_TEXT);
    memcpy(g_bad, g_buf, n);
    g_bad[info + 2] = 0x1Bu; /* ESC in the name */
    reseal(g_bad);
    assert_int_equal(sc_case_load(g_bad, n, &c), SC_ERR_CASE_TEXT);
    memcpy(g_bad, g_buf, n);
    g_bad[info + SC_CASE_NAME_LEN - 1u] = 'x'; /* bytes after the NUL not zero */
    g_bad[info + SC_CASE_NAME_LEN - 2u] = 0;
    reseal(g_bad);
    assert_int_equal(sc_case_load(g_bad, n, &c), SC_ERR_CASE_TEXT);
    /* the writer refuses text that does not fit */
    char longname[SC_CASE_NAME_LEN + 1u];
    memset(longname, 'n', SC_CASE_NAME_LEN);
    longname[SC_CASE_NAME_LEN] = 0;
    d.name = longname;
    size_t out = 0;
    assert_int_equal(sc_case_write(&d, g_buf, sizeof g_buf, &out), SC_ERR_CASE_TEXT);
}

static void writer_refuses_small_buffers_and_null_volumes(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t need = sc_case_encoded_size(&d);
    size_t out = 0;
    assert_int_equal(sc_case_write(&d, g_buf, need - 1u, &out), SC_ERR_NO_SPACE);
    d.volume.labels = NULL;
    assert_int_equal(sc_case_write(&d, g_buf, sizeof g_buf, &out), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_case_encoded_size(NULL), 0);
}

static void refused_case_leaves_the_running_case_untouched(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    sc_case running;
    assert_int_equal(sc_case_load(g_buf, n, &running), SC_OK);
    sc_case snapshot = running;
    /* a bad case that fails late (after most fields were decoded): mesh box */
    d.mesh.origin_mm[0] = -100.0f;
    size_t nb = write_def(&d, g_bad);
    assert_int_equal(sc_case_load(g_bad, nb, &running), SC_ERR_CASE_MESH_BOX);
    assert_memory_equal(&running, &snapshot, sizeof running);
    assert_int_equal(sc_case_load(g_bad, nb / 2u, &running), SC_ERR_CASE_TRUNCATED);
    assert_memory_equal(&running, &snapshot, sizeof running);
}

/* A fake storage with two named images that counts open mappings. */
typedef struct fake_storage {
    const uint8_t *good, *bad;
    size_t good_size, bad_size;
    int open_maps;
} fake_storage;

static int fake_open(void *ctx, const char *name, const uint8_t **data, size_t *size)
{
    fake_storage *f = (fake_storage *)ctx;
    if (strcmp(name, "good") == 0) {
        *data = f->good;
        *size = f->good_size;
    } else if (strcmp(name, "bad") == 0) {
        *data = f->bad;
        *size = f->bad_size;
    } else {
        return SC_ERR_NOT_FOUND;
    }
    f->open_maps++;
    return SC_OK;
}

static void fake_close(void *ctx, const uint8_t *data, size_t size)
{
    (void)data;
    (void)size;
    ((fake_storage *)ctx)->open_maps--;
}

static void slot_switch_keeps_the_running_case_when_the_new_one_is_refused(void **state)
{
    (void)state;
    sc_case_def d = make_def();
    size_t n = write_def(&d, g_buf);
    memcpy(g_bad, g_buf, n);
    g_bad[n / 2u] ^= 0x40u; /* corrupt a voxel */
    static const sc_storage_ops ops = {fake_open, fake_close};
    fake_storage fs = {g_buf, g_bad, n, n, 0};
    sc_storage_dev dev = {&ops, &fs};
    sc_case_slot slot;
    sc_case_slot_init(&slot);
    assert_int_equal(sc_case_slot_switch(&slot, &dev, "good"), SC_OK);
    assert_true(slot.loaded);
    assert_int_equal(fs.open_maps, 1);
    sc_case before = slot.c;
    assert_int_equal(sc_case_slot_switch(&slot, &dev, "bad"), SC_ERR_CASE_CRC);
    assert_int_equal(sc_case_slot_switch(&slot, &dev, "missing"), SC_ERR_NOT_FOUND);
    assert_int_equal(slot.refused, 2);
    assert_int_equal(slot.last_error, SC_ERR_NOT_FOUND);
    assert_int_equal(fs.open_maps, 1); /* the refused mapping was released */
    assert_memory_equal(&slot.c, &before, sizeof before);
    assert_ptr_equal(slot.data, g_buf);
    /* switching to a good case releases the old mapping */
    assert_int_equal(sc_case_slot_switch(&slot, &dev, "good"), SC_OK);
    assert_int_equal(fs.open_maps, 1);
    sc_case_slot_close(&slot);
    assert_int_equal(fs.open_maps, 0);
    assert_false(slot.loaded);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(round_trip_gives_identical_voxels_labels_transforms_and_text),
        cmocka_unit_test(orientation_is_folded_into_the_registration),
        cmocka_unit_test(truncation_at_every_length_including_section_boundaries_is_refused),
        cmocka_unit_test(flipped_bit_anywhere_is_refused_by_crc_magic_or_padding_check),
        cmocka_unit_test(dimensions_above_limits_or_overflowing_are_refused),
        cmocka_unit_test(non_finite_or_non_positive_spacing_is_refused),
        cmocka_unit_test(labels_outside_the_material_table_are_refused),
        cmocka_unit_test(sliced_check_accepts_exactly_what_load_accepts_and_fills_the_same_view),
        cmocka_unit_test(invalid_materials_are_refused),
        cmocka_unit_test(physically_absurd_values_are_refused_by_name),
        cmocka_unit_test(mesh_box_outside_the_volume_is_refused),
        cmocka_unit_test(mesh_node_counts_outside_limits_are_refused),
        cmocka_unit_test(non_finite_or_non_rigid_transforms_are_refused),
        cmocka_unit_test(imaging_flags_round_trip_and_unknown_bits_are_refused),
        cmocka_unit_test(usable_depth_round_trips_zero_means_not_stated_and_bad_values_are_refused),
        cmocka_unit_test(header_magic_version_and_section_table_errors_are_named),
        cmocka_unit_test(unterminated_or_control_character_text_is_refused),
        cmocka_unit_test(writer_refuses_small_buffers_and_null_volumes),
        cmocka_unit_test(refused_case_leaves_the_running_case_untouched),
        cmocka_unit_test(slot_switch_keeps_the_running_case_when_the_new_one_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
