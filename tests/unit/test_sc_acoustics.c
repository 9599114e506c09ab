/* test_sc_acoustics.c: beam-dependent acoustics, measured on a phantom whose volume holds no
 * acoustic effects of its own.
 *
 * The volume is uniform muscle (grey 100), a bone slab (label bone, its voxels as grey as the
 * muscle) and a 10 mm vein (label vein, grey 10, an IJV's size). With the acoustics off the
 * image below the bone and below the vein is as bright as beside them (the checks below fail);
 * with them on, the bone shadows and the vein gives posterior enhancement, measured in displayed
 * grey levels; and the shadow runs along the beam, so a tilted probe moves it where geometry
 * says.
 */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_acoustics.h"
#include "sc_bscan.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_mesh.h"

#define PH_SP_MM 0.25f
#define PH_NX    321u /* x -40 .. 40 */
#define PH_NY    9u   /* y -1 .. 1 */
#define PH_NZ    221u /* z -5 .. 50 */
#define PH_VOX   (PH_NX * PH_NY * PH_NZ)
/* bone slab: x in [-6, 6], z in [18, 24]; vein centre (14, 12), radius 5 */
#define BONE_X0 (-6.0f)
#define BONE_X1 6.0f
#define BONE_Z0 18.0f
#define BONE_Z1 24.0f
#define VEIN_X  14.0f
#define VEIN_Z  12.0f
#define VEIN_R  5.0f

static uint8_t g_vox[PH_VOX], g_lab[PH_VOX];
static sc_volume g_vol;
static sc_bscan g_b;
static sc_hs_display g_disp;

static int group_setup(void **state)
{
    (void)state;
    for (uint32_t k = 0; k < PH_NZ; k++) {
        for (uint32_t j = 0; j < PH_NY; j++) {
            for (uint32_t i = 0; i < PH_NX; i++) {
                const float x = -40.0f + (float)i * PH_SP_MM, z = -5.0f + (float)k * PH_SP_MM;
                const size_t o = ((size_t)k * PH_NY + j) * PH_NX + i;
                uint8_t lab = SC_LABEL_MUSCLE, v = 100u;
                if (z < 0.0f) {
                    lab = SC_LABEL_OUTSIDE;
                    v = 0u;
                } else if (x >= BONE_X0 && x <= BONE_X1 && z >= BONE_Z0 && z <= BONE_Z1) {
                    lab = SC_LABEL_BONE;
                } else if (hypotf(x - VEIN_X, z - VEIN_Z) < VEIN_R) {
                    lab = SC_LABEL_VEIN;
                    v = 10u;
                }
                g_vox[o] = v;
                g_lab[o] = lab;
            }
        }
    }
    g_vol.dim[0] = PH_NX;
    g_vol.dim[1] = PH_NY;
    g_vol.dim[2] = PH_NZ;
    g_vol.spacing_mm[0] = g_vol.spacing_mm[1] = g_vol.spacing_mm[2] = PH_SP_MM;
    g_vol.origin_mm[0] = -40.0f;
    g_vol.origin_mm[1] = -1.0f;
    g_vol.origin_mm[2] = -5.0f;
    g_vol.voxels = g_vox;
    g_vol.labels = g_lab;
    return 0;
}

/* Probe face centre at (x, 0, z), beam along +z, tilted by tilt_deg about y. */
static sc_xform probe_at(float x, float z, float tilt_deg)
{
    const float a = tilt_deg * 3.14159265f / 180.0f;
    const float c = cosf(a), s = sinf(a);
    const sc_xform t = {.r = {c, 0.0f, s, 0.0f, 1.0f, 0.0f, -s, 0.0f, c}, .t_mm = {x, 0.0f, z}};
    return t;
}

/* 200 lines over 50 mm (0.25 mm apart), 160 samples over 40 mm (0.25 mm). */
static sc_bscan_def def_with(uint32_t acoustics)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.scan.lines_n = 200u;
    d.scan.samples_n = 160u;
    d.scan.width_mm = 50.0f;
    d.scan.depth_mm = 40.0f;
    d.acoustics = acoustics;
    return d;
}

