/* test_casebuild_phantom.c: the phantom cases: vessels present at the stated depths and sizes,
 * clinically plausible, the right tissue in the lumen, ultrasound-like image features, valid
 * case files, deterministic from the seed. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_phantom.h"

/* 0.5 mm voxels keep the test fast; the measurements below tolerate one voxel. */
#define SP 0.5f

typedef struct blob {
    size_t count;
    float cx, cz;       /* centroid, mm */
    float width, depth; /* extent along x and z, mm (voxel count across + 1 voxel) */
} blob;

static size_t vidx(const sc_volume *v, uint32_t i, uint32_t j, uint32_t k)
{
    return i + (size_t)v->dim[0] * (j + (size_t)v->dim[1] * k);
}

/* cross-section y = 0 of the voxels whose label is in mask (bit per label) */
static blob measure(const sc_volume *v, unsigned mask)
{
    const uint32_t j = (uint32_t)lrintf((0.0f - v->origin_mm[1]) / v->spacing_mm[1]);
    blob b = {0};
    double sx = 0.0, sz = 0.0;
    float x0 = 1e9f, x1 = -1e9f, z0 = 1e9f, z1 = -1e9f;
    for (uint32_t k = 0; k < v->dim[2]; k++) {
        for (uint32_t i = 0; i < v->dim[0]; i++) {
            if (mask & (1u << v->labels[vidx(v, i, j, k)])) {
                float x = v->origin_mm[0] + v->spacing_mm[0] * (float)i;
                float z = v->origin_mm[2] + v->spacing_mm[2] * (float)k;
                b.count++;
                sx += x;
                sz += z;
                x0 = fminf(x0, x);
                x1 = fmaxf(x1, x);
                z0 = fminf(z0, z);
                z1 = fmaxf(z1, z);
            }
        }
    }
    if (b.count > 0u) {
        b.cx = (float)(sx / (double)b.count);
        b.cz = (float)(sz / (double)b.count);
        b.width = x1 - x0 + v->spacing_mm[0];
        b.depth = z1 - z0 + v->spacing_mm[2];
    }
    return b;
}

static void generate(sc_phantom_kind kind, uint64_t seed, sc_phantom *p)
{
    sc_phantom_def d = sc_phantom_default_def();
    d.kind = kind;
    d.seed = seed;
    d.spacing_mm = SP;
    assert_int_equal(sc_phantom_generate(&d, p), SC_OK);
}

/* the description states "Vein centre D mm deep ..., W x H mm outer" and the same for the
 * artery: parse it back so that the test checks the case's own text */
static void stated(const char *desc, const char *what, float *depth, float *w, float *h)
{
    const char *p = strstr(desc, what);
    assert_non_null(p);
    float x;
    assert_int_equal(
        sscanf(p + strlen(what), " centre %f mm deep at x %f mm, %f x %f mm", depth, &x, w, h), 4);
}

