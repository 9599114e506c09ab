/*
 * test_material_cmd.c: CmdMaterial (0x090, MAC 0x098) end to end on the host simulator: the
 * command is signed (sc_cmdsign, as the console and sc-tracker-emu send it) and sent through
 * the simulated bus while the probe presses the neck-ijv phantom (the `cases` target) 6 mm
 * deep, MSDS. Checked:
 *   - the engine rebuilds the running case's tissue with the commanded fat (E 3.5 -> 0.7 kPa)
 *     off the frame path (a switch to the same case through the standby slot, counted in
 *     material_rebuilds), the new tissue's table holds it, the solver parameters too;
 *   - the softer fat deforms more: at the same press depth the tissue pushes back with less
 *     force and the vein beside it is compressed less (the fat takes the press); the same
 *     force takes the probe deeper (measured in 0.5 mm steps);
 *   - CmdReset (tissue) restores the case's own materials by the same rebuild: the image
 *     hashes of the frames after it are those of a fresh load under the same press;
 *   - bad values reach the engine and are refused and counted; a command while the rebuild
 *     runs is refused (busy) and counted; no material command: nothing changes.
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_canproto.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_test_cmd.h"
#include "sc_test_press.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_storage_linux storage;
static sc_emu_row rows[2];
static uint64_t t0;
static int more = 1;

#define PRESS_MM 6.0f
#define SETTLE_FRAMES 90u
#define HASH_FRAMES 40u

static float vein_ratio(void)
{
    const sc_bscan_status *b = sc_bscan_status_get(&rig.engine.bscan);
    return b->areas_valid ? b->area_ratio[SC_LABEL_VEIN] : -1.0f;
}

/* from now on the probe depth_mm into the skin over the middle of the mesh's top */
static void press_at(float depth_mm)
{
    const sc_case *cs = &rig.engine.slot.c;
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_emu_def ed = sc_emu_default_def();
    float top[3];
    sc_xform_apply(&v2t, p_vol, top);
    sc_emu_row r = {0.0, {top[0], top[1], top[2] - depth_mm}, {0, 0, 0, 0}, -1.0f};
    memcpy(r.q, ed.base_q, sizeof r.q);
    rows[0] = r;
    r.t_s = 60.0;
    rows[1] = r;
    ed.script = SC_EMU_CSV;
    ed.rows = rows;
    ed.n_rows = 2u;
    ed.duration_s = 60.0;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);
    t0 = rig.clock.now_ns;
    more = 1;
}

/* the engine on neck-ijv (MSDS), the probe PRESS_MM into the skin for the whole run */
static void rig_up(void)
{
    sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", "neck-ijv.scase",
                         SC_TISSUE_MSDS);
    press_at(PRESS_MM);
}

static void run(uint32_t frames)
{
    for (uint32_t f = 0; f < frames; f++) {
        sc_test_press_frame(&rig, &emu, t0, &more);
        assert_true(sc_test_press_state_finite(&rig));
    }
}

static uint64_t last_hash(void)
{
    assert_true(rig.display.hash_count > 0u);
    const uint32_t i = rig.display.hash_count - 1u;
    return rig.display.hashes[i < SC_HS_DISPLAY_HISTORY ? i : SC_HS_DISPLAY_HISTORY - 1u];
}

/* runs frames until the rebuild's swap (at most 600), returns the frames run */
static uint32_t run_until_rebuilt(uint64_t rebuilds_before)
{
    uint32_t n = 0;
    while (rig.engine.counters.material_rebuilds == rebuilds_before && n < 600u) {
        run(1u);
        n++;
    }
    assert_true(rig.engine.counters.material_rebuilds == rebuilds_before + 1u);
    return n;
}

/* sends the signed command and runs one frame: applied (1) or refused (-1), 0 neither */
static int send(const sc_cmd *c)
{
    const uint64_t applied = rig.engine.counters.commands_applied;
    const uint64_t refused = rig.engine.counters.commands_refused;
    assert_int_equal(sc_test_send_cmd(&rig.peer, c), SC_OK);
    run(1u);
    const int a = (int)(rig.engine.counters.commands_applied - applied);
    const int r = (int)(rig.engine.counters.commands_refused - refused);
    assert_true(a + r <= 1);
    return a == 1 ? 1 : r == 1 ? -1 : 0;
}

static sc_cmd material(uint8_t label, float e_kpa, float nu)
{
    sc_cmd c = {.kind = SC_CMD_MATERIAL};
    c.material = (sc_material_cmd){.label = label, .cg_iterations = 10u, .corotated = 0u,
                                   .e_kpa = e_kpa, .poisson = nu, .damping_s = 0.1f};
    return c;
}

