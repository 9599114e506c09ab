/* test_sc_bscan.c: B-scan synthesis through the deformed mesh (paper section IV).
 *
 * The scene (tools/bench_bscan/bscan_scene.h) is a generated volume with a vein and an artery
 * and prescribed smooth mesh deformations; the reference rigid slice is computed here
 * independently (double precision trilinear), the oracle mapper is the per-pixel brute force.
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../tools/bench_bscan/bscan_scene.h"
#include "sc_bscan.h"
#include "sc_cpu.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_mesh.h"
#include "sc_simd.h"

#define IMG_MAX (SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES)

static scn_volume g_vol;
static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_bscan g_b;
static sc_hs_display g_disp;
static uint8_t g_a[IMG_MAX], g_o[IMG_MAX], g_ref[IMG_MAX];
static float g_ref_i[IMG_MAX]; /* reference intensity before display processing */

static int group_setup(void **state)
{
    (void)state;
    scn_make_volume(&g_vol);
    return 0;
}

static void build_mesh(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = nx;
    md.ny = ny;
    md.nz = nz;
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
}

static void deform(int kind, float a, int wobble)
{
    scn_deform(&g_mesh, &g_nodes, kind, a);
    if (wobble) {
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            float u[3];
            scn_displacement(SCN_DEFORM_WOBBLE, 1.0f, g_mesh.rest_x[i], g_mesh.rest_y[i],
                             g_mesh.rest_z[i], u);
            g_nodes.x[i] += u[0];
            g_nodes.y[i] += u[1];
            g_nodes.z[i] += u[2];
        }
    }
}

/* Render one frame into out (line-major); returns the frame's return code. */
static int render(const sc_bscan_def *def, const sc_xform *probe, int contact, uint8_t *out)
{
    assert_int_equal(sc_bscan_init(&g_b, def), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    const int rc = sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, probe, contact, &dev, 7u);
    assert_int_equal(g_disp.frames_complete, 1);
    assert_int_equal(g_disp.protocol_errors, 0);
    memcpy(out, g_disp.last, (size_t)def->scan.lines_n * def->scan.samples_n);
    return rc;
}

/* Independent rigid slice: double-precision trilinear at each pixel's own position, 0 where
 * the nearest label is OUTSIDE or the point is outside the volume. */
static void rigid_slice(const sc_bscan_def *def, const sc_xform *probe)
{
    sc_scan_geom g;
    assert_int_equal(sc_scan_geom_init(&g, &def->scan), SC_OK);
    const sc_xform m = sc_xform_compose(probe, &def->scan.image_to_probe);
    const sc_volume *v = &g_vol.v;
    for (uint32_t l = 0; l < def->scan.lines_n; l++) {
        for (uint32_t k = 0; k < def->scan.samples_n; k++) {
            float img[3], w[3];
            sc_scan_geom_pixel(&g, l, k, img);
            sc_xform_apply(&m, img, w);
            double f[3];
            double out2_mm2 = 0.0; /* squared distance outside the volume */
            for (int d = 0; d < 3; d++) {
                f[d] = ((double)w[d] - v->origin_mm[d]) / v->spacing_mm[d];
                /* beyond the volume: back and forth across the 6 mm slab along the face
                 * (clamped above the top) */
                const double lo = -0.5, hi = (double)v->dim[d] - 0.5;
                const double o = f[d] < lo ? lo - f[d] : (f[d] >= hi ? f[d] - hi : 0.0);
                out2_mm2 += o * o * v->spacing_mm[d] * v->spacing_mm[d];
                const double slab = 6.0 / v->spacing_mm[d];
                double back = fmod(o, 2.0 * slab);
                back = back < slab ? back : 2.0 * slab - back;
                if (f[d] < lo) {
                    f[d] = d == 2 ? 0.0 : lo + back;
                } else if (f[d] >= hi) {
                    f[d] = hi - back;
                }
                f[d] = f[d] < 0.0 ? 0.0 : (f[d] > hi - 0.5 ? hi - 0.5 : f[d]);
            }
            /* darkened by 0.5 dB/mm outside, in grey levels of the 60 dB display */
            const double loss = 255.0 * 0.5 / 60.0 * sqrt(out2_mm2);
            const size_t o = (size_t)l * def->scan.samples_n + k;
            int i0[3];
            double t[3];
            for (int d = 0; d < 3; d++) {
                double c = f[d] < 0.0 ? 0.0 : f[d];
                int lim = (int)v->dim[d] - 2;
                i0[d] = (int)floor(c);
                if (i0[d] > lim) {
                    i0[d] = lim;
                }
                t[d] = c - i0[d];
                if (t[d] > 1.0) {
                    t[d] = 1.0;
                }
            }
            double acc = 0.0;
            for (int c = 0; c < 8; c++) {
                const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
                const double wgt =
                    (dx ? t[0] : 1.0 - t[0]) * (dy ? t[1] : 1.0 - t[1]) * (dz ? t[2] : 1.0 - t[2]);
                const size_t idx =
                    (size_t)(i0[0] + dx) +
                    v->dim[0] * ((size_t)(i0[1] + dy) + v->dim[1] * (size_t)(i0[2] + dz));
                acc += wgt * v->voxels[idx];
            }
            const size_t li =
                (size_t)(int)(f[0] + 0.5) +
                v->dim[0] * ((size_t)(int)(f[1] + 0.5) + v->dim[1] * (size_t)(int)(f[2] + 0.5));
            const int dark = v->labels[li] == SC_LABEL_OUTSIDE || acc - loss <= 0.0;
            g_ref_i[o] = dark ? -1.0f : (float)(acc - loss);
            g_ref[o] = dark ? 0 : (uint8_t)floor(acc - loss + 0.5);
        }
    }
}

