/* test_sc_needle.c: the tracked needle: its CAN receiver (E2E, assembly, plausibility), its
 * drawing in the B-scan (in plane a line on the geometric track, out of plane a dot) and its
 * puncture reports (each lumen entry once, arteries flagged). */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_canproto.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_needle.h"
#include "sc_needle_rx.h"
#include "sc_trkemu.h"

#define VSP 0.5f
#define VNX 100u /* x -10 .. 40 */
#define VNY 40u  /* y -10 .. 10 */
#define VNZ 100u /* z -5 .. 45 */

static uint8_t g_vox[VNX * VNY * VNZ], g_lab[VNX * VNY * VNZ];
static sc_volume g_vol;
static sc_bscan g_b;
static sc_needle g_n;
static sc_hs_display g_disp;

/* muscle (grey 120, never 255) with a vein along y at x 15, z 20 (r 4) and an artery at x 28,
 * z 20 (r 3) */
static void make_volume(void)
{
    g_vol.dim[0] = VNX;
    g_vol.dim[1] = VNY;
    g_vol.dim[2] = VNZ;
    for (uint32_t a = 0; a < 3u; a++) {
        g_vol.spacing_mm[a] = VSP;
    }
    g_vol.origin_mm[0] = -10.0f;
    g_vol.origin_mm[1] = -10.0f;
    g_vol.origin_mm[2] = -5.0f;
    g_vol.voxels = g_vox;
    g_vol.labels = g_lab;
    for (uint32_t k = 0; k < VNZ; k++) {
        for (uint32_t j = 0; j < VNY; j++) {
            for (uint32_t i = 0; i < VNX; i++) {
                const size_t idx = i + VNX * (j + (size_t)VNY * k);
                const float x = -10.0f + (float)i * VSP, z = -5.0f + (float)k * VSP;
                uint8_t lab = SC_LABEL_MUSCLE;
                if (z < 0.0f) {
                    lab = SC_LABEL_OUTSIDE;
                } else if (hypotf(x - 15.0f, z - 20.0f) < 4.0f) {
                    lab = SC_LABEL_VEIN;
                } else if (hypotf(x - 28.0f, z - 20.0f) < 3.0f) {
                    lab = SC_LABEL_ARTERY;
                }
                g_lab[idx] = lab;
                g_vox[idx] = lab == SC_LABEL_MUSCLE ? 120u : (lab == SC_LABEL_OUTSIDE ? 0u : 20u);
            }
        }
    }
}

static void hook(void *ctx, const sc_bscan_line_view *v)
{
    sc_needle_line(ctx, v);
}

static sc_bscan_def scan_def(void)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.scan.depth_mm = 40.0f;
    return d;
}

/* One frame with the probe at (15, 0, 0) (image x = volume x - 15, z = volume z). */
static int frame(uint32_t fno)
{
    const sc_xform probe = {.r = {1, 0, 0, 0, 1, 0, 0, 0, 1}, .t_mm = {15.0f, 0.0f, 0.0f}};
    const sc_bscan_def bd = scan_def();
    const sc_xform img2vol = sc_xform_compose(&probe, &bd.scan.image_to_probe);
    sc_needle_frame_begin(&g_n, &img2vol);
    sc_bscan_set_line_hook(&g_b, hook, &g_n);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, &g_vol, &probe, 1, &dev, fno), SC_OK);
    return sc_needle_frame_end(&g_n, &g_vol);
}

static void setup_scene(void)
{
    make_volume();
    const sc_bscan_def bd = scan_def();
    assert_int_equal(sc_bscan_init(&g_b, &bd), SC_OK);
    const sc_needle_def nd = sc_needle_default_def();
    assert_int_equal(sc_needle_init(&g_n, &nd), SC_OK);
    sc_hs_display_init(&g_disp);
}