static void check_vessels_at_stated_geometry(sc_phantom_kind kind)
{
    sc_phantom p;
    generate(kind, 1u, &p);
    const sc_volume *v = &p.def.volume;
    const unsigned vein_mask = (1u << SC_LABEL_VEIN) | (1u << SC_LABEL_THROMBUS);
    const unsigned art_mask = 1u << SC_LABEL_ARTERY;
    blob vein = measure(v, vein_mask), art = measure(v, art_mask);
    assert_true(vein.count > 0u);
    assert_true(art.count > 0u);
    float d, w, h;
    /* one voxel (0.5 mm) of rasterisation on each side: 1 mm on extents, 0.5 on centres */
    stated(p.description, "Vein", &d, &w, &h);
    assert_true(fabsf(vein.cz - d) <= 0.5f);
    assert_true(fabsf(vein.width - w) <= 1.0f);
    assert_true(fabsf(vein.depth - h) <= 1.0f);
    assert_true(fabsf(vein.cx - p.vessels[0].x_mm) <= 0.5f);
    stated(p.description, "Artery", &d, &w, &h);
    assert_true(fabsf(art.cz - d) <= 0.5f);
    assert_true(fabsf(art.width - w) <= 1.0f);
    assert_true(fabsf(art.depth - h) <= 1.0f);
    assert_true(fabsf(art.cx - p.vessels[1].x_mm) <= 0.5f);
    /* clinical plausibility (adult): vessels side by side, 1-2.5 cm deep, not touching */
    assert_true(vein.cz > 10.0f && vein.cz < 25.0f);
    assert_true(art.cz > 10.0f && art.cz < 25.0f);
    assert_true(fabsf(vein.cx - art.cx) > 0.5f * (vein.width + art.width));
    /* the artery is round (stiff, pressurised) */
    assert_true(fabsf(art.width - art.depth) <= 1.0f);
    if (kind == SC_PHANTOM_NECK_IJV) {
        /* IJV 10-16 mm wide, oval (depth/width < 0.8); CCA 6-9 mm */
        assert_true(vein.width >= 10.0f && vein.width <= 16.0f);
        assert_true(vein.depth / vein.width < 0.8f);
        assert_true(art.width >= 6.0f && art.width <= 9.0f);
        /* under the sternocleidomastoid: muscle directly above the vein centre */
        blob scm = measure(v, 1u << SC_LABEL_MUSCLE);
        assert_true(scm.count > 0u);
        uint32_t j = (uint32_t)lrintf(-v->origin_mm[1] / SP);
        uint32_t i = (uint32_t)lrintf((vein.cx - v->origin_mm[0]) / SP);
        int muscle_above = 0;
        for (float z = 3.0f; z < vein.cz - 0.5f * vein.depth; z += SP) {
            uint32_t k = (uint32_t)lrintf((z - v->origin_mm[2]) / SP);
            muscle_above |= v->labels[vidx(v, i, j, k)] == SC_LABEL_MUSCLE;
        }
        assert_true(muscle_above);
    } else {
        /* CFV 9-14 mm, CFA 7-10 mm */
        assert_true(vein.width >= 9.0f && vein.width <= 14.0f);
        assert_true(art.width >= 7.0f && art.width <= 10.0f);
    }
    /* thrombus only in the DVT case, and then it fills the lumen (>= 80% of the vessel) */
    blob thr = measure(v, 1u << SC_LABEL_THROMBUS);
    if (kind == SC_PHANTOM_FEMORAL_DVT) {
        assert_true(thr.count * 10u >= vein.count * 8u);
    } else {
        assert_int_equal(thr.count, 0);
    }
    /* the case file is valid and labels are all in the table */
    size_t need = sc_case_encoded_size(&p.def), n = 0;
    uint8_t *buf = malloc(need);
    assert_non_null(buf);
    assert_int_equal(sc_case_write(&p.def, buf, need, &n), SC_OK);
    sc_case c;
    assert_int_equal(sc_case_load(buf, n, &c), SC_OK);
    assert_string_equal(c.name, sc_phantom_kind_name(kind));
    /* the mesh box contains both vessels */
    for (int i = 0; i < 2; i++) {
        const blob *b = i == 0 ? &vein : &art;
        assert_true(b->cx - 0.5f * b->width >= c.mesh.origin_mm[0]);
        assert_true(b->cx + 0.5f * b->width <= c.mesh.origin_mm[0] + c.mesh.size_mm[0]);
        assert_true(b->cz + 0.5f * b->depth <= c.mesh.origin_mm[2] + c.mesh.size_mm[2]);
    }
    free(buf);
    sc_phantom_free(&p);
}

static void neck_ijv_has_oval_vein_beside_round_artery_under_scm(void **state)
{
    (void)state;
    check_vessels_at_stated_geometry(SC_PHANTOM_NECK_IJV);
}

static void femoral_has_vein_and_artery_at_stated_geometry(void **state)
{
    (void)state;
    check_vessels_at_stated_geometry(SC_PHANTOM_FEMORAL);
}

static void femoral_dvt_vein_is_filled_with_thrombus(void **state)
{
    (void)state;
    check_vessels_at_stated_geometry(SC_PHANTOM_FEMORAL_DVT);
}

/* mean intensity over a box (mm) of the y = 0 slice band |y| < 5 mm, voxels with label in mask */
static double mean_box(const sc_volume *v, float x0, float x1, float z0, float z1, unsigned mask)
{
    double s = 0.0;
    size_t n = 0;
    for (uint32_t k = 0; k < v->dim[2]; k++) {
        float z = v->origin_mm[2] + SP * (float)k;
        if (z < z0 || z > z1) {
            continue;
        }
        for (uint32_t j = 0; j < v->dim[1]; j++) {
            float y = v->origin_mm[1] + SP * (float)j;
            if (fabsf(y) > 5.0f) {
                continue;
            }
            for (uint32_t i = 0; i < v->dim[0]; i++) {
                float x = v->origin_mm[0] + SP * (float)i;
                size_t q = vidx(v, i, j, k);
                if (x >= x0 && x <= x1 && (mask & (1u << v->labels[q]))) {
                    s += v->voxels[q];
                    n++;
                }
            }
        }
    }
    assert_true(n > 50u);
    return s / (double)n;
}

