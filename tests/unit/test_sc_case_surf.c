/* test_sc_case_surf.c: the case file's SURF section (core/case/sc_case_surf.h): the parser's
 * refusals by rule, the loader (whole and sliced) refusing a case with a bad SURF and accepting
 * one without, and the phantom cases' SURF from sc-casebuild: skin and vessel surfaces whose
 * barycentric embedding reproduces points inside the rest mesh. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_case.h"
#include "sc_case_surf.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_mesh.h"
#include "sc_test_case.h"

static void wr32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void wrf(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    wr32(p, u);
}

/* one vessel surface: 3 vertices (tets 0, 1, 2), 1 triangle */
#define SURF_N (16u + 16u + 3u * 16u + 12u)
static void make_surf(uint8_t p[SURF_N])
{
    memset(p, 0, SURF_N);
    wr32(p, SC_CASE_SURF_VERSION);
    wr32(p + 4, 1);
    wr32(p + 8, 3);
    wr32(p + 12, 1);
    p[16] = SC_LABEL_VEIN;
    p[17] = SC_CASE_SURF_VESSEL;
    wr32(p + 24, 3);
    wr32(p + 28, 1);
    for (uint32_t v = 0; v < 3u; v++) {
        wr32(p + 32 + 16 * v, v);
        for (int k = 0; k < 3; k++) {
            wrf(p + 36 + 16 * v + 4 * (uint32_t)k, 0.25f);
        }
    }
    wr32(p + 80, 0);
    wr32(p + 84, 1);
    wr32(p + 88, 2);
}

static void parser_accepts_a_valid_payload(void **state)
{
    (void)state;
    uint8_t p[SURF_N];
    make_surf(p);
    sc_case_surf s;
    assert_int_equal(sc_case_surf_parse(p, SURF_N, 320u, &s), SC_OK);
    assert_int_equal(s.count, 1u);
    assert_int_equal(s.vertex_count, 3u);
    assert_int_equal(s.s[0].label, SC_LABEL_VEIN);
    uint32_t tet;
    float w[4];
    sc_case_surf_vertex(&s, 2, &tet, w);
    assert_int_equal(tet, 2u);
    assert_true(fabsf(w[3] - 0.25f) < 1e-6f);
}

static void parser_refuses_each_broken_rule(void **state)
{
    (void)state;
    uint8_t p[SURF_N];
    sc_case_surf s;
    struct {
        const char *what;
        uint32_t off;
        uint32_t value;
        int as_float;
    } bad[] = {
        {"version", 0, 2, 0},
        {"no surface", 4, 0, 0},
        {"vertex count vs size", 8, 4, 0},
        {"kind", 17, 9, 0}, /* byte, written below */
        {"first vertex", 20, 1, 0},
        {"tet out of range", 32, 320, 0},
        {"weight not finite", 36, 0x7fc00000u, 0},
        {"weight far outside", 40, 0, 1},
        {"triangle outside the surface", 88, 3, 0},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        make_surf(p);
        if (bad[i].off == 17u) {
            p[17] = (uint8_t)bad[i].value;
        } else if (bad[i].as_float) {
            wrf(p + bad[i].off, 3.0f);
        } else {
            wr32(p + bad[i].off, bad[i].value);
        }
        const int rc = sc_case_surf_parse(p, SURF_N, 320u, &s);
        if (rc != SC_ERR_CASE_SURFACE) {
            fail_msg("%s: %d", bad[i].what, rc);
        }
    }
    make_surf(p);
    assert_int_equal(sc_case_surf_parse(p, SURF_N - 1u, 320u, &s), SC_ERR_CASE_SURFACE);
}