static void in_plane_needle_is_a_line_on_its_track(void **state)
{
    (void)state;
    setup_scene();
    /* entry at volume (5, 0, 0), 30 degrees below the horizontal, 20 mm inserted */
    const float c = cosf(30.0f * 3.14159265f / 180.0f), s = sinf(30.0f * 3.14159265f / 180.0f);
    const float dir[3] = {c, 0.0f, s};
    const float tip[3] = {5.0f + 20.0f * c, 0.0f, 20.0f * s};
    sc_needle_set(&g_n, 1, tip, dir, 20.0f);
    (void)frame(1u);
    assert_true(g_n.status.in_plane);
    assert_true(g_n.status.drawn_pixels > 200u);
    const uint32_t lines = g_b.def.scan.lines_n, n = g_b.def.scan.samples_n;
    const float pitch = g_b.geom.line_pitch, smm = g_b.geom.sample_mm;
    uint32_t checked = 0;
    for (uint32_t l = 0; l < lines; l++) {
        const float xi = g_b.geom.start_x_mm[l]; /* image x */
        const float xv = xi + 15.0f;
        if (xv < 6.0f || xv > tip[0] - 1.0f) {
            continue; /* away from the ends */
        }
        /* centre of the 255 run nearest the shaft: the line's samples through the shaft */
        const float z_expect = (xv - 5.0f) * s / c;
        uint32_t k_first = n, k_last = 0;
        for (uint32_t k = 0; k < n; k++) {
            if (g_disp.last[(size_t)l * n + k] == 255u) {
                k_first = k < k_first ? k : k_first;
                k_last = k;
                if (k + 1u < n && g_disp.last[(size_t)l * n + k + 1u] != 255u) {
                    break; /* first run only: the echoes below are dimmer anyway */
                }
            }
        }
        assert_true(k_first < n);
        const float z_mid = g_b.geom.start_z_mm[l] + 0.5f * (float)(k_first + k_last) * smm;
        /* within a pixel (the larger of the line pitch and the sample pitch) */
        assert_true(fabsf(z_mid - z_expect) <= fmaxf(pitch, smm) + 1e-3f);
        checked++;
    }
    assert_true(checked > 50u);
    /* reverberation: dimmer echoes below the shaft, at its spacing */
    const uint32_t l = lines / 2u;
    const float xv = g_b.geom.start_x_mm[l] + 15.0f;
    const float z_echo = (xv - 5.0f) * s / c + 1.0f;
    const uint32_t k_echo = (uint32_t)((z_echo - g_b.geom.start_z_mm[l]) / smm + 0.5f);
    const uint8_t e = g_disp.last[(size_t)l * n + k_echo];
    /* 255 x 0.55 x cos 30 degrees (the shaft's share across the beam) = 121 */
    print_message("first echo %u\n", e);
    assert_true(e >= 115u && e <= 128u);
}

static void out_of_plane_needle_is_a_dot(void **state)
{
    (void)state;
    setup_scene();
    /* along y through the plane at volume (12, 0, 10) */
    const float dir[3] = {0.0f, 1.0f, 0.0f};
    const float tip[3] = {12.0f, 5.0f, 10.0f};
    sc_needle_set(&g_n, 1, tip, dir, 15.0f);
    (void)frame(1u);
    assert_false(g_n.status.in_plane);
    const uint32_t lines = g_b.def.scan.lines_n, n = g_b.def.scan.samples_n;
    float xmin = 1e9f, xmax = -1e9f, zmin = 1e9f, zmax = -1e9f;
    uint32_t cnt = 0;
    for (uint32_t l = 0; l < lines; l++) {
        for (uint32_t k = 0; k < n; k++) {
            if (g_disp.last[(size_t)l * n + k] == 255u) {
                const float x = g_b.geom.start_x_mm[l] + 15.0f;
                const float z = g_b.geom.start_z_mm[l] + (float)k * g_b.geom.sample_mm;
                xmin = fminf(xmin, x);
                xmax = fmaxf(xmax, x);
                zmin = fminf(zmin, z);
                zmax = fmaxf(zmax, z);
                cnt++;
            }
        }
    }
    assert_true(cnt > 10u);
    /* a dot of the shaft's diameter around (12, 10) */
    assert_true(xmax - xmin < 1.5f && zmax - zmin < 1.5f);
    assert_true(fabsf(0.5f * (xmin + xmax) - 12.0f) < 0.3f);
    assert_true(fabsf(0.5f * (zmin + zmax) - 10.0f) < 0.3f);
    /* no needle: nothing drawn */
    sc_needle_set(&g_n, 0, NULL, NULL, 0.0f);
    (void)frame(2u);
    assert_int_equal(g_n.status.drawn_pixels, 0u);
}