static void image(const sc_bscan_def *d, const sc_xform *probe)
{
    assert_int_equal(sc_bscan_init(&g_b, d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, &g_vol, probe, 1, &dev, 1u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
}

/* Mean displayed value over image-frame x in [x0, x1] mm, depth in [z0, z1] mm. */
static float mean_box(const sc_bscan_def *d, float x0, float x1, float z0, float z1)
{
    const float pitch = d->scan.width_mm / (float)d->scan.lines_n;
    const float dr = d->scan.depth_mm / (float)d->scan.samples_n;
    double s = 0.0;
    uint32_t n = 0;
    for (uint32_t l = 0; l < d->scan.lines_n; l++) {
        const float x = -0.5f * d->scan.width_mm + ((float)l + 0.5f) * pitch;
        if (x < x0 || x > x1) {
            continue;
        }
        for (uint32_t k = 0; k < d->scan.samples_n; k++) {
            const float z = ((float)k + 0.5f) * dr;
            if (z >= z0 && z <= z1) {
                s += g_disp.last[(size_t)l * d->scan.samples_n + k];
                n++;
            }
        }
    }
    assert_true(n > 0u);
    return (float)(s / n);
}

static void bone_casts_a_shadow_of_at_most_0_3_of_beside(void **state)
{
    (void)state;
    const sc_xform probe = probe_at(0.0f, 0.0f, 0.0f);
    const sc_bscan_def off = def_with(0u), on = def_with(1u);
    image(&off, &probe);
    const float below_off = mean_box(&off, -4.0f, 4.0f, 28.0f, 38.0f);
    const float beside_off = mean_box(&off, -22.0f, -12.0f, 28.0f, 38.0f);
    image(&on, &probe);
    const float below = mean_box(&on, -4.0f, 4.0f, 28.0f, 38.0f);
    const float beside = mean_box(&on, -22.0f, -12.0f, 28.0f, 38.0f);
    /* the brightest sample of each line through the bone's top (the echo is one sample thick) */
    float bone_top = 255.0f;
    for (float x = -3.875f; x <= 4.0f; x += 0.25f) { /* line and sample centres */
        float mx = 0.0f;
        for (float z = 17.125f; z <= 19.0f; z += 0.25f) {
            const float m = mean_box(&on, x - 0.1f, x + 0.1f, z - 0.1f, z + 0.1f);
            mx = m > mx ? m : mx;
        }
        bone_top = mx < bone_top ? mx : bone_top;
    }
    print_message("off: below bone %.1f, beside %.1f; on: below %.1f, beside %.1f (%.3f), "
                  "bone surface %.1f\n",
                  (double)below_off, (double)beside_off, (double)below, (double)beside,
                  (double)(below / beside), (double)bone_top);
    assert_true(below_off > 0.9f * beside_off); /* no shadow in the volume itself */
    assert_true(beside > 50.0f);                /* the TGC keeps uniform tissue visible */
    assert_true(below <= 0.3f * beside);
    assert_true(bone_top > beside + 80.0f); /* the bone surface echoes brightly on every line */
}

static void vein_gives_posterior_enhancement_of_at_least_1_2(void **state)
{
    (void)state;
    const sc_xform probe = probe_at(0.0f, 0.0f, 0.0f);
    const sc_bscan_def off = def_with(0u), on = def_with(1u);
    /* below the vein (17 .. 24 mm deep, its bottom at 17), beside it at the same depths */
    image(&off, &probe);
    const float below_off = mean_box(&off, VEIN_X - 2.0f, VEIN_X + 2.0f, 18.0f, 24.0f);
    const float beside_off = mean_box(&off, -22.0f, -18.0f, 18.0f, 24.0f);
    image(&on, &probe);
    const float below = mean_box(&on, VEIN_X - 2.0f, VEIN_X + 2.0f, 18.0f, 24.0f);
    const float beside = mean_box(&on, -22.0f, -18.0f, 18.0f, 24.0f);
    print_message("off: below vein %.1f, beside %.1f; on: below %.1f, beside %.1f (%.3f)\n",
                  (double)below_off, (double)beside_off, (double)below, (double)beside,
                  (double)(below / beside));
    assert_true(below_off < 1.05f * beside_off);
    assert_true(below >= 1.2f * beside);
}

/* Centre (image-frame x, mm) of the dark part of a depth band: the shadow's position. */
static float shadow_centre(const sc_bscan_def *d, float z0, float z1)
{
    const float pitch = d->scan.width_mm / (float)d->scan.lines_n;
    double sx = 0.0, sw = 0.0;
    for (uint32_t l = 0; l < d->scan.lines_n; l++) {
        const float x = -0.5f * d->scan.width_mm + ((float)l + 0.5f) * pitch;
        const float m = mean_box(d, x - 0.1f, x + 0.1f, z0, z1);
        if (m < 20.0f) {
            sx += x;
            sw += 1.0;
        }
    }
    assert_true(sw > 10.0);
    return (float)(sx / sw);
}

/* Tilted by 15 degrees, the shadow runs along the beam: at every depth below the bone it is
 * centred on the line through the bone's centre, whose image-frame x follows from the pose,
 * and not where a shadow fixed in the volume (straight down in z) would be. */
static void tilting_the_probe_turns_the_shadow_with_the_beam(void **state)
{
    (void)state;
    const sc_bscan_def on = def_with(1u);
    const float tilt = 15.0f, a = tilt * 3.14159265f / 180.0f;
    const sc_xform probe = probe_at(-3.0f, 0.0f, tilt);
    image(&on, &probe);
    /* the bone's centre (0, 21) in the image frame: R^T (p - t) */
    const float px = 0.0f - (-3.0f), pz = 21.0f - 0.0f;
    const float xb = cosf(a) * px - sinf(a) * pz;
    const float zb = sinf(a) * px + cosf(a) * pz;
    for (int i = 0; i < 2; i++) {
        const float z0 = zb + 6.0f + 6.0f * (float)i; /* 6 and 12 mm below the centre */
        const float c = shadow_centre(&on, z0, z0 + 2.0f);
        /* a shadow straight down in the volume would be at x where the image point lands
         * on the volume's x = 0 */
        const float zm = z0 + 1.0f;
        const float x_fixed = (0.0f - (-3.0f) - sinf(a) * zm) / cosf(a);
        print_message("depth %.1f mm: shadow at x %.2f mm, beam through the bone %.2f, "
                      "volume-fixed %.2f\n",
                      (double)zm, (double)c, (double)xb, (double)x_fixed);
        assert_float_equal(c, xb, 0.6f);
        assert_true(fabsf(c - x_fixed) > 1.0f);
    }
    /* untilted the shadow is centred under the bone */
    const sc_xform straight = probe_at(-3.0f, 0.0f, 0.0f);
    image(&on, &straight);
    assert_float_equal(shadow_centre(&on, 28.0f, 30.0f), 3.0f, 0.6f);
}

static sc_mesh g_mesh;
static sc_nodes g_nodes;

/* The pass runs along the beam through the deformed tissue: a mesh over the bone moves it 4 mm
 * sideways and shears it (u_x = 4 + 0.3 (z - 21) mm). The shadow must hang straight down the
 * beam below the bone where it now is: centred at x = 4 at every depth. Rest labels (no
 * deformation) would put it at 0; a shadow carried with the tissue (baked into the volume)
 * would lean with the shear, at 4 + 0.3 (z - 21). */
static void shadow_hangs_below_the_bone_where_the_deformation_put_it(void **state)
{
    (void)state;
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = 21u;
    md.ny = 2u;
    md.nz = 16u;
    md.origin_mm[0] = -20.0f;
    md.origin_mm[1] = -0.9f;
    md.origin_mm[2] = 0.0f;
    md.size_mm[0] = 40.0f;
    md.size_mm[1] = 1.8f;
    md.size_mm[2] = 40.0f;
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_nodes.x[i] += 4.0f + 0.3f * (g_mesh.rest_z[i] - 21.0f);
    }
    const sc_bscan_def on = def_with(1u);
    assert_int_equal(sc_bscan_init(&g_b, &on), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    const sc_xform probe = probe_at(0.0f, 0.0f, 0.0f);
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol, &probe, 1, &dev, 1u), SC_OK);
    assert_true(g_b.status.pixels_in_mesh > 1000u);
    for (int i = 0; i < 2; i++) {
        const float z0 = 28.0f + 6.0f * (float)i;
        const float c = shadow_centre(&on, z0, z0 + 2.0f);
        print_message("depth %.0f mm: shadow at x %.2f mm (beam below the moved bone 4.00, rest "
                      "labels 0, carried with the tissue %.2f)\n",
                      (double)(z0 + 1.0f), (double)c, (double)(4.0f + 0.3f * (z0 + 1.0f - 21.0f)));
        assert_float_equal(c, 4.0f, 0.6f);
    }
}

