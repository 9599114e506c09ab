/* test_bscan_folds.c: the walker maps deformed contact frames of the real physics as the oracle
 * does, folds included, without handing lines to the region path (issue 15 item 5).
 *
 * A whole engine on the host simulator loads the built neck-ijv case and the tracker emulator
 * plays the rock script (pressed 8 mm, rocked +-15 degrees about the probe's y axis, 1.05 s: the
 * frame of docs/images' rocked strips, where vertical black/white bars over the IJV showed). At that frame the
 * engine's deformed mesh is imaged three ways: the walker (the engine's default), the oracle
 * (every tet per pixel) and the region path, each through a label image: a copy of the case
 * volume whose voxels are 25 x label, so a pixel's grey level names the rest label it maps to
 * (rounded: trilinear blending at label borders is the same for every mapper where they map to
 * the same rest point).
 *
 * The bars were the walker's: under the pressed, rocked face the skin's boundary triangles lie
 * in the face's plane, so each line's first boundary crossing is at s ~ 0 and its side (entry
 * or exit) a rounding that changes cell by cell; a line whose first crossing came out an exit
 * behind the first pixel was skipped and left unmapped (rigid: the vein drawn open at its rest
 * place), 9 lines in 18 at 256 lines. Before the fix this test saw 231 of 3393 in-mesh pixels
 * differ from the oracle (a run of 26), with 779 pixels left unmapped. (Its former script ran
 * the emulator from clock 0 instead of the rig's start, so frame 60 was not the rocked frame
 * and the test missed them; it blamed the physics' inverted lumen tets.) Inverted tets in the
 * frame are printed: the vein's lumen still turns partly inside out (92 MSDS / 136 FEM).
 *
 * Tolerance: inside a fold a pixel lies in several tets (the fold's layers) and the mappers may
 * choose differently by design (sc_bscan.h: the oracle the deepest tet, the walker the layer it
 * walks); elsewhere they agree up to ties on faces. The test allows at most 0.5 % of the in-mesh
 * pixels of a frame to differ and no line a stretch of more than 4 consecutive differing samples
 * (1.25 mm at 96 samples over 30 mm; a tie on a face is 1 sample, a mapper disagreement over a
 * vessel tens), and asks that the walker hands no line to the region path.
 */
#include "sc_test.h"

#include <stdlib.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_hs_rig.h"
#include "sc_storage_linux.h"
#include "sc_trkemu.h"

#define LINES   48u
#define SAMPLES 96u

static sc_hs_rig g_rig;
static sc_emu g_emu;
static uint64_t g_t0; /* the rig's clock when the emulator started */
static sc_storage_linux g_storage;
static uint8_t *g_label_vox;
static uint8_t g_img[3][LINES * SAMPLES];

static int send_peer(void *ctx, const sc_can_frame *f)
{
    return sc_can_send((const sc_can_dev *)ctx, f);
}

static void rig_up(sc_tissue_method method)
{
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0;
    def.tissue.method = method;
    def.bscan.scan.lines_n = LINES;
    def.bscan.scan.samples_n = SAMPLES;
    def.bscan.scan.depth_mm = 30.0f;
    assert_int_equal(sc_hs_rig_init(&g_rig, &def, 3u, 0), SC_OK);
    sc_storage_linux_init(&g_storage, SC_BINARY_DIR "/cases");
    g_rig.hal.storage = sc_storage_linux_dev(&g_storage);
    assert_int_equal(sc_engine_load_case(&g_rig.engine, "neck-ijv.scase"), SC_OK);
    const sc_case *cs = sc_engine_get_case(&g_rig.engine);
    sc_emu_def ed = sc_emu_default_def();
    ed.script = SC_EMU_ROCK;
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_xform_apply(&v2t, p_vol, ed.point_mm);
    ed.depth_mm = 8.0f; /* sc-hostsim's default */
    /* as tools/docs-strip.sh's rocked frame (sc-hostsim --script rock --depth 8 --seconds
     * 1.05): the script's largest angle at frame 60 */
    ed.duration_s = 1.05;
    assert_int_equal(sc_emu_init(&g_emu, &ed), SC_OK);
    g_t0 = g_rig.clock.now_ns;
    /* the label image's volume */
    const size_t n = (size_t)cs->volume.dim[0] * cs->volume.dim[1] * cs->volume.dim[2];
    g_label_vox = malloc(n);
    assert_non_null(g_label_vox);
    for (size_t i = 0; i < n; i++) {
        g_label_vox[i] = (uint8_t)(25u * cs->volume.labels[i]);
    }
}