static void a_vein_puncture_is_reported_once(void **state)
{
    (void)state;
    setup_scene();
    /* in plane, straight down at x 15 into the vein (z 16 .. 24), 0.5 mm per frame */
    const float dir[3] = {0.0f, 0.0f, 1.0f};
    int entries = 0;
    for (uint32_t f = 0; f < 44u; f++) {
        const float depth = 2.0f + 0.5f * (float)f; /* tip to z 23.5: inside the vein */
        const float tip[3] = {15.0f, 0.0f, depth};
        sc_needle_set(&g_n, 1, tip, dir, depth);
        entries += frame(f);
    }
    assert_int_equal(entries, 1);
    assert_int_equal(g_n.status.vein_punctures, 1u);
    assert_int_equal(g_n.status.artery_punctures, 0u);
    assert_int_equal(g_n.status.last_puncture, SC_LABEL_VEIN);
    assert_int_equal(g_n.status.tip_label, SC_LABEL_VEIN);
    assert_int_equal(g_n.status.tip_label_deformed, 1u); /* read from the scan line */
    /* held inside: still one */
    for (uint32_t f = 0; f < 10u; f++) {
        entries += frame(100u + f);
    }
    assert_int_equal(entries, 1);
    /* withdrawn and in again: a second entry */
    const float out_tip[3] = {15.0f, 0.0f, 10.0f}, in_tip[3] = {15.0f, 0.0f, 20.0f};
    sc_needle_set(&g_n, 1, out_tip, dir, 10.0f);
    entries += frame(200u);
    sc_needle_set(&g_n, 1, in_tip, dir, 20.0f);
    entries += frame(201u);
    assert_int_equal(entries, 2);
    assert_int_equal(g_n.status.vein_punctures, 2u);
}

static void an_artery_puncture_is_flagged(void **state)
{
    (void)state;
    setup_scene();
    const float dir[3] = {0.0f, 0.0f, 1.0f};
    const float tip[3] = {28.0f, 0.0f, 20.0f};
    sc_needle_set(&g_n, 1, tip, dir, 20.0f);
    assert_int_equal(frame(1u), 1);
    assert_int_equal(g_n.status.artery_punctures, 1u);
    assert_int_equal(g_n.status.vein_punctures, 0u);
    assert_int_equal(g_n.status.last_puncture, SC_LABEL_ARTERY);
    /* out of the slab: the label map decides (rigid) */
    const float tip2[3] = {15.0f, 3.0f, 20.0f}, dir2[3] = {0.0f, 0.0f, 1.0f};
    sc_needle_set(&g_n, 1, tip2, dir2, 20.0f);
    assert_int_equal(frame(2u), 1);
    assert_int_equal(g_n.status.tip_label_deformed, 0u);
    assert_int_equal(g_n.status.vein_punctures, 1u);
}

static void needle_image_is_deterministic(void **state)
{
    (void)state;
    uint64_t h[2];
    for (int r = 0; r < 2; r++) {
        setup_scene();
        const float dir[3] = {0.8f, 0.0f, 0.6f};
        const float tip[3] = {20.0f, 0.0f, 15.0f};
        sc_needle_set(&g_n, 1, tip, dir, 25.0f);
        (void)frame(5u);
        h[r] = sc_hs_hash64(g_disp.last, sizeof g_disp.last, 7u);
    }
    assert_true(h[0] == h[1]);
}

/* ---- the CAN receiver ---------------------------------------------------------------------- */

static sc_needle_rx g_rx;

static void send(const sc_needle_msg *m, uint8_t counter, uint64_t t_ns, sc_needle_outcome last)
{
    sc_can_frame f[3];
    size_t nf = 0;
    assert_int_equal(sc_canproto_encode_needle(m, counter, f, 3u, &nf), SC_OK);
    assert_int_equal(nf, 3u);
    for (size_t i = 0; i < nf; i++) {
        const sc_needle_outcome o = sc_needle_rx_on_frame(&g_rx, &f[i], t_ns);
        assert_int_equal(o, i + 1u < nf ? SC_NEEDLE_PART : last);
    }
}

