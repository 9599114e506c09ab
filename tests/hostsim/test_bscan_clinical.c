/* test_bscan_clinical.c: the B-scan's compression measure on the physics' clinical scene
 * (tests/support/sc_test_tissue_scene.h): a linear probe pressing over a vein and an artery.
 * The soft-tissue facade deforms the mesh (MSDS and FEM), sc_bscan images it; the vein's area
 * in the image must collapse while the artery's stays, as an instructor would check. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_labels.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"

static sc_tissue g_t; /* ~13 MB: static */
static sc_test_scene g_scene;
static sc_bscan g_b;
static sc_hs_display g_disp;

static void init_scene(uint8_t vein_label, sc_tissue_method m)
{
    sc_test_scene_params p = sc_test_scene_default_params();
    p.vein_label = vein_label;
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def d = sc_test_scene_tissue_def(&g_scene, m);
    sc_material_table mat;
    sc_material_table_default(&mat);
    assert_int_equal(sc_tissue_init(&g_t, &d, &g_scene.vol, &mat, SC_LABEL_FAT), SC_OK);
    sc_bscan_def bd = sc_bscan_default_def();
    assert_int_equal(sc_bscan_init(&g_b, &bd), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_t.mesh), SC_OK);
    sc_hs_display_init(&g_disp);
}

static const sc_bscan_status *image(float face_z_mm, uint32_t frame_no)
{
    const sc_pose pose = sc_test_scene_probe(&g_scene, face_z_mm);
    const sc_xform x = sc_xform_from_pose(&pose);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(
        sc_bscan_frame(&g_b, &g_t.mesh, &g_t.nodes, &g_scene.vol, &x, 1, &dev, frame_no), SC_OK);
    assert_int_equal(g_disp.protocol_errors, 0);
    return sc_bscan_status_get(&g_b);
}

/* Press 15 % of the block depth (the physics' clinical test) over 60 frames, hold 30. */
static float press(void)
{
    const float press_mm = 0.15f * g_scene.p.size_mm[2];
    for (int f = 0; f < 90; f++) {
        const float k = f < 60 ? (float)(f + 1) / 60.0f : 1.0f;
        const sc_pose pose = sc_test_scene_probe(&g_scene, -0.5f + (press_mm + 0.5f) * k);
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
    }
    return press_mm;
}

static void check(sc_tissue_method m)
{
    init_scene(SC_LABEL_VEIN, m);
    /* at rest, probe on the skin: every area equals its rest area (same pixels) */
    const sc_bscan_status *st = image(0.0f, 1u);
    assert_int_equal(st->areas_valid, 1);
    assert_true(st->area_rest_mm2[SC_LABEL_VEIN] > 20.0f); /* pi 3^2 = 28 mm^2 in view */
    assert_true(st->area_rest_mm2[SC_LABEL_ARTERY] > 20.0f);
    assert_true(fabsf(st->area_ratio[SC_LABEL_VEIN] - 1.0f) < 0.02f);
    assert_true(fabsf(st->area_ratio[SC_LABEL_ARTERY] - 1.0f) < 0.02f);
    const float press_mm = press();
    st = image(press_mm, 2u);
    print_message("%s: vein area %.1f of %.1f mm^2 (%.2f), artery %.1f of %.1f mm^2 (%.2f)\n",
                  m == SC_TISSUE_MSDS ? "MSDS" : "FEM", (double)st->area_now_mm2[SC_LABEL_VEIN],
                  (double)st->area_rest_mm2[SC_LABEL_VEIN], (double)st->area_ratio[SC_LABEL_VEIN],
                  (double)st->area_now_mm2[SC_LABEL_ARTERY],
                  (double)st->area_rest_mm2[SC_LABEL_ARTERY],
                  (double)st->area_ratio[SC_LABEL_ARTERY]);
    print_message("  in mesh %u px, walk aborts %u, line fallbacks %u, event overflows %u\n",
                  st->pixels_in_mesh, st->walk_aborts, st->line_fallbacks, st->event_overflows);
    {
        /* the walker against the oracle on this physics frame (smaller image) */
        static uint8_t img_w[64 * 128], img_o[64 * 128];
        sc_bscan_def d = sc_bscan_default_def();
        d.scan.lines_n = 64;
        d.scan.samples_n = 128;
        for (int mp = 0; mp < 2; mp++) {
            d.mapper = mp ? SC_BSCAN_MAP_ORACLE : SC_BSCAN_MAP_WALK;
            assert_int_equal(sc_bscan_set_def(&g_b, &d), SC_OK);
            (void)image(press_mm, 3u + (uint32_t)mp);
            memcpy(mp ? img_o : img_w, g_disp.last, sizeof img_w);
            print_message("  mapper %d: vein ratio %.2f in mesh %u\n", mp,
                          (double)g_b.status.area_ratio[SC_LABEL_VEIN], g_b.status.pixels_in_mesh);
        }
        uint32_t diff = 0;
        for (size_t i = 0; i < sizeof img_w; i++) {
            diff += img_w[i] != img_o[i];
        }
        print_message("  walker vs oracle: %u of %zu pixels differ\n", diff, sizeof img_w);
        if (m == SC_TISSUE_FEM) {
            /* a mesh without inverted tets: ties on faces only */
            assert_true(diff * 1000u <= sizeof img_w);
        }
        sc_bscan_def d0 = sc_bscan_default_def();
        assert_int_equal(sc_bscan_set_def(&g_b, &d0), SC_OK);
        st = image(press_mm, 5u);
    }
    assert_int_equal(g_b.status.walk_aborts, 0);
    assert_true(st->area_ratio[SC_LABEL_ARTERY] > 0.8f);
    if (m == SC_TISSUE_MSDS) {
        /* the physics' MSDS does not collapse the vein yet (test_sc_tissue.c reports -17 %
         * of its volume at this press, below the brief's -60 %): the image must show that,
         * not more */
        assert_true(st->area_ratio[SC_LABEL_VEIN] < 1.0f);
        return;
    }
    /* the brief's criteria: vein below 0.4 of its rest area, artery above 0.8 */
    assert_true(st->area_ratio[SC_LABEL_VEIN] < 0.4f);
}

static void msds_press_image_shows_partial_vein_compression_artery_above_0_8(void **state)
{
    (void)state;
    check(SC_TISSUE_MSDS);
}

static void fem_press_vein_area_below_0_4_artery_above_0_8_walker_equals_oracle(void **state)
{
    (void)state;
    check(SC_TISSUE_FEM);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(msds_press_image_shows_partial_vein_compression_artery_above_0_8),
        cmocka_unit_test(fem_press_vein_area_below_0_4_artery_above_0_8_walker_equals_oracle),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