static uint64_t fresh_hashes[HASH_FRAMES];

static void softer_fat_deforms_more_and_reset_restores_the_hashes(void **state)
{
    (void)state;
    /* the reference: a fresh load under the press, its first frames' hashes */
    rig_up();
    for (uint32_t f = 0; f < HASH_FRAMES; f++) {
        run(1u);
        fresh_hashes[f] = last_hash();
    }
    run(SETTLE_FRAMES - HASH_FRAMES);
    const float vein_own = vein_ratio();
    const float force_own = sc_tissue_probe_force_n(sc_test_press_tissue(&rig), NULL);
    const float dev_own = sc_test_press_max_dev_mm(&rig);
    assert_true(vein_own > 0.0f && force_own > 0.0f);
    assert_int_equal(rig.engine.counters.material_rebuilds, 0u);
    assert_int_equal(sc_engine_get_material(&rig.engine)->label_mask, 0u);

    /* fat five times softer */
    const uint64_t loads = rig.engine.counters.case_loads;
    const sc_cmd soft = material(SC_LABEL_FAT, 0.7f, 0.45f);
    assert_int_equal(send(&soft), 1);
    const uint32_t took = run_until_rebuilt(0u);
    assert_int_equal(rig.engine.counters.case_loads, loads + 1u);
    const sc_tissue *t = sc_test_press_tissue(&rig);
    assert_float_equal(t->mat.row[SC_LABEL_FAT].e_pa, 700.0f, 0.5f);
    assert_float_equal(t->mat.row[SC_LABEL_MUSCLE].e_pa, 15.0e3f, 0.5f); /* the case's own */
    assert_int_equal(t->fem.def.cg_iterations, 10u);
    assert_float_equal(t->msds.gamma_per_k_s, 0.1f, 1e-6f);
    assert_int_equal(sc_engine_get_material(&rig.engine)->label_mask, 1u << SC_LABEL_FAT);
    assert_int_equal(rig.engine.sched.misses, 0u);
    run(SETTLE_FRAMES);
    const float vein_soft = vein_ratio();
    const float force_soft = sc_tissue_probe_force_n(sc_test_press_tissue(&rig), NULL);
    const float dev_soft = sc_test_press_max_dev_mm(&rig);
    print_message("fat 3.5 kPa: vein ratio %.3f, force %.2f N, max node displacement %.2f mm\n"
                  "fat 0.7 kPa: vein ratio %.3f, force %.2f N, max node displacement %.2f mm "
                  "(rebuilt in %u frames)\n",
                  (double)vein_own, (double)force_own, (double)dev_own, (double)vein_soft,
                  (double)force_soft, (double)dev_soft, took);
    assert_true(force_soft < 0.8f * force_own);
    assert_true(vein_soft > vein_own + 0.02f);
    /* the same press (force): the soft fat lets the probe in deeper; 0.5 mm steps */
    float depth_same_force = 0.0f, force_there = 0.0f;
    for (int step = 1; step <= 12 && !(force_there >= force_own); step++) {
        depth_same_force = PRESS_MM + 0.5f * (float)step;
        press_at(depth_same_force);
        run(60u);
        force_there = sc_tissue_probe_force_n(sc_test_press_tissue(&rig), NULL);
    }
    assert_true(force_there >= force_own);
    print_message("fat 0.7 kPa: the 3.5 kPa fat's force at %.1f mm (%.2f N) is reached at %.1f mm "
                  "(%.2f N)\n",
                  (double)PRESS_MM, (double)force_own, (double)depth_same_force,
                  (double)force_there);
    assert_true(depth_same_force >= PRESS_MM + 1.0f);
    press_at(PRESS_MM);
    run(60u);

    /* reset (tissue): the case's own materials, rebuilt; the frames after the swap are those
     * of the fresh load, hash for hash */
    sc_cmd reset = {.kind = SC_CMD_RESET, .reset_target = SC_RESET_TISSUE};
    assert_int_equal(send(&reset), 1);
    (void)run_until_rebuilt(1u);
    assert_int_equal(sc_engine_get_material(&rig.engine)->label_mask, 0u);
    assert_float_equal(sc_test_press_tissue(&rig)->mat.row[SC_LABEL_FAT].e_pa, 3.5e3f, 0.5f);
    for (uint32_t f = 0; f < HASH_FRAMES; f++) {
        run(1u);
        assert_true(last_hash() == fresh_hashes[f]);
    }
    /* a reset without overrides in force rebuilds nothing */
    assert_int_equal(send(&reset), 1);
    run(30u);
    assert_int_equal(rig.engine.counters.material_rebuilds, 2u);
    assert_int_equal(rig.engine.counters.phys_resets, 0u);
}