static void table_out_of_range_is_refused(void **state)
{
    (void)state;
    sc_acoustics a;
    sc_acoustics_def d = sc_acoustics_default_def();
    assert_int_equal(sc_acoustics_init(&a, &d, 0.1f, 60.0f), SC_OK);
    d.label[SC_LABEL_BONE].impedance_mrayl = 0.0f;
    assert_int_equal(sc_acoustics_init(&a, &d, 0.1f, 60.0f), SC_ERR_RANGE);
    d = sc_acoustics_default_def();
    d.frequency_mhz = NAN;
    assert_int_equal(sc_acoustics_init(&a, &d, 0.1f, 60.0f), SC_ERR_NOT_FINITE);
    sc_bscan_def bd = sc_bscan_default_def();
    bd.acoustics = 2u;
    assert_int_equal(sc_bscan_init(&g_b, &bd), SC_ERR_RANGE);
}

/* The pass in fixed point against the float pass it replaced (the float tables and the loss
 * chain per sample, copied here as the reference): random lines of label runs (every label,
 * out-of-range labels, runs of 1..60 samples, zero samples among the grey), the default table
 * at 60 and 40 dB over 512 samples of 0.1 mm (the engine's 256x512 over 50 mm is about 0.1):
 * no sample differs by more than one grey level, and at most 1 in 200 differs at all. */