static void image_shows_anechoic_lumen_enhancement_and_bone_shadow(void **state)
{
    (void)state;
    sc_phantom p;
    generate(SC_PHANTOM_NECK_IJV, 1u, &p);
    const sc_volume *v = &p.def.volume;
    const sc_phantom_vessel *ijv = &p.vessels[0];
    /* lumen anechoic: well below soft tissue (which sits mid-grey) */
    double lumen = mean_box(v, ijv->x_mm - 3.0f, ijv->x_mm + 3.0f, ijv->z_mm - 2.0f,
                            ijv->z_mm + 2.0f, 1u << SC_LABEL_VEIN);
    double tissue =
        mean_box(v, -24.0f, 24.0f, 2.0f, 30.0f, (1u << SC_LABEL_FAT) | (1u << SC_LABEL_MUSCLE));
    assert_true(lumen < 20.0);
    assert_true(tissue > 50.0 && tissue < 160.0);
    /* posterior acoustic enhancement: the same tissue at the same depth is brighter below
     * the vein (9 mm of blood saves ~8 dB = ~40 grey levels at 50 dB range) than beside it;
     * 15 levels is far above the speckle noise of a mean over thousands of voxels */
    float zb = ijv->z_mm + ijv->half_d_mm;
    const unsigned deep_fat = 1u << SC_LABEL_FAT;
    double below = mean_box(v, ijv->x_mm - 2.0f, ijv->x_mm + 2.0f, zb + 0.8f, zb + 3.0f, deep_fat);
    double beside = mean_box(v, -24.0f, -16.0f, zb + 0.8f, zb + 3.0f, deep_fat);
    assert_true(below > beside + 15.0);
    /* bright artery wall: the top of the ring (specular, across the beam) well above tissue */
    const sc_phantom_vessel *cca = &p.vessels[1];
    double wall = mean_box(v, cca->x_mm - 1.5f, cca->x_mm + 1.5f, cca->z_mm - cca->half_d_mm,
                           cca->z_mm - cca->half_d_mm + cca->wall_mm, 1u << SC_LABEL_ARTERY);
    assert_true(wall > tissue + 40.0);
    /* bone: bright cortex, dark shadow below it */
    double above_bone = mean_box(v, 2.0f, 10.0f, 30.0f, 34.0f, 1u << SC_LABEL_MUSCLE);
    double shadow = mean_box(v, 2.0f, 10.0f, 39.0f, 44.0f, 1u << SC_LABEL_BONE);
    assert_true(shadow < 15.0);
    assert_true(above_bone > 40.0);
    sc_phantom_free(&p);
}

static void generation_is_deterministic_from_the_seed(void **state)
{
    (void)state;
    sc_phantom a, b, c;
    generate(SC_PHANTOM_FEMORAL, 7u, &a);
    generate(SC_PHANTOM_FEMORAL, 7u, &b);
    generate(SC_PHANTOM_FEMORAL, 8u, &c);
    size_t n = (size_t)a.def.volume.dim[0] * a.def.volume.dim[1] * a.def.volume.dim[2];
    assert_memory_equal(a.voxels, b.voxels, n);
    assert_memory_equal(a.labels, b.labels, n);
    /* another seed: other speckle, same anatomy */
    assert_memory_equal(a.labels, c.labels, n);
    size_t diff = 0;
    for (size_t i = 0; i < n; i++) {
        diff += a.voxels[i] != c.voxels[i];
    }
    assert_true(diff > n / 4u);
    sc_phantom_free(&a);
    sc_phantom_free(&b);
    sc_phantom_free(&c);
}

static void bad_definitions_are_refused(void **state)
{
    (void)state;
    sc_phantom p;
    sc_phantom_def d = sc_phantom_default_def();
    d.spacing_mm = 0.0f;
    assert_int_equal(sc_phantom_generate(&d, &p), SC_ERR_INVALID_ARG);
    d = sc_phantom_default_def();
    d.kind = SC_PHANTOM_KIND_COUNT;
    assert_int_equal(sc_phantom_generate(&d, &p), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_phantom_kind_from_name("neck-ijv"), SC_PHANTOM_NECK_IJV);
    assert_int_equal(sc_phantom_kind_from_name("femoral-dvt"), SC_PHANTOM_FEMORAL_DVT);
    assert_int_equal(sc_phantom_kind_from_name("liver"), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(neck_ijv_has_oval_vein_beside_round_artery_under_scm),
        cmocka_unit_test(femoral_has_vein_and_artery_at_stated_geometry),
        cmocka_unit_test(femoral_dvt_vein_is_filled_with_thrombus),
        cmocka_unit_test(image_shows_anechoic_lumen_enhancement_and_bone_shadow),
        cmocka_unit_test(generation_is_deterministic_from_the_seed),
        cmocka_unit_test(bad_definitions_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
