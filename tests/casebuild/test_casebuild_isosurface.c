/* test_casebuild_isosurface.c: label isosurfaces (marching cubes by face walking + Gaussian
 * Taubin smoothing) are closed, consistently oriented outward, and of the right size. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_isosurface.h"

#define D 40u
static uint8_t g_lab[D * D * D];

static sc_volume sphere_volume(float r_mm, float sp)
{
    const float c = 0.5f * (float)(D - 1u) * sp;
    for (uint32_t k = 0; k < D; k++) {
        for (uint32_t j = 0; j < D; j++) {
            for (uint32_t i = 0; i < D; i++) {
                float x = (float)i * sp - c, y = (float)j * sp - c, z = (float)k * sp - c;
                g_lab[i + D * (j + D * k)] =
                    (uint8_t)(x * x + y * y + z * z <= r_mm * r_mm ? 4 : 2);
            }
        }
    }
    sc_volume v = {{D, D, D}, {sp, sp, sp}, {0.0f, 0.0f, 0.0f}, g_lab, g_lab};
    return v;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* every directed edge appears once and its reverse once: closed, oriented 2-manifold */
static void assert_closed_and_oriented(const sc_iso_mesh *m)
{
    size_t ne = m->triangle_count * 3u;
    uint64_t *e = malloc(ne * sizeof *e);
    assert_non_null(e);
    for (size_t t = 0; t < m->triangle_count; t++) {
        for (int k = 0; k < 3; k++) {
            uint64_t a = m->tri[t * 3u + (size_t)k], b = m->tri[t * 3u + (size_t)((k + 1) % 3)];
            assert_true(a != b);
            e[t * 3u + (size_t)k] = (a << 32) | b;
        }
    }
    qsort(e, ne, sizeof *e, cmp_u64);
    for (size_t i = 0; i + 1u < ne; i++) {
        assert_true(e[i] != e[i + 1u]); /* no directed edge twice: consistent winding */
    }
    for (size_t i = 0; i < ne; i++) {
        uint64_t rev = (e[i] << 32) | (e[i] >> 32);
        assert_non_null(bsearch(&rev, e, ne, sizeof *e, cmp_u64)); /* no boundary edge */
    }
    free(e);
}

static double signed_volume(const sc_iso_mesh *m)
{
    double v = 0.0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        const float *a = &m->xyz[m->tri[t * 3u] * 3u], *b = &m->xyz[m->tri[t * 3u + 1u] * 3u],
                    *c = &m->xyz[m->tri[t * 3u + 2u] * 3u];
        v += ((double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
              (double)a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) /
             6.0;
    }
    return v;
}

static void sphere_surface_is_closed_outward_and_of_the_right_volume(void **state)
{
    (void)state;
    const float r = 6.0f, sp = 0.5f;
    sc_volume v = sphere_volume(r, sp);
    for (int smooth = 0; smooth < 2; smooth++) {
        sc_iso_opts o = sc_iso_default_opts();
        o.label = 4;
        o.sigma_mm = smooth ? 1.0f : 0.0f;
        sc_iso_mesh m;
        assert_int_equal(sc_iso_extract(&v, &o, &m), SC_OK);
        assert_true(m.triangle_count > 500u);
        assert_closed_and_oriented(&m);
        /* outward normals give a positive volume; the voxelised ball's volume is within 10%
         * of 4/3 pi r^3 at r = 12 voxels (midpoint vertices cut corners) */
        double vol = signed_volume(&m), want = 4.0 / 3.0 * M_PI * (double)(r * r * r);
        assert_true(vol > 0.0);
        assert_true(fabs(vol - want) < 0.10 * want);
        /* every vertex near the sphere: within one voxel before smoothing, and smoothing
         * (Taubin, non-shrinking) keeps it within one voxel */
        const float c = 0.5f * (float)(D - 1u) * sp;
        double rms = 0.0;
        for (size_t i = 0; i < m.vertex_count; i++) {
            float dx = m.xyz[i * 3u] - c, dy = m.xyz[i * 3u + 1u] - c, dz = m.xyz[i * 3u + 2u] - c;
            float dr = sqrtf(dx * dx + dy * dy + dz * dz) - r;
            assert_true(fabsf(dr) < sp);
            rms += (double)(dr * dr);
        }
        rms = sqrt(rms / (double)m.vertex_count);
        if (smooth) {
            assert_true(rms < 0.25 * sp); /* smoothing removes most of the faceting */
        }
        sc_iso_mesh_free(&m);
    }
}

static void saddle_configurations_stay_manifold(void **state)
{
    (void)state;
    /* checkerboard-ish random labels: every ambiguous face and cube case occurs */
    uint32_t x = 99u;
    for (size_t i = 0; i < sizeof g_lab; i++) {
        x = x * 1664525u + 1013904223u;
        g_lab[i] = (uint8_t)((x >> 28) & 1u ? 4 : 0);
    }
    sc_volume v = {{D, D, D}, {1.0f, 1.0f, 1.0f}, {0.0f, 0.0f, 0.0f}, g_lab, g_lab};
    sc_iso_opts o = sc_iso_default_opts();
    o.label = 4;
    o.sigma_mm = 0.0f;
    sc_iso_mesh m;
    assert_int_equal(sc_iso_extract(&v, &o, &m), SC_OK);
    assert_closed_and_oriented(&m);
    sc_iso_mesh_free(&m);
}

static void missing_label_is_not_found_and_files_are_written(void **state)
{
    (void)state;
    sc_volume v = sphere_volume(3.0f, 1.0f);
    sc_iso_opts o = sc_iso_default_opts();
    sc_iso_mesh m;
    o.label = 7;
    assert_int_equal(sc_iso_extract(&v, &o, &m), SC_ERR_NOT_FOUND);
    o.label = 4;
    assert_int_equal(sc_iso_extract(&v, &o, &m), SC_OK);
    char ply[] = "/tmp/sc_iso_XXXXXX";
    int fd = mkstemp(ply);
    assert_true(fd >= 0);
    assert_int_equal(sc_iso_write_ply(&m, ply), SC_OK);
    FILE *f = fopen(ply, "r");
    char line[64];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "ply\n");
    fclose(f);
    assert_int_equal(sc_iso_write_obj(&m, ply), SC_OK);
    remove(ply);
    sc_iso_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sphere_surface_is_closed_outward_and_of_the_right_volume),
        cmocka_unit_test(saddle_configurations_stay_manifold),
        cmocka_unit_test(missing_label_is_not_found_and_files_are_written),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