typedef struct ref_tables {
    float atten[SC_LABEL_COUNT], scatter[SC_LABEL_COUNT];
    float trans[SC_LABEL_COUNT][SC_LABEL_COUNT], echo[SC_LABEL_COUNT][SC_LABEL_COUNT];
} ref_tables;

static void ref_init(ref_tables *a, const sc_acoustics_def *def, float sample_mm, float dr_db)
{
    const float gl_per_db = 255.0f / dr_db;
    const float path_cm_mhz = 2.0f * 0.1f * sample_mm * def->frequency_mhz;
    const float comp_gl = def->ref_atten_db_cm_mhz * path_cm_mhz * gl_per_db;
    for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
        const sc_acoustic_props *p = &def->label[i];
        a->atten[i] = p->atten_db_cm_mhz * path_cm_mhz * gl_per_db - comp_gl;
        a->scatter[i] = p->scatter_db * gl_per_db;
        for (uint32_t j = 0; j < SC_LABEL_COUNT; j++) {
            if (i == SC_LABEL_OUTSIDE || j == SC_LABEL_OUTSIDE) {
                a->trans[i][j] = 0.0f;
                a->echo[i][j] = 0.0f;
                continue;
            }
            const float z1 = p->impedance_mrayl, z2 = def->label[j].impedance_mrayl;
            const float r = (z2 - z1) / (z2 + z1);
            const float refl = r * r;
            a->trans[i][j] = -20.0f * log10f(1.0f - refl) * gl_per_db;
            const float echo = refl > 0.0f ? 255.0f + 10.0f * log10f(refl) * gl_per_db : 0.0f;
            a->echo[i][j] = echo > 0.0f ? echo : 0.0f;
        }
    }
}