typedef struct cmp_result {
    uint32_t n, equal, max_diff, differ_gt1;
} cmp_result;

static cmp_result compare(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    cmp_result r = {n, 0, 0, 0};
    for (uint32_t i = 0; i < n; i++) {
        const uint32_t d = (uint32_t)abs((int)a[i] - (int)b[i]);
        r.equal += d == 0;
        r.differ_gt1 += d > 1u;
        if (d > r.max_diff) {
            r.max_diff = d;
        }
    }
    return r;
}

static sc_bscan_def small_def(uint32_t mapper, uint32_t lines, uint32_t samples)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.mapper = mapper;
    d.scan.lines_n = lines;
    d.scan.samples_n = samples;
    return d;
}

/* ---- rigid: the undeformed mesh changes nothing ------------------------------------------- */

static void undeformed_mesh_image_equals_rigid_slice_all_mappers(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    /* straight above the centre, and tilted across the mesh side and above the skin */
    const sc_xform poses[2] = {scn_probe(20.0f, 10.0f, 0.0f, 0.0f),
                               scn_probe(4.0f, 9.3f, -2.0f, 14.0f)};
    for (int p = 0; p < 2; p++) {
        for (uint32_t mp = 0; mp < SC_BSCAN_MAP_COUNT; mp++) {
            /* the oracle is O(pixels * tets): a smaller image */
            sc_bscan_def d =
                mp == SC_BSCAN_MAP_ORACLE ? small_def(mp, 24, 64) : small_def(mp, 256, 512);
            render(&d, &poses[p], 1, g_a);
            rigid_slice(&d, &poses[p]);
            const uint32_t n = d.scan.lines_n * d.scan.samples_n;
            cmp_result r = compare(g_a, g_ref, n);
            if (r.max_diff > 1u) {
                for (uint32_t i = 0, shown = 0; i < n && shown < 5u; i++) {
                    if (abs((int)g_a[i] - (int)g_ref[i]) > 1) {
                        print_message("pose %d mapper %u: line %u sample %u: %u vs ref %u (%.3f)\n",
                                      p, mp, i / d.scan.samples_n, i % d.scan.samples_n, g_a[i],
                                      g_ref[i], (double)g_ref_i[i]);
                        shown++;
                    }
                }
            }
            /* 1 grey level: float32 sampling positions vs the double reference can round the
             * other way at .5 */
            assert_true(r.max_diff <= 1u);
            assert_true(g_b.status.pixels_in_mesh > n / 4u); /* the mesh was really used */
            if (p == 1) {
                uint32_t dark = 0;
                for (uint32_t i = 0; i < n; i++) {
                    dark += g_a[i] == 0;
                }
                assert_true(dark > n / 50u); /* the tilted probe sees air above the skin */
            }
        }
    }
}

/* ---- deformed: fast paths agree with the oracle -------------------------------------------- */

static void check_against_oracle(sc_bscan_def d, const sc_xform *probe, uint32_t min_changed)
{
    d.mapper = SC_BSCAN_MAP_ORACLE;
    render(&d, probe, 1, g_o);
    const uint32_t oracle_in = g_b.status.pixels_in_mesh;
    const uint32_t n = d.scan.lines_n * d.scan.samples_n;
    rigid_slice(&d, probe);
    cmp_result moved = compare(g_o, g_ref, n);
    print_message("oracle: %u of %u pixels in mesh, %u differ from the rigid slice by > 1\n",
                  oracle_in, n, moved.differ_gt1);
    /* the deformation must visibly change the image, or the comparison proves nothing */
    assert_true(moved.differ_gt1 >= min_changed);
    for (uint32_t mp = 0; mp < SC_BSCAN_MAP_COUNT; mp++) {
        if (mp == SC_BSCAN_MAP_ORACLE) {
            continue;
        }
        d.mapper = mp;
        render(&d, probe, 1, g_a);
        cmp_result r = compare(g_a, g_o, n);
        {
            print_message("mapper %u: %u/%u equal, max diff %u, in mesh %u vs oracle %u\n", mp,
                          r.equal, n, r.max_diff, g_b.status.pixels_in_mesh, oracle_in);
        }
        /* ties on tet faces: at most 0.1 % of pixels differ, none by more than 1 grey level
         * (the rest map is continuous across faces; float rounding only) */
        assert_true(r.equal * 1000u >= n * 999u);
        assert_true(r.max_diff <= 1u);
        const uint32_t in = g_b.status.pixels_in_mesh;
        assert_true(in + n / 1000u >= oracle_in && in <= oracle_in + n / 1000u);
    }
}

