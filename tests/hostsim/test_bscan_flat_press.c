/*
 * test_bscan_flat_press.c: no U-bend. The probe presses flat 16 mm into each phantom case
 * (whole engine on the host simulator, MSDS) and holds; the held frame is imaged again with the
 * engine's deformed mesh, and every scan line's labels are read (a line hook). Under a flat
 * face the skin stays a flat layer under it across the whole 38 mm image: every line starts in
 * skin (the first sample whose rest label is skin lies within 1 mm of the face) and the skin's
 * lower edge lies at the same depth on every line (spread at most 1 mm). With the former 30 mm
 * mesh box the image's edge lines lay beyond the mesh, imaged undeformed tissue 16 mm below the
 * skin, and had no skin at all (the U of the issue).
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_storage_linux.h"
#include "sc_test_press.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_storage_linux storage;
static sc_bscan g_b;
static sc_hs_display g_disp;
static sc_emu_row rows[8];

#define PRESS_MM 16.0f

typedef struct skin_lines {
    uint32_t lines;
    int32_t first_k[SC_MAX_SCAN_LINES]; /* first skin sample, -1 none */
    int32_t last_k[SC_MAX_SCAN_LINES];  /* last skin sample of that first run */
    float sample_mm;
} skin_lines;
static skin_lines g_sk;

static void skin_hook(void *ctx, const sc_bscan_line_view *v)
{
    skin_lines *s = ctx;
    int32_t first = -1, last = -1;
    for (uint32_t k = 0; k < v->samples_n; k++) {
        if (v->labels[k] == SC_LABEL_SKIN) {
            if (first < 0) {
                first = (int32_t)k;
            }
            last = (int32_t)k;
        } else if (first >= 0) {
            break;
        }
    }
    s->first_k[v->line] = first;
    s->last_k[v->line] = last;
    s->lines = v->lines_n;
}

static void press_and_check(const char *case_file)
{
    sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", case_file, SC_TISSUE_MSDS);
    const sc_case *cs = &rig.engine.slot.c;
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    float top[3];
    sc_xform_apply(&v2t, p_vol, top);
    sc_emu_def ed = sc_emu_default_def();
    /* hover, ramp to the press in 1 s, hold */
    const double ts[3] = {0.0, 0.3, 1.3};
    const float dz[3] = {-3.0f, -3.0f, PRESS_MM};
    for (int i = 0; i < 3; i++) {
        sc_emu_row r = {ts[i], {top[0], top[1], top[2] - dz[i]}, {0, 0, 0, 0}, -1.0f};
        memcpy(r.q, ed.base_q, sizeof r.q);
        rows[i] = r;
    }
    rows[3] = rows[2];
    rows[3].t_s = 2.3;
    ed.script = SC_EMU_CSV;
    ed.rows = rows;
    ed.n_rows = 4;
    ed.duration_s = 2.3;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);
    const uint64_t t0 = rig.clock.now_ns;
    int more = 1;
    const uint32_t frames = (uint32_t)(2.0 * rig.engine.def.sched.rate_hz);
    for (uint32_t f = 0; f < frames; f++) {
        sc_test_press_frame(&rig, &emu, t0, &more);
    }
    const sc_probe_in *probe = sc_engine_get_probe(&rig.engine);
    assert_true(probe->tracked);
    /* the held frame, imaged again with the engine's settings and a line hook */
    const sc_tissue *t = sc_test_press_tissue(&rig);
    assert_int_equal(sc_bscan_init(&g_b, &rig.engine.bscan.def), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &t->mesh), SC_OK);
    memset(&g_sk, 0, sizeof g_sk);
    g_sk.sample_mm = g_b.geom.sample_mm;
    sc_bscan_set_line_hook(&g_b, skin_hook, &g_sk);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, &t->mesh, &t->nodes, &cs->volume, &probe->to_volume, 1,
                                    &dev, 1u),
                     SC_OK);
    assert_int_equal(g_sk.lines, g_b.def.scan.lines_n);
    float lo = 1e9f, hi = -1e9f;
    uint32_t no_skin = 0, late = 0;
    for (uint32_t l = 0; l < g_sk.lines; l++) {
        if (g_sk.first_k[l] < 0) {
            no_skin++;
            continue;
        }
        late += (float)g_sk.first_k[l] * g_sk.sample_mm > 1.0f;
        const float bottom = ((float)g_sk.last_k[l] + 1.0f) * g_sk.sample_mm;
        lo = fminf(lo, bottom);
        hi = fmaxf(hi, bottom);
    }
    print_message("%s, %.0f mm press: %u of %u lines without skin, %u starting below 1 mm; skin's "
                  "lower edge %.2f .. %.2f mm\n",
                  case_file, (double)PRESS_MM, no_skin, g_sk.lines, late, (double)lo, (double)hi);
    assert_int_equal(no_skin, 0u);
    assert_int_equal(late, 0u);
    assert_true(hi - lo <= 1.0f);
}

static void neck_press_keeps_the_skin_flat_across_the_image(void **state)
{
    (void)state;
    press_and_check("neck-ijv.scase");
}

static void groin_press_keeps_the_skin_flat_across_the_image(void **state)
{
    (void)state;
    press_and_check("femoral.scase");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(neck_press_keeps_the_skin_flat_across_the_image),
        cmocka_unit_test(groin_press_keeps_the_skin_flat_across_the_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