static void run_to(uint32_t frame)
{
    const uint64_t t0 = g_t0;
    while (sc_engine_get_sched(&g_rig.engine)->frames < frame) {
        const uint64_t release = sc_engine_next_release_ns(&g_rig.engine);
        (void)sc_emu_feed(&g_emu, release - t0, send_peer, &g_rig.peer);
        sc_engine_step(&g_rig.engine, NULL);
    }
}

/* The engine's mesh of this frame imaged into the label image with the given mapper. */
static void label_image(uint32_t mapper, uint8_t *out, uint32_t *fallbacks)
{
    sc_engine *e = &g_rig.engine;
    const sc_tissue *t = sc_engine_get_tissue(e);
    const sc_case *cs = sc_engine_get_case(e);
    sc_volume v = cs->volume;
    v.voxels = g_label_vox;
    sc_bscan_def d = e->bscan.def;
    const sc_bscan_def keep = d;
    d.mapper = mapper;
    d.acoustics = 0u;
    d.gain_db = 0.0f;
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        d.tgc_db[i] = 0.0f;
    }
    d.dynamic_range_db = d.volume_range_db; /* the volume's values shown unchanged */
    assert_int_equal(sc_bscan_set_def(&e->bscan, &d), SC_OK);
    const uint32_t fb0 = e->bscan.status.line_fallbacks;
    const sc_display_dev *dev = &g_rig.hal.display;
    assert_int_equal(sc_bscan_frame(&e->bscan, &t->mesh, &t->nodes, &v,
                                    &sc_engine_get_probe(e)->to_volume, 1, dev, 900000u + mapper),
                     SC_OK);
    *fallbacks = e->bscan.status.line_fallbacks - fb0;
    memcpy(out, g_rig.display.last, LINES * SAMPLES);
    assert_int_equal(sc_bscan_set_def(&e->bscan, &keep), SC_OK);
}

/* Tets of the deformed mesh turned inside out (negative volume), and how many of them carry
 * the vein's label at rest (the vein's lumen turned inside out by the press). */
static uint32_t inverted_tets(uint32_t *vein)
{
    const sc_tissue *t = sc_engine_get_tissue(&g_rig.engine);
    const sc_case *cs = sc_engine_get_case(&g_rig.engine);
    uint32_t n = 0;
    *vein = 0;
    for (uint32_t i = 0; i < t->mesh.tet_count; i++) {
        const uint32_t *tv = t->mesh.tet[i];
        float e[3][3];
        for (uint32_t j = 0; j < 3u; j++) {
            e[j][0] = t->nodes.x[tv[j + 1u]] - t->nodes.x[tv[0]];
            e[j][1] = t->nodes.y[tv[j + 1u]] - t->nodes.y[tv[0]];
            e[j][2] = t->nodes.z[tv[j + 1u]] - t->nodes.z[tv[0]];
        }
        const float det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                          e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        if (det < 0.0f) {
            n++;
            float c[3] = {0.0f, 0.0f, 0.0f};
            for (uint32_t j = 0; j < 4u; j++) {
                c[0] += 0.25f * t->mesh.rest_x[tv[j]];
                c[1] += 0.25f * t->mesh.rest_y[tv[j]];
                c[2] += 0.25f * t->mesh.rest_z[tv[j]];
            }
            const sc_volume *v = &cs->volume;
            int32_t ix[3];
            for (uint32_t d = 0; d < 3u; d++) {
                ix[d] = (int32_t)((c[d] - v->origin_mm[d]) / v->spacing_mm[d] + 0.5f);
                ix[d] =
                    ix[d] < 0 ? 0 : (ix[d] >= (int32_t)v->dim[d] ? (int32_t)v->dim[d] - 1 : ix[d]);
            }
            const size_t vi =
                (size_t)ix[0] +
                (size_t)v->dim[0] * ((size_t)ix[1] + (size_t)v->dim[1] * (size_t)ix[2]);
            *vein += v->labels[vi] == SC_LABEL_VEIN;
        }
    }
    return n;
}