static void linear_fast_paths_match_oracle_on_deformed_small_mesh(void **state)
{
    (void)state;
    build_mesh(16, 8, 8);
    deform(SCN_DEFORM_DENT, 6.0f, 1);
    const sc_xform straight = scn_probe(20.0f, 10.0f, 5.0f, 0.0f);
    check_against_oracle(small_def(0, 48, 128), &straight, 300u);
    /* tilted and rolled: lines leave through the side, pixels above the skin */
    sc_xform tilted = scn_probe(5.0f, 8.0f, -1.0f, 17.0f);
    const sc_xform roll = {
        .r = {1.0f, 0.0f, 0.0f, 0.0f, 0.9848078f, -0.1736482f, 0.0f, 0.1736482f, 0.9848078f},
        .t_mm = {0.0f, 0.0f, 0.0f}};
    tilted = sc_xform_compose(&tilted, &roll);
    check_against_oracle(small_def(0, 48, 128), &tilted, 150u);
}

static void curvilinear_fast_paths_match_oracle_on_deformed_small_mesh(void **state)
{
    (void)state;
    build_mesh(16, 8, 8);
    deform(SCN_DEFORM_DENT, 6.0f, 1);
    sc_bscan_def d = small_def(0, 48, 128);
    d.scan = sc_scan_curvilinear_default_def();
    d.scan.lines_n = 48;
    d.scan.samples_n = 128;
    d.scan.radius_mm = 20.0f;
    const sc_xform probe = scn_probe(20.0f, 10.0f, 5.0f, 0.0f);
    check_against_oracle(d, &probe, 300u);
}

static void fast_paths_match_oracle_on_deformed_full_mesh(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    deform(SCN_DEFORM_DENT, 8.0f, 1);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 7.5f, 3.0f);
    check_against_oracle(small_def(0, 24, 80), &probe, 80u);
}

/* A node pushed through its neighbours inverts tets: the walker cannot follow its faces there,
 * locates the samples beyond among the plane's tets and walks on (no line handed to the region
 * path), and the image agrees with the region path's and the oracle's everywhere but on face
 * ties. */
static void lines_through_inverted_tets_are_walked_by_locating_across_the_fold(void **state)
{
    (void)state;
    build_mesh(16, 8, 8);
    deform(SCN_DEFORM_DENT, 4.0f, 0);
    /* the node nearest to (20, 10, 8): pushed up by 1.6 cells in z, through its upper
     * neighbours' cells */
    uint32_t best = 0;
    float bd = 1e9f;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float dx = g_mesh.rest_x[i] - 20.0f, dy = g_mesh.rest_y[i] - 10.0f,
                    dz = g_mesh.rest_z[i] - 8.0f;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < bd) {
            bd = d2;
            best = i;
        }
    }
    g_nodes.z[best] -= 1.6f * g_mesh.cell_mm[2];
    uint32_t inverted = 0;
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        inverted += sc_mesh_tet_volume_mm3(g_nodes.x, g_nodes.y, g_nodes.z, g_mesh.tet[t]) <= 0.0f;
    }
    assert_true(inverted > 0u);
    /* the image plane through the pushed node */
    const sc_xform probe = scn_probe(20.0f, g_mesh.rest_y[best], 4.0f, 0.0f);
    sc_bscan_def d = small_def(SC_BSCAN_MAP_WALK, 64, 160);
    render(&d, &probe, 1, g_a);
    assert_true(g_b.status.walk_relocations > 0u);
    assert_int_equal(g_b.status.line_fallbacks, 0);
    assert_int_equal(g_b.status.walk_aborts, 0);
    const uint32_t n = d.scan.lines_n * d.scan.samples_n;
    for (uint32_t mp = SC_BSCAN_MAP_REGIONS; mp <= SC_BSCAN_MAP_ORACLE; mp++) {
        d.mapper = mp;
        render(&d, &probe, 1, g_o);
        cmp_result r = compare(g_a, g_o, n);
        print_message("walker vs %s: %u of %u equal, max diff %u\n",
                      mp == SC_BSCAN_MAP_REGIONS ? "regions" : "oracle", r.equal, n,
                      (unsigned)r.max_diff);
        assert_true(r.equal * 1000u >= n * 999u);
        assert_true(r.max_diff <= 1u);
    }
}

/* The region bins find the plane's tets cell row by cell row on sc_mesh_build's layout
 * (mesh_grid): the same tets in the same order as the pass over every tet, so the same bytes,
 * plane tets and relocations, through a fold (walker) and on the region path; a mesh not in
 * that layout is recognised and takes the pass over every tet. */