static void needle_frames_assemble_and_bad_ones_are_refused_and_counted(void **state)
{
    (void)state;
    const sc_needle_rx_def def = sc_needle_rx_default_def();
    assert_int_equal(sc_needle_rx_init(&g_rx, &def), SC_OK);
    sc_needle_msg m = {.tip_mm = {10.0f, -5.0f, 30.0f}, .dir = {0.0f, 0.6f, 0.8f},
                       .depth_mm = 25.0f, .tracking = SC_TRACKING_OK};
    uint64_t t = 1000000000u;
    send(&m, 0u, t, SC_NEEDLE_ACCEPTED);
    sc_needle_sample smp;
    assert_int_equal(sc_needle_rx_poll(&g_rx, t, &smp), 1);
    assert_true(fabsf(smp.tip_mm[2] - 30.0f) <= 0.025f);
    assert_true(fabsf(smp.depth_mm - 25.0f) <= 0.025f);
    assert_true(fabsf(sqrtf(smp.dir[0] * smp.dir[0] + smp.dir[1] * smp.dir[1] +
                            smp.dir[2] * smp.dir[2]) - 1.0f) < 1e-5f);
    /* a corrupted byte: the CRC */
    sc_can_frame f[3];
    size_t nf;
    assert_int_equal(sc_canproto_encode_needle(&m, 1u, f, 3u, &nf), SC_OK);
    f[1].data[4] ^= 0x40u;
    t += 10000000u;
    assert_int_equal(sc_needle_rx_on_frame(&g_rx, &f[0], t), SC_NEEDLE_PART);
    assert_int_equal(sc_needle_rx_on_frame(&g_rx, &f[1], t), SC_NEEDLE_E2E_CRC);
    /* the same counter again on the first part: repeated */
    assert_int_equal(sc_needle_rx_on_frame(&g_rx, &f[0], t), SC_NEEDLE_E2E_REPEATED);
    /* implausible: direction norm 0.5, depth 500 mm, outside the workspace, too fast */
    sc_needle_msg bad = m;
    bad.dir[1] = 0.3f;
    bad.dir[2] = 0.4f;
    t += 10000000u;
    send(&bad, 2u, t, SC_NEEDLE_REJ_DIR_NORM);
    bad = m;
    bad.depth_mm = 500.0f;
    t += 10000000u;
    send(&bad, 3u, t, SC_NEEDLE_REJ_DEPTH);
    bad = m;
    bad.tip_mm[0] = 1500.0f;
    t += 10000000u;
    send(&bad, 4u, t, SC_NEEDLE_REJ_WORKSPACE);
    bad = m;
    bad.tip_mm[0] = 200.0f; /* 190 mm in the 60 ms since the last accepted sample */
    t += 10000000u;
    send(&bad, 5u, t, SC_NEEDLE_REJ_SPEED);
    assert_int_equal(g_rx.rejected, 6u);
    assert_int_equal(g_rx.outcome[SC_NEEDLE_E2E_CRC], 1u);
    assert_int_equal(g_rx.outcome[SC_NEEDLE_E2E_REPEATED], 1u);
    assert_int_equal(g_rx.outcome[SC_NEEDLE_REJ_DIR_NORM], 1u);
    /* the accepted sample stays until its timeout */
    assert_int_equal(sc_needle_rx_poll(&g_rx, 1000000000u + 90000000u, &smp), 1);
    assert_int_equal(sc_needle_rx_poll(&g_rx, 1000000000u + 150000000u, &smp), 0);
    /* a good sample again */
    m.tip_mm[0] = 11.0f;
    t += 10000000u;
    send(&m, 6u, t, SC_NEEDLE_ACCEPTED);
    /* not tracking: no needle, not a refusal */
    m.tracking = SC_TRACKING_LOST;
    t += 10000000u;
    send(&m, 7u, t, SC_NEEDLE_NOT_TRACKING);
    assert_int_equal(g_rx.rejected, 6u);
    /* a probe frame is not the needle's */
    sc_can_frame pf = {.id = SC_CANID_POSE_POS, .len = 8};
    assert_int_equal(sc_needle_rx_on_frame(&g_rx, &pf, t), SC_NEEDLE_NOT_OURS);
    /* a needle id with the wrong length */
    sc_can_frame sf = {.id = SC_CANID_NEEDLE_AUX, .len = 7};
    assert_int_equal(sc_needle_rx_on_frame(&g_rx, &sf, t), SC_NEEDLE_BAD_LENGTH);
    assert_int_equal(g_rx.rejected, 7u);
}