static uint32_t label_of(uint8_t grey)
{
    return ((uint32_t)grey + 12u) / 25u;
}

/* Pixels whose labels differ, the longest stretch of them on a line. */
static uint32_t compare(const uint8_t *a, const uint8_t *b, uint32_t *longest)
{
    uint32_t diff = 0;
    *longest = 0;
    for (uint32_t l = 0; l < LINES; l++) {
        uint32_t run = 0;
        for (uint32_t k = 0; k < SAMPLES; k++) {
            const size_t i = (size_t)l * SAMPLES + k;
            if (label_of(a[i]) != label_of(b[i])) {
                diff++;
                run++;
                *longest = run > *longest ? run : *longest;
            } else {
                run = 0;
            }
        }
    }
    return diff;
}

static void check_method(sc_tissue_method method)
{
    rig_up(method);
    static const uint32_t frames[] = {60u}; /* the frame of the bars */
    for (size_t f = 0; f < sizeof frames / sizeof frames[0]; f++) {
        run_to(frames[f]);
        sc_engine_status st;
        sc_engine_get_status(&g_rig.engine, &st);
        assert_int_equal(st.probe_contact, 1);
        uint32_t fb_walk = 0, fb = 0;
        label_image(SC_BSCAN_MAP_WALK, g_img[0], &fb_walk);
        const uint32_t in_mesh = g_rig.engine.bscan.status.pixels_in_mesh;
        const uint32_t relocations = g_rig.engine.bscan.status.walk_relocations;
        label_image(SC_BSCAN_MAP_ORACLE, g_img[1], &fb);
        label_image(SC_BSCAN_MAP_REGIONS, g_img[2], &fb);
        uint32_t run_w = 0, run_r = 0;
        const uint32_t dw = compare(g_img[0], g_img[1], &run_w);
        const uint32_t dr = compare(g_img[2], g_img[1], &run_r);
        uint32_t inv_vein = 0;
        const uint32_t inv = inverted_tets(&inv_vein);
        print_message("%s frame %u: %u tets inverted (%u of the vein), in mesh %u px, walker vs "
                      "oracle %u px (longest %u), regions vs "
                      "oracle %u px (longest %u), walker fallbacks %u, relocations so far %u\n",
                      method == SC_TISSUE_FEM ? "FEM" : "MSDS", frames[f], inv, inv_vein, in_mesh,
                      dw, run_w, dr, run_r, fb_walk, relocations);
        assert_true(in_mesh > LINES * SAMPLES / 4u);
        assert_int_equal(fb_walk, 0);
        assert_true(dw * 200u <= in_mesh);
        assert_true(run_w <= 4u);
        assert_true(dr * 200u <= in_mesh);
        assert_true(run_r <= 4u);
    }
    free(g_label_vox);
    g_label_vox = NULL;
}

static void msds_rocked_press_walker_matches_oracle_labels_through_folds(void **state)
{
    (void)state;
    check_method(SC_TISSUE_MSDS);
}

static void fem_rocked_press_walker_matches_oracle_labels_through_folds(void **state)
{
    (void)state;
    check_method(SC_TISSUE_FEM);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(msds_rocked_press_walker_matches_oracle_labels_through_folds),
        cmocka_unit_test(fem_rocked_press_walker_matches_oracle_labels_through_folds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