static sc_mesh g_mesh_swapped;

static void render_grid(const sc_bscan_def *def, const sc_xform *probe, uint32_t grid,
                        uint8_t *out)
{
    assert_int_equal(sc_bscan_init(&g_b, def), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    assert_int_equal(g_b.mesh_grid, 1);
    g_b.mesh_grid = grid;
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, probe, 1, &dev, 7u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
    memcpy(out, g_disp.last, (size_t)def->scan.lines_n * def->scan.samples_n);
}

static void plane_tets_from_cell_rows_equal_the_pass_over_every_tet(void **state)
{
    (void)state;
    build_mesh(16, 8, 8);
    deform(SCN_DEFORM_DENT, 4.0f, 0);
    uint32_t best = 0;
    float bd = 1e9f;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float dx = g_mesh.rest_x[i] - 20.0f, dy = g_mesh.rest_y[i] - 10.0f,
                    dz = g_mesh.rest_z[i] - 8.0f;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < bd) {
            bd = d2;
            best = i;
        }
    }
    g_nodes.z[best] -= 1.6f * g_mesh.cell_mm[2]; /* a fold: the walker relocates */
    const sc_xform probe = scn_probe(20.0f, g_mesh.rest_y[best], 4.0f, 0.0f);
    for (uint32_t mp = SC_BSCAN_MAP_WALK; mp <= SC_BSCAN_MAP_REGIONS; mp++) {
        sc_bscan_def d = small_def(mp, 64, 160);
        const uint32_t n = d.scan.lines_n * d.scan.samples_n;
        render_grid(&d, &probe, 1u, g_a);
        const sc_bscan_status st = g_b.status;
        render_grid(&d, &probe, 0u, g_o);
        assert_memory_equal(g_a, g_o, n);
        assert_int_equal(st.plane_tets, g_b.status.plane_tets);
        assert_int_equal(st.walk_relocations, g_b.status.walk_relocations);
        assert_memory_equal(st.area_now_mm2, g_b.status.area_now_mm2, sizeof st.area_now_mm2);
        if (mp == SC_BSCAN_MAP_WALK) {
            assert_true(st.walk_relocations > 0u);
        } else {
            assert_true(st.plane_tets > 0u);
        }
    }
    /* two tets of different cells swapped: not the layout, recognised */
    memcpy(&g_mesh_swapped, &g_mesh, sizeof g_mesh);
    const uint32_t last = g_mesh.tet_count - 1u;
    for (uint32_t v = 0; v < 4u; v++) {
        g_mesh_swapped.tet[0][v] = g_mesh.tet[last][v];
        g_mesh_swapped.tet[last][v] = g_mesh.tet[0][v];
    }
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh_swapped), SC_OK);
    assert_int_equal(g_b.mesh_grid, 0);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    assert_int_equal(g_b.mesh_grid, 1);
}

/* ---- dark images ------------------------------------------------------------------------- */

static void probe_in_air_gives_dark_image(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    sc_bscan_def d = sc_bscan_default_def();
    const sc_xform on_skin = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
    const uint32_t n = d.scan.lines_n * d.scan.samples_n;
    /* no contact: dark even with the probe on the skin, contact flag clear */
    assert_int_equal(render(&d, &on_skin, 0, g_a), SC_OK);
    for (uint32_t i = 0; i < n; i++) {
        assert_int_equal(g_a[i], 0);
    }
    assert_int_equal(g_disp.last_info.flags & SC_DISPLAY_FLAG_CONTACT, 0);
    assert_int_equal(g_b.status.areas_valid, 0);
    /* "contact" but the whole image above the skin (air, label OUTSIDE): dark */
    const sc_xform lifted = scn_probe(20.0f, 10.0f, -61.0f, 0.0f);
    render(&d, &lifted, 1, g_a);
    for (uint32_t i = 0; i < n; i++) {
        assert_int_equal(g_a[i], 0);
    }
    /* the same frame with the probe on the skin is not dark: the test can fail */
    render(&d, &on_skin, 1, g_a);
    uint32_t lit = 0;
    for (uint32_t i = 0; i < n; i++) {
        lit += g_a[i] > 0;
    }
    assert_true(lit > n / 2u);
    assert_int_equal(g_disp.last_info.flags & SC_DISPLAY_FLAG_CONTACT, SC_DISPLAY_FLAG_CONTACT);
}

/* ---- display processing ------------------------------------------------------------------ */