static void ref_line(const ref_tables *a, const uint8_t *lab, uint8_t *out, uint32_t n)
{
    float loss = 0.0f;
    uint32_t prev = SC_LABEL_OUTSIDE;
    for (uint32_t k = 0; k < n; k++) {
        const uint32_t l = lab[k] < SC_LABEL_COUNT ? lab[k] : (uint32_t)SC_LABEL_OUTSIDE;
        float echo = 0.0f;
        if (l != prev) {
            echo = a->echo[prev][l] - loss;
            loss += a->trans[prev][l];
            prev = l;
        }
        const float half = 0.5f * a->atten[l];
        loss += half;
        if (out[k] != 0u) {
            float v = (float)out[k] + a->scatter[l] - loss;
            v = v > echo ? v : echo;
            out[k] = (uint8_t)(v <= 0.0f ? 0.0f : (v >= 255.0f ? 255.0f : v + 0.5f));
        }
        loss += half;
    }
}

static void fixed_point_pass_matches_the_float_pass_within_one_grey_level(void **state)
{
    (void)state;
    enum { N = 512, LINES = 400 };
    static uint8_t lab[N], in[N], got[N], want[N];
    uint32_t rng = 99u, differ = 0, total = 0, changed = 0;
    const float ranges[2] = {60.0f, 40.0f};
    for (uint32_t ri = 0; ri < 2u; ri++) {
        sc_acoustics_def d = sc_acoustics_default_def();
        d.label[SC_LABEL_MUSCLE].scatter_db = 3.0f;
        d.label[SC_LABEL_FAT].scatter_db = -4.5f;
        sc_acoustics a;
        ref_tables r;
        assert_int_equal(sc_acoustics_init(&a, &d, 0.1f, ranges[ri]), SC_OK);
        ref_init(&r, &d, 0.1f, ranges[ri]);
        for (uint32_t line = 0; line < LINES; line++) {
            uint32_t k = 0;
            while (k < N) {
                rng = rng * 1664525u + 1013904223u;
                const uint32_t len = 1u + (rng >> 8) % 60u;
                rng = rng * 1664525u + 1013904223u;
                /* bone rarely (it blacks out the rest), one in 16 out of range */
                uint32_t l = (rng >> 8) % 17u;
                l = l == SC_LABEL_BONE && (rng >> 20) % 4u != 0u ? SC_LABEL_MUSCLE : l;
                l = l >= SC_LABEL_COUNT ? (l == 16u ? 200u : SC_LABEL_FAT) : l;
                for (uint32_t i = 0; i < len && k < N; i++, k++) {
                    lab[k] = (uint8_t)l;
                    rng = rng * 1664525u + 1013904223u;
                    in[k] = (uint8_t)((rng >> 9) % 11u == 0u ? 0u : 20u + (rng >> 12) % 200u);
                }
            }
            memcpy(got, in, N);
            memcpy(want, in, N);
            sc_acoustics_line(&a, lab, got, N);
            ref_line(&r, lab, want, N);
            for (uint32_t i = 0; i < N; i++) {
                const int dv = (int)got[i] - (int)want[i];
                assert_true(dv >= -1 && dv <= 1);
                differ += dv != 0;
                changed += got[i] != in[i];
                total++;
            }
        }
    }
    print_message("fixed point against float: %u of %u samples differ by one grey level, %u "
                  "changed by the pass\n", differ, total, changed);
    assert_true(differ * 200u <= total);
    assert_true(changed * 2u > total);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bone_casts_a_shadow_of_at_most_0_3_of_beside),
        cmocka_unit_test(vein_gives_posterior_enhancement_of_at_least_1_2),
        cmocka_unit_test(tilting_the_probe_turns_the_shadow_with_the_beam),
        cmocka_unit_test(shadow_hangs_below_the_bone_where_the_deformation_put_it),
        cmocka_unit_test(table_out_of_range_is_refused),
        cmocka_unit_test(fixed_point_pass_matches_the_float_pass_within_one_grey_level),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