static void loader_takes_no_surf_a_good_one_and_refuses_a_bad_one(void **state)
{
    (void)state;
    sc_test_case tc;
    assert_int_equal(sc_test_case_make(&tc, 5, 5, 5, SC_LABEL_VEIN, "surf"), SC_OK);
    sc_case c;
    assert_int_equal(sc_case_load(tc.bytes, tc.size, &c), SC_OK);
    assert_int_equal(c.surf.count, 0u);
    for (int broken = 0; broken < 2; broken++) {
        uint8_t p[SURF_N];
        make_surf(p);
        if (broken) {
            wr32(p + 32, 100000u); /* a tet the 5x5x5 mesh does not have */
        }
        const size_t cap = tc.size + 64u + 128u;
        uint8_t *b = malloc(cap);
        assert_non_null(b);
        memcpy(b, tc.bytes, tc.size);
        size_t n = tc.size;
        assert_int_equal(sc_case_append_section(b, cap, &n, SC_CASE_TAG_SURF_U32, p, SURF_N), SC_OK);
        const int want = broken ? SC_ERR_CASE_SURFACE : SC_OK;
        assert_int_equal(sc_case_load(b, n, &c), want);
        if (!broken) {
            assert_int_equal(c.surf.count, 1u);
            assert_int_equal(c.surf.triangle_count, 1u);
        }
        /* the sliced validation of a case switch agrees */
        static sc_case_check k;
        assert_int_equal(sc_case_check_begin(&k, b, n), SC_OK);
        int r;
        while ((r = sc_case_check_step(&k, 1u << 16)) == 0) {
        }
        assert_int_equal(r, 1);
        assert_int_equal(sc_case_check_finish(&k, &c), want);
        free(b);
    }
    free(tc.bytes);
}

static sc_mesh g_mesh;

static void phantom_surfaces_are_embedded_in_the_rest_mesh(void **state)
{
    (void)state;
    const char *path = SC_BINARY_DIR "/cases/neck-ijv.scase";
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        skip(); /* the cases target builds it with every build */
    }
    fseek(f, 0, SEEK_END);
    const long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)size);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    sc_case c;
    assert_int_equal(sc_case_load(b, (size_t)size, &c), SC_OK);
    assert_true(c.surf.count >= 3u);
    assert_int_equal(c.surf.s[0].kind, SC_CASE_SURF_SKIN);
    assert_int_equal(c.surf.s[0].vertex_count, c.mesh.nx * c.mesh.ny);
    int have_vein = 0, have_artery = 0;
    for (uint32_t i = 1; i < c.surf.count; i++) {
        have_vein |= c.surf.s[i].label == SC_LABEL_VEIN && c.surf.s[i].vertex_count > 100u;
        have_artery |= c.surf.s[i].label == SC_LABEL_ARTERY && c.surf.s[i].vertex_count > 100u;
    }
    assert_true(have_vein && have_artery);
    assert_int_equal(sc_mesh_build(&g_mesh, &c.mesh), SC_OK);
    /* every vertex, carried by its weights over the rest mesh, lies inside the mesh box; the
     * skin's lie on its top face (z = origin) */
    for (uint32_t v = 0; v < c.surf.vertex_count; v++) {
        uint32_t tet;
        float w[4], p[3] = {0, 0, 0};
        sc_case_surf_vertex(&c.surf, v, &tet, w);
        for (int k = 0; k < 4; k++) {
            const uint32_t n = g_mesh.tet[tet][k];
            p[0] += w[k] * g_mesh.rest_x[n];
            p[1] += w[k] * g_mesh.rest_y[n];
            p[2] += w[k] * g_mesh.rest_z[n];
        }
        for (int a = 0; a < 3; a++) {
            assert_true(p[a] >= c.mesh.origin_mm[a] - 1e-3f);
            assert_true(p[a] <= c.mesh.origin_mm[a] + c.mesh.size_mm[a] + 1e-3f);
        }
        if (v < c.surf.s[0].vertex_count) {
            assert_true(fabsf(p[2] - c.mesh.origin_mm[2]) < 1e-3f);
        }
    }
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(parser_accepts_a_valid_payload),
        cmocka_unit_test(parser_refuses_each_broken_rule),
        cmocka_unit_test(loader_takes_no_surf_a_good_one_and_refuses_a_bad_one),
        cmocka_unit_test(phantom_surfaces_are_embedded_in_the_rest_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