static void gain_tgc_and_dynamic_range_follow_the_display_formula(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
    sc_bscan_def d = small_def(SC_BSCAN_MAP_WALK, 64, 256);
    d.gain_db = 6.0f;
    d.dynamic_range_db = 40.0f;
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        d.tgc_db[i] = -4.0f + 2.0f * (float)i;
    }
    render(&d, &probe, 1, g_a);
    rigid_slice(&d, &probe);
    const float band_mm = d.scan.depth_mm / (float)SC_BSCAN_TGC_BANDS;
    const float dr = d.scan.depth_mm / (float)d.scan.samples_n;
    uint32_t checked = 0, brighter = 0, darker = 0;
    for (uint32_t l = 0; l < d.scan.lines_n; l++) {
        for (uint32_t k = 0; k < d.scan.samples_n; k++) {
            const size_t o = (size_t)l * d.scan.samples_n + k;
            if (g_ref_i[o] < 0.0f) {
                assert_int_equal(g_a[o], 0);
                continue;
            }
            /* TGC by hand: linear between band centres, flat beyond the outer ones */
            double t = ((k + 0.5) * dr) / band_mm - 0.5;
            t = t < 0.0 ? 0.0 : (t > SC_BSCAN_TGC_BANDS - 1.0 ? SC_BSCAN_TGC_BANDS - 1.0 : t);
            const double tgc = -4.0 + 2.0 * t;
            double e = g_ref_i[o] * 60.0 / 255.0 - 60.0 + 6.0 + tgc;
            double out = 255.0 * (e + 40.0) / 40.0;
            out = out < 0.0 ? 0.0 : (out > 255.0 ? 255.0 : out);
            /* 1 grey level of float rounding, times the contrast gain 60/40 */
            assert_true(fabs(out - g_a[o]) <= 2.0);
            checked++;
            brighter += g_a[o] > g_ref[o];
            darker += g_a[o] < g_ref[o];
        }
    }
    assert_true(checked > 1000u);
    assert_true(brighter > 100u && darker > 100u); /* range 40 dB spreads both ways */
    /* settings out of range are refused and leave the old ones */
    sc_bscan_def bad = d;
    bad.tgc_db[3] = NAN;
    assert_int_equal(sc_bscan_set_def(&g_b, &bad), SC_ERR_NOT_FINITE);
    bad = d;
    bad.dynamic_range_db = 5.0f;
    assert_int_equal(sc_bscan_set_def(&g_b, &bad), SC_ERR_RANGE);
    bad = d;
    bad.scan.samples_n = SC_MAX_SCAN_SAMPLES + 1u;
    assert_int_equal(sc_bscan_set_def(&g_b, &bad), SC_ERR_IMG_GEOMETRY);
    bad = d;
    bad.regions_n = 0u;
    assert_int_equal(sc_bscan_set_def(&g_b, &bad), SC_ERR_RANGE);
    assert_true(fabsf(g_b.def.dynamic_range_db - 40.0f) < 1e-6f);
}

/* ---- streaming --------------------------------------------------------------------------- */

typedef struct rec_display {
    int begins, ends, fail_line;
    uint32_t frame_no;
    uint32_t next_line;
    int order_ok;
    sc_display_frame_info info;
    sc_display_end_info end;
} rec_display;

static int rec_begin(void *ctx, const sc_display_frame_info *info)
{
    rec_display *r = ctx;
    r->begins++;
    r->info = *info;
    r->next_line = 0;
    return SC_OK;
}

static int rec_line(void *ctx, uint32_t frame_no, uint16_t line, const uint8_t *s, uint16_t n)
{
    rec_display *r = ctx;
    (void)s;
    if (r->begins != 1 || r->ends != 0 || frame_no != r->info.frame_no || line != r->next_line ||
        n != r->info.samples) {
        r->order_ok = 0;
    }
    r->next_line++;
    return (int)line == r->fail_line ? SC_ERR_IO : SC_OK;
}

static int rec_end(void *ctx, const sc_display_end_info *end)
{
    rec_display *r = ctx;
    r->ends++;
    r->frame_no = end->frame_no;
    r->end = *end;
    return SC_OK;
}

static void lines_stream_in_order_between_begin_and_end_with_frame_number(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    static const sc_display_ops ops = {rec_begin, rec_line, rec_end, NULL, NULL, NULL};
    rec_display rec = {.order_ok = 1, .fail_line = -1};
    const sc_display_dev dev = {&ops, &rec};
    sc_bscan_def d = sc_bscan_default_def();
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &probe, 1, &dev, 4242u),
                     SC_OK);
    assert_int_equal(rec.begins, 1);
    assert_int_equal(rec.ends, 1);
    assert_true(rec.order_ok);
    assert_int_equal(rec.next_line, d.scan.lines_n);
    assert_int_equal(rec.frame_no, 4242u);
    assert_int_equal(rec.info.frame_no, 4242u);
    assert_int_equal(rec.info.lines, 256);
    assert_int_equal(rec.info.samples, 512);
    assert_int_equal(rec.info.geometry_id, SC_SCAN_GEOM_LINEAR);
    assert_true(fabsf(rec.info.depth_mm - 60.0f) < 1e-6f &&
                fabsf(rec.info.width_mm - 38.0f) < 1e-6f);
    /* the frame's own compression measure closes it: the same numbers as its status */
    assert_int_equal(rec.end.frame_no, 4242u);
    assert_int_equal(g_b.status.areas_valid, 1);
    assert_memory_equal(&rec.end.vein_area_ratio, &g_b.status.area_ratio[SC_LABEL_VEIN],
                        sizeof(float));
    assert_memory_equal(&rec.end.artery_area_ratio, &g_b.status.area_ratio[SC_LABEL_ARTERY],
                        sizeof(float));
    assert_true(rec.end.vein_area_ratio > 0.9f);
    /* without contact there is no measure */
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &probe, 0, &dev, 4243u),
                     SC_OK);
    assert_true(rec.end.vein_area_ratio < 0.0f && rec.end.artery_area_ratio < 0.0f);
    /* a failing display line is counted and reported, the frame still completes */
    rec = (rec_display){.order_ok = 1, .fail_line = 17};
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &probe, 1, &dev, 5u),
                     SC_ERR_IO);
    assert_int_equal(rec.next_line, d.scan.lines_n);
    assert_int_equal(rec.ends, 1);
    assert_int_equal(g_b.status.display_errors, 1);
}