static void needle_status_frame_round_trips(void **state)
{
    (void)state;
    const sc_needle_status_msg s = {.tip_vessel = SC_LABEL_VEIN, .needle_tracked = 1u,
                                    .last_puncture = SC_LABEL_ARTERY, .vein_punctures = 3u,
                                    .artery_punctures = 1u, .needle_rejected = 1234u};
    sc_can_frame f;
    assert_int_equal(sc_canproto_encode_needle_status(&s, 9u, &f), SC_OK);
    assert_int_equal(f.id, SC_CANID_NEEDLE_STATUS);
    sc_needle_status_msg d;
    assert_int_equal(sc_canproto_decode_needle_status(&f, &d), SC_OK);
    assert_memory_equal(&d, &s, sizeof s);
    assert_int_equal(sc_e2e_crc(SC_CANID_NEEDLE_STATUS, f.data, f.len), f.data[0]);
}

static void the_emulated_needle_goes_in_holds_and_comes_out(void **state)
{
    (void)state;
    sc_emu_needle_def d = sc_emu_needle_default_def();
    d.entry_mm[0] = 15.0f;
    d.dir[0] = 1.0f; /* normalised by init: (1, 0, 1) / sqrt 2 */
    sc_emu_needle en;
    assert_int_equal(sc_emu_needle_init(&en, &d), SC_OK);
    const sc_needle_rx_def rd = sc_needle_rx_default_def();
    assert_int_equal(sc_needle_rx_init(&g_rx, &rd), SC_OK);
    float max_depth = 0.0f, last_depth = -1.0f;
    for (int i = 0; i < 650; i++) { /* 6.5 s at 100 Hz: 0.5 s, then 2.5 s in, 1 s, 2.5 s out */
        sc_can_frame f[3];
        uint64_t t;
        assert_int_equal(sc_emu_needle_next(&en, f, 3u, &t), 3);
        for (int k = 0; k < 3; k++) {
            const sc_needle_outcome o = sc_needle_rx_on_frame(&g_rx, &f[k], t);
            assert_int_equal(o, k < 2 ? SC_NEEDLE_PART : SC_NEEDLE_ACCEPTED);
        }
        sc_needle_sample smp;
        assert_int_equal(sc_needle_rx_poll(&g_rx, t, &smp), 1);
        /* the tip is where the script says, within the signals' resolution */
        const sc_needle_msg m = sc_emu_needle_at(&en.def, (double)t * 1e-9);
        for (int a = 0; a < 3; a++) {
            assert_true(fabsf(smp.tip_mm[a] - m.tip_mm[a]) <= 0.03f);
        }
        max_depth = fmaxf(max_depth, smp.depth_mm);
        last_depth = smp.depth_mm;
    }
    assert_true(fabsf(max_depth - 25.0f) <= 0.03f);
    assert_true(last_depth < 1.0f); /* withdrawn at the end of the cycle */
    assert_int_equal(g_rx.rejected, 0u);
    d.speed_mm_s = 0.0f;
    assert_int_equal(sc_emu_needle_init(&en, &d), SC_ERR_RANGE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(in_plane_needle_is_a_line_on_its_track),
        cmocka_unit_test(out_of_plane_needle_is_a_dot),
        cmocka_unit_test(a_vein_puncture_is_reported_once),
        cmocka_unit_test(an_artery_puncture_is_flagged),
        cmocka_unit_test(needle_image_is_deterministic),
        cmocka_unit_test(needle_frames_assemble_and_bad_ones_are_refused_and_counted),
        cmocka_unit_test(needle_status_frame_round_trips),
        cmocka_unit_test(the_emulated_needle_goes_in_holds_and_comes_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