static void bad_values_and_a_busy_engine_are_refused_and_counted(void **state)
{
    (void)state;
    rig_up();
    run(10u);
    /* the codec refuses what the DBC cannot carry; the engine what the case cannot take */
    sc_engine_material before = *sc_engine_get_material(&rig.engine);
    const sc_material_cmd bad[] = {
        {0u, 10u, 0u, 3.5f, 0.45f, 0.1f},   /* outside */
        {8u, 10u, 0u, 3.5f, 0.45f, 0.1f},   /* bone */
        {2u, 0u, 0u, 3.5f, 0.45f, 0.1f},    /* no iterations */
        {2u, 10u, 2u, 3.5f, 0.45f, 0.1f},   /* corotated 2 */
        {2u, 10u, 0u, 0.0f, 0.45f, 0.1f},   /* E 0 */
        {2u, 10u, 0u, 3.5f, 0.5f, 0.1f},    /* nu 0.5 */
        {2u, 10u, 0u, 3.5f, 0.45f, 0.6f},   /* damping */
        {2u, 10u, 0u, NAN, 0.45f, 0.1f},
    };
    const uint64_t refused = rig.engine.counters.material_refused;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(sc_engine_set_material(&rig.engine, &bad[i]),
                         i == 7u ? SC_ERR_NOT_FINITE : SC_ERR_RANGE);
    }
    assert_int_equal(rig.engine.counters.material_refused, refused + 8u);
    assert_memory_equal(sc_engine_get_material(&rig.engine), &before, sizeof before);
    assert_int_equal(rig.engine.sw.phase, SC_SWITCH_IDLE);
    /* (on the bus the codec refuses them first: test_sc_canproto) */
    sc_cmd ok = material(SC_LABEL_MUSCLE, 30.0f, 0.45f);
    ok.material.cg_iterations = 20u; /* the solver's parameters too */
    ok.material.damping_s = 0.2f;
    ok.material.corotated = 1u;
    assert_int_equal(send(&ok), 1);
    /* while its rebuild runs another one is refused (busy), counted */
    const uint64_t cmd_refused = rig.engine.counters.commands_refused;
    sc_cmd again = material(SC_LABEL_FAT, 1.0f, 0.45f);
    assert_int_equal(send(&again), -1);
    assert_int_equal(rig.engine.counters.commands_refused, cmd_refused + 1u);
    assert_int_equal(rig.engine.counters.material_refused, refused + 9u);
    (void)run_until_rebuilt(0u);
    assert_float_equal(sc_test_press_tissue(&rig)->mat.row[SC_LABEL_MUSCLE].e_pa, 30.0e3f, 1.0f);
    assert_float_equal(sc_test_press_tissue(&rig)->mat.row[SC_LABEL_FAT].e_pa, 3.5e3f, 0.5f);
    assert_int_equal(sc_test_press_tissue(&rig)->fem.def.cg_iterations, 20u);
    assert_int_equal(sc_test_press_tissue(&rig)->fem.def.corotated, 1u);
    assert_float_equal(sc_test_press_tissue(&rig)->fem.def.rayleigh_beta_s, 0.2f, 1e-3f);
    assert_float_equal(sc_test_press_tissue(&rig)->msds.gamma_per_k_s, 0.2f, 1e-3f);
    run(60u);
    assert_int_equal(rig.engine.counters.phys_resets, 0u);
    /* a case switch restores the case's own */
    assert_int_equal(sc_engine_select_case(&rig.engine, "neck-ijv.scase"), SC_OK);
    uint32_t n = 0;
    const uint64_t loads = rig.engine.counters.case_loads;
    while (rig.engine.counters.case_loads == loads && n++ < 600u) {
        run(1u);
    }
    assert_int_equal(rig.engine.counters.case_loads, loads + 1u);
    assert_int_equal(sc_engine_get_material(&rig.engine)->label_mask, 0u);
    assert_float_equal(sc_test_press_tissue(&rig)->mat.row[SC_LABEL_MUSCLE].e_pa, 15.0e3f, 0.5f);
    assert_int_equal(sc_test_press_tissue(&rig)->fem.def.cg_iterations,
                     rig.engine.def.tissue.fem.cg_iterations);
    assert_float_equal(sc_test_press_tissue(&rig)->msds.gamma_per_k_s, 0.1f, 1e-6f);
    assert_int_equal(rig.engine.counters.material_rebuilds, 1u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(softer_fat_deforms_more_and_reset_restores_the_hashes),
        cmocka_unit_test(bad_values_and_a_busy_engine_are_refused_and_counted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