/* ---- compression measure ----------------------------------------------------------------- */

static void squashed_vein_area_drops_while_artery_stays(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
    sc_bscan_def d = sc_bscan_default_def();
    render(&d, &probe, 1, g_a);
    const sc_bscan_status *st = sc_bscan_status_get(&g_b);
    assert_int_equal(st->areas_valid, 1);
    /* at rest: now == rest for the vessels (same pixels, same labels) */
    assert_true(fabsf(st->area_ratio[SC_LABEL_VEIN] - 1.0f) < 0.01f);
    assert_true(fabsf(st->area_ratio[SC_LABEL_ARTERY] - 1.0f) < 0.01f);
    /* vein cross-section pi r^2 = 50 mm^2 in the plane (pixel quantisation: 5 %) */
    assert_true(fabsf(st->area_rest_mm2[SC_LABEL_VEIN] - 50.27f) < 2.5f);
    assert_true(fabsf(st->image_area_mm2 - 38.0f * 60.0f) < 0.5f);
    /* squash the band around the vein to 20 % thickness at its centre */
    deform(SCN_DEFORM_SQUASH_VEIN, 0.8f, 0);
    for (uint32_t mp = 0; mp < 2u; mp++) {
        d.mapper = mp;
        render(&d, &probe, 1, g_a);
        assert_true(st->area_ratio[SC_LABEL_VEIN] < 0.4f);
        assert_true(st->area_ratio[SC_LABEL_ARTERY] > 0.8f);
        assert_true(st->area_ratio[SC_LABEL_VEIN] > 0.1f); /* squashed, not gone */
    }
}

/* A probe pressed 10 mm in: the vein (top 8 mm deep at rest) lies partly above the face in
 * the rigid slice; the rest reference reaches rest_margin_mm above the face and counts it
 * whole, so the measure compares with the whole vessel. */
static void rest_reference_counts_vessels_pushed_into_view(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    deform(SCN_DEFORM_DENT, 10.0f, 0);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 10.0f, 0.0f);
    sc_bscan_def d = sc_bscan_default_def();
    render(&d, &probe, 1, g_a);
    /* pi 4^2 = 50.3 mm^2; pixel and margin sampling quantisation: 5 % */
    print_message("vein rest %.2f mm^2 now %.2f\n", (double)g_b.status.area_rest_mm2[SC_LABEL_VEIN],
                  (double)g_b.status.area_now_mm2[SC_LABEL_VEIN]);
    assert_true(fabsf(g_b.status.area_rest_mm2[SC_LABEL_VEIN] - 50.27f) < 2.5f);
    const float ratio_margin = g_b.status.area_ratio[SC_LABEL_VEIN];
    d.rest_margin_mm = 0.0f;
    render(&d, &probe, 1, g_a);
    assert_true(g_b.status.area_rest_mm2[SC_LABEL_VEIN] < 45.0f); /* cut at the face */
    assert_true(g_b.status.area_ratio[SC_LABEL_VEIN] > ratio_margin);
}

/* The compression measure at depth (issue 12): with the probe face 28 mm deep the vein (8-16 mm
 * deep at rest) lies 12-20 mm above the face; the default rest reference (60 mm) still counts
 * it whole, where the former 15 mm reference cut it (and read a collapsed vein as half open). */
static void rest_reference_counts_vessels_far_above_a_deep_face(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    deform(SCN_DEFORM_DENT, 10.0f, 0);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 28.0f, 0.0f);
    sc_bscan_def d = sc_bscan_default_def();
    render(&d, &probe, 1, g_a);
    print_message("face 28 mm deep: vein rest %.2f mm^2 (margin %.0f mm)\n",
                  (double)g_b.status.area_rest_mm2[SC_LABEL_VEIN], (double)d.rest_margin_mm);
    assert_true(fabsf(g_b.status.area_rest_mm2[SC_LABEL_VEIN] - 50.27f) < 2.5f);
    d.rest_margin_mm = 15.0f;
    render(&d, &probe, 1, g_a);
    print_message("  with a 15 mm reference: %.2f mm^2\n",
                  (double)g_b.status.area_rest_mm2[SC_LABEL_VEIN]);
    assert_true(g_b.status.area_rest_mm2[SC_LABEL_VEIN] < 45.0f);
}

/* The rest reference above the face is kept from the last frame while the pose and the volume
 * are the same (a held probe): every frame's measure equals a fresh object's, which labels the
 * margin itself, through a held pose, a deeper press under it, a moved pose and back, another
 * volume (another labels pointer) under the same pose and a changed margin. */
static sc_bscan g_fresh;
static scn_volume g_vol2;

static void frame_on(sc_bscan *b, const sc_volume *v, const sc_xform *probe)
{
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(b, &g_mesh, &g_nodes, v, probe, 1, &dev, 3u), SC_OK);
}

static void expect_as_fresh(const sc_bscan_def *d, const sc_volume *v, const sc_xform *probe)
{
    frame_on(&g_b, v, probe);
    assert_int_equal(sc_bscan_init(&g_fresh, d), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_fresh, &g_mesh), SC_OK);
    frame_on(&g_fresh, v, probe);
    const sc_bscan_status *a = &g_b.status, *f = &g_fresh.status;
    assert_int_equal(a->areas_valid, 1);
    assert_memory_equal(a->area_rest_mm2, f->area_rest_mm2, sizeof a->area_rest_mm2);
    assert_memory_equal(a->area_now_mm2, f->area_now_mm2, sizeof a->area_now_mm2);
    assert_memory_equal(a->area_ratio, f->area_ratio, sizeof a->area_ratio);
}

static void rest_reference_kept_for_a_held_pose_equals_recomputed(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    deform(SCN_DEFORM_DENT, 6.0f, 0);
    const sc_xform probe = scn_probe(20.0f, 10.0f, 10.0f, 0.0f);
    sc_bscan_def d = sc_bscan_default_def();
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    assert_int_equal(g_b.margin_memo.valid, 0);
    expect_as_fresh(&d, &g_vol.v, &probe);
    assert_int_equal(g_b.margin_memo.valid, 1);
    /* the vein reaches above the face: the margin counts some of it */
    const float rest_vein = g_b.status.area_rest_mm2[SC_LABEL_VEIN];
    assert_true(rest_vein > 40.0f);
    expect_as_fresh(&d, &g_vol.v, &probe); /* held: the memo */
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    deform(SCN_DEFORM_DENT, 10.0f, 0); /* pressed deeper under the same pose */
    expect_as_fresh(&d, &g_vol.v, &probe);
    const sc_xform moved = scn_probe(21.0f, 10.0f, 12.0f, 0.0f);
    expect_as_fresh(&d, &g_vol.v, &moved);
    expect_as_fresh(&d, &g_vol.v, &probe);
    /* another volume under the same pose: no vein above the face (its labels there muscle) */
    memcpy(g_vol2.vox, g_vol.vox, sizeof g_vol2.vox);
    memcpy(g_vol2.lab, g_vol.lab, sizeof g_vol2.lab);
    g_vol2.v = g_vol.v;
    g_vol2.v.voxels = g_vol2.vox;
    g_vol2.v.labels = g_vol2.lab;
    uint32_t changed = 0;
    for (uint32_t k = 0; k < SCN_NZ; k++) {
        const float z = g_vol.v.origin_mm[2] + (float)k * g_vol.v.spacing_mm[2];
        for (uint32_t i = 0; i < SCN_NX * SCN_NY && z < 10.0f; i++) {
            uint8_t *l = &g_vol2.lab[i + SCN_NX * SCN_NY * k];
            if (*l == (uint8_t)SC_LABEL_VEIN) {
                *l = (uint8_t)SC_LABEL_MUSCLE;
                changed++;
            }
        }
    }
    assert_true(changed > 100u);
    expect_as_fresh(&d, &g_vol2.v, &probe);
    assert_true(g_b.status.area_rest_mm2[SC_LABEL_VEIN] < rest_vein - 5.0f);
    expect_as_fresh(&d, &g_vol.v, &probe);
    /* a changed margin (sc_bscan_set_def forgets the memo) */
    d.rest_margin_mm = 0.0f;
    assert_int_equal(sc_bscan_set_def(&g_b, &d), SC_OK);
    assert_int_equal(g_b.margin_memo.valid, 0);
    expect_as_fresh(&d, &g_vol.v, &probe);
    assert_true(g_b.status.area_rest_mm2[SC_LABEL_VEIN] < rest_vein - 5.0f);
}

/* ---- determinism ------------------------------------------------------------------------- */

/* Golden image: fixed scene, deformation and pose. A change of this value is a numerics
 * decision: look at the new image (bench_bscan writes PNGs) before updating it. */
#define GOLDEN_HASH UINT64_C(0xa8d1b8c1b2d8e17d)

static void golden_image_hash_is_stable(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    deform(SCN_DEFORM_DENT, 8.0f, 1);
    const sc_xform probe = scn_probe(19.0f, 10.5f, 7.0f, 4.0f);
    sc_bscan_def d = sc_bscan_default_def();
    render(&d, &probe, 1, g_a);
    const uint64_t h1 = g_disp.hashes[0];
    render(&d, &probe, 1, g_a);
    assert_true(g_disp.hashes[0] == h1); /* identical across runs */
    print_message("golden hash 0x%016llx\n", (unsigned long long)h1);
    assert_true(h1 == GOLDEN_HASH);
    /* every kernel variant this build and CPU have (sc_bscan_kern.h): the same image; with the
     * acoustics on too, and at a pose whose lines run beyond the volume (clamped ends) */
    const sc_simd keep = sc_simd_selected();
    sc_bscan_def da = d;
    da.acoustics = 1u;
    const sc_xform deep = scn_probe(19.0f, 10.5f, 7.0f, 40.0f);
    (void)sc_simd_select(SC_SIMD_GENERIC);
    render(&d, &probe, 1, g_a);
    sc_bscan_status st0 = g_b.status; /* the compression measure (rest labels) too */
    render(&da, &probe, 1, g_a);
    const uint64_t ha = g_disp.hashes[0];
    render(&d, &deep, 1, g_a);
    const uint64_t hd = g_disp.hashes[0];
    uint32_t variants = 0;
    for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
        if (!sc_simd_built((sc_simd)v) || v > (int)sc_cpu_best_simd()) {
            continue;
        }
        assert_int_equal(sc_simd_select((sc_simd)v), SC_OK);
        render(&d, &probe, 1, g_a);
        assert_true(g_disp.hashes[0] == GOLDEN_HASH);
        assert_memory_equal(g_b.status.area_now_mm2, st0.area_now_mm2, sizeof st0.area_now_mm2);
        assert_memory_equal(g_b.status.area_rest_mm2, st0.area_rest_mm2,
                            sizeof st0.area_rest_mm2);
        render(&da, &probe, 1, g_a);
        assert_true(g_disp.hashes[0] == ha);
        render(&d, &deep, 1, g_a);
        assert_true(g_disp.hashes[0] == hd);
        variants++;
    }
    (void)sc_simd_select(keep);
    print_message("golden hash in %u kernel variants\n", variants);
}

/* ---- argument checks --------------------------------------------------------------------- */

static void bad_arguments_are_refused(void **state)
{
    (void)state;
    build_mesh(16, 8, 8);
    sc_bscan_def d = sc_bscan_default_def();
    assert_int_equal(sc_bscan_init(NULL, &d), SC_ERR_INVALID_ARG);
    d.mapper = SC_BSCAN_MAP_COUNT;
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_ERR_RANGE);
    d = sc_bscan_default_def();
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    sc_xform probe = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
    /* mesh not attached */
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &probe, 1, &dev, 1u),
                     SC_ERR_INVALID_ARG);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    probe.r[0] = 2.0f;
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &probe, 1, &dev, 1u),
                     SC_ERR_CASE_TRANSFORM);
    probe = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
    sc_volume bad = g_vol.v;
    bad.spacing_mm[1] = 0.0f;
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &bad, &probe, 1, &dev, 1u),
                     SC_ERR_INVALID_ARG);
    /* no mesh at all: every pixel rigid, still a valid frame */
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, &g_vol.v, &probe, 1, &dev, 2u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
    assert_int_equal(g_b.status.pixels_in_mesh, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(undeformed_mesh_image_equals_rigid_slice_all_mappers),
        cmocka_unit_test(linear_fast_paths_match_oracle_on_deformed_small_mesh),
        cmocka_unit_test(curvilinear_fast_paths_match_oracle_on_deformed_small_mesh),
        cmocka_unit_test(fast_paths_match_oracle_on_deformed_full_mesh),
        cmocka_unit_test(lines_through_inverted_tets_are_walked_by_locating_across_the_fold),
        cmocka_unit_test(plane_tets_from_cell_rows_equal_the_pass_over_every_tet),
        cmocka_unit_test(probe_in_air_gives_dark_image),
        cmocka_unit_test(gain_tgc_and_dynamic_range_follow_the_display_formula),
        cmocka_unit_test(lines_stream_in_order_between_begin_and_end_with_frame_number),
        cmocka_unit_test(squashed_vein_area_drops_while_artery_stays),
        cmocka_unit_test(rest_reference_counts_vessels_pushed_into_view),
        cmocka_unit_test(rest_reference_counts_vessels_far_above_a_deep_face),
        cmocka_unit_test(rest_reference_kept_for_a_held_pose_equals_recomputed),
        cmocka_unit_test(golden_image_hash_is_stable),
        cmocka_unit_test(bad_arguments_are_refused),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
