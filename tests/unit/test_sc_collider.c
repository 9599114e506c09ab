/* test_sc_collider.c: probe collider: MPR depth/direction against the exact distance, broad
 * phase cost, forces, pose validation. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_collider.h"
#include "sc_err.h"
#include "sc_pose.h"

static sc_contact_set g_set;

static uint32_t g_rng = 12345u;
static float rnd(float lo, float hi)
{
    g_rng = g_rng * 1664525u + 1013904223u;
    return lo + (hi - lo) * (float)(g_rng >> 8) / 16777216.0f;
}

/* a tilted probe: 20 degrees about an oblique axis */
static sc_pose tilted_pose(void)
{
    sc_pose p = sc_pose_identity();
    const float ang = 20.0f * 3.14159265f / 180.0f;
    const float ax[3] = {0.6f, 0.8f, 0.0f};
    p.q[0] = cosf(ang / 2.0f);
    p.q[1] = sinf(ang / 2.0f) * ax[0];
    p.q[2] = sinf(ang / 2.0f) * ax[1];
    p.q[3] = 0.0f;
    p.pos_mm[0] = 20.0f;
    p.pos_mm[1] = 10.0f;
    p.pos_mm[2] = 2.0f;
    return p;
}

/* Points scattered around the probe face, one at a time through a 1-node grid: every point
 * within the margin is found, and the depth on its contact plane equals the exact penetration
 * (minus the signed distance) within 2e-3 mm (MPR tolerance 1e-6 in double, float32 inputs
 * and outputs around coordinates of ~40 mm: ~1e-5; the plane is exact for the flat face and
 * the first-order tangent of a rounded part). */
static void check_shape(const sc_collider_def *def)
{
    sc_collider c;
    assert_int_equal(sc_collider_init(&c, def), SC_OK);
    const sc_pose pose = tilted_pose();
    assert_int_equal(sc_collider_set_pose(&c, &pose), SC_OK);
    sc_xform to_vol = sc_xform_from_pose(&pose);
    int found = 0, inside = 0;
    for (int i = 0; i < 3000; i++) {
        /* probe-frame sample around the face and the rounded edges */
        float l[3] = {rnd(-24.0f, 24.0f), rnd(-9.0f, 9.0f), rnd(-4.0f, 2.0f)};
        float p[3];
        sc_xform_apply(&to_vol, l, p);
        const float sd = sc_collider_signed_distance_mm(&c, p);
        const sc_collider_grid g = {1, 1, 1, {p[0], p[1], p[2]}, {1.0f, 1.0f, 1.0f}};
        sc_collider_detect(&c, &g, &p[0], &p[1], &p[2], NULL, 0.0f, &g_set);
        if (sd < def->margin_mm - 1e-3f) {
            assert_int_equal(g_set.count, 1);
        }
        if (sd > def->margin_mm + 1e-3f) {
            assert_int_equal(g_set.count, 0);
        }
        if (g_set.count == 1u) {
            found++;
            const float depth = sc_contact_depth_mm(&g_set.c[0], p[0], p[1], p[2]);
            const float *n = g_set.c[0].n;
            assert_true(fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0f) <= 1e-5f);
            if (def->shape == SC_COLLIDER_ROUNDED_BOX && l[2] < def->margin_mm) {
                /* sliding face: a point above the face plane (inside the probe or within the
                 * margin of it) leaves through the face plane z = 0 (probe frame), along the
                 * probe's z axis, never through a side wall */
                inside += sd < 0.0f;
                assert_true(fabsf(depth + l[2]) <= 2e-3f);
                assert_true(sd >= 0.0f || depth >= -sd - 2e-3f);
                float zax[3];
                const float ez[3] = {0.0f, 0.0f, 1.0f};
                sc_xform_rotate(&to_vol, ez, zax);
                assert_true(fabsf(n[0] * zax[0] + n[1] * zax[1] + n[2] * zax[2] - 1.0f) <= 1e-5f);
                continue;
            }
            assert_true(fabsf(depth + sd) <= 2e-3f);
            if (sd < 0.0f) {
                inside++;
                /* moving the point by its depth along the normal puts it on the surface */
                const float q[3] = {p[0] + depth * n[0], p[1] + depth * n[1],
                                    p[2] + depth * n[2]};
                assert_true(fabsf(sc_collider_signed_distance_mm(&c, q)) <= 2e-3f);
            }
        }
    }
    /* the sample must exercise both outcomes */
    assert_true(found > 100 && inside > 100 && found < 3000);
}

static void mpr_depth_and_direction_match_exact_distance_rounded_box(void **state)
{
    (void)state;
    sc_collider_def d = sc_collider_default_def();
    check_shape(&d);
}

static void mpr_depth_and_direction_match_exact_distance_sphere(void **state)
{
    (void)state;
    sc_collider_def d = sc_collider_default_def();
    d.shape = SC_COLLIDER_SPHERE;
    d.sphere_radius_mm = 12.0f;
    check_shape(&d);
}

/* Two grids with the same node spacing, one 8x the nodes of the other: the same probe gives
 * the same candidates and MPR calls (the broad phase works on the contact area). */
static void broad_phase_cost_does_not_grow_with_the_mesh(void **state)
{
    (void)state;
    static float xs[32 * 16 * 16], ys[32 * 16 * 16], zs[32 * 16 * 16];
    sc_collider c;
    sc_collider_def d = sc_collider_default_def();
    d.half_mm[0] = 6.0f;
    d.half_mm[1] = 3.0f;
    assert_int_equal(sc_collider_init(&c, &d), SC_OK);
    uint32_t cand[2], mpr[2], cnt[2];
    for (int r = 0; r < 2; r++) {
        const sc_collider_grid g = {r ? 32u : 16u, r ? 16u : 8u, r ? 16u : 8u,
                                    {0.0f, 0.0f, 0.0f}, {1.25f, 1.25f, 2.0f}};
        for (uint32_t k = 0; k < g.nz; k++) {
            for (uint32_t j = 0; j < g.ny; j++) {
                for (uint32_t i = 0; i < g.nx; i++) {
                    const uint32_t n = i + g.nx * (j + g.ny * k);
                    xs[n] = (float)i * 1.25f;
                    ys[n] = (float)j * 1.25f;
                    zs[n] = (float)k * 2.0f;
                }
            }
        }
        sc_pose p = sc_pose_identity();
        p.pos_mm[0] = 10.0f;
        p.pos_mm[1] = 5.0f;
        p.pos_mm[2] = 1.0f; /* 1 mm into the top */
        assert_int_equal(sc_collider_set_pose(&c, &p), SC_OK);
        sc_collider_detect(&c, &g, xs, ys, zs, NULL, 0.0f, &g_set);
        cand[r] = g_set.candidates;
        mpr[r] = g_set.mpr_calls;
        cnt[r] = g_set.count;
    }
    print_message("broad phase: 2,048 nodes: %u candidates, %u MPR, %u contacts; 8,192 nodes: "
                  "%u, %u, %u\n", cand[0], mpr[0], cnt[0], cand[1], mpr[1], cnt[1]);
    assert_int_equal(cand[0], cand[1]);
    assert_int_equal(mpr[0], mpr[1]);
    assert_int_equal(cnt[0], cnt[1]);
    assert_true(cnt[0] > 0u && cand[1] < 8192u / 8u);
}

static void forces_push_out_along_the_normal_in_proportion_to_depth(void **state)
{
    (void)state;
    sc_collider c;
    sc_collider_def d = sc_collider_default_def();
    assert_int_equal(sc_collider_init(&c, &d), SC_OK);
    sc_pose p = sc_pose_identity();
    p.pos_mm[2] = 1.0f;
    assert_int_equal(sc_collider_set_pose(&c, &p), SC_OK);
    float x[2] = {0.0f, 3.0f}, y[2] = {0.0f, 1.0f}, z[2] = {0.25f, 0.5f};
    const sc_collider_grid g = {2, 1, 1, {0.0f, 0.0f, 0.0f}, {3.0f, 1.0f, 1.0f}};
    y[1] = 0.0f;
    sc_collider_detect(&c, &g, x, y, z, NULL, 0.0f, &g_set);
    assert_int_equal(g_set.count, 2);
    float fx[2] = {0, 0}, fy[2] = {0, 0}, fz[2] = {0, 0};
    const float kappa[2] = {2.0f, 2.0f};
    sc_contact_add_forces(&g_set, x, y, z, kappa, 0.5f, fx, fy, fz);
    /* face at z = 1 facing +z: depths 0.75 and 0.5 mm, force kappa * 0.5 * depth along +z */
    assert_true(fabsf(fz[0] - 0.75f) <= 1e-5f && fabsf(fz[1] - 0.5f) <= 1e-5f);
    assert_true(fabsf(fx[0]) <= 1e-6f && fabsf(fy[1]) <= 1e-6f);
    sc_contact_clear_forces(&g_set, fx, fy, fz);
    assert_true(fabsf(fz[0]) <= 0.0f && fabsf(fz[1]) <= 0.0f);
}

static void lifted_or_implausible_probe_has_no_contact(void **state)
{
    (void)state;
    sc_collider c;
    sc_collider_def d = sc_collider_default_def();
    assert_int_equal(sc_collider_init(&c, &d), SC_OK);
    float x = 0.0f, y = 0.0f, z = 0.5f;
    const sc_collider_grid g = {1, 1, 1, {0.0f, 0.0f, 0.5f}, {1.0f, 1.0f, 1.0f}};
    sc_pose p = sc_pose_identity();
    p.pos_mm[2] = 1.0f;
    assert_int_equal(sc_collider_set_pose(&c, &p), SC_OK);
    sc_collider_detect(&c, &g, &x, &y, &z, NULL, 0.0f, &g_set);
    assert_int_equal(g_set.count, 1);
    assert_int_equal(sc_collider_set_pose(&c, NULL), SC_OK);
    sc_collider_detect(&c, &g, &x, &y, &z, NULL, 0.0f, &g_set);
    assert_int_equal(g_set.count, 0);
    p.q[0] = 2.0f; /* not a unit quaternion */
    assert_int_equal(sc_collider_set_pose(&c, &p), SC_ERR_POSE_IMPLAUSIBLE);
    sc_collider_detect(&c, &g, &x, &y, &z, NULL, 0.0f, &g_set);
    assert_int_equal(g_set.count, 0);
    p = sc_pose_identity();
    p.pos_mm[0] = NAN;
    assert_int_equal(sc_collider_set_pose(&c, &p), SC_ERR_POSE_IMPLAUSIBLE);
    /* a fixed node is never a contact */
    p = sc_pose_identity();
    p.pos_mm[2] = 1.0f;
    assert_int_equal(sc_collider_set_pose(&c, &p), SC_OK);
    const uint8_t fixed = 1u;
    sc_collider_detect(&c, &g, &x, &y, &z, &fixed, 0.0f, &g_set);
    assert_int_equal(g_set.count, 0);
    /* definitions */
    d.round_radius_mm = 6.0f; /* larger than the 5 mm half elevation */
    assert_int_equal(sc_collider_def_validate(&d), SC_ERR_RANGE);
    d = sc_collider_default_def();
    d.margin_mm = INFINITY;
    assert_int_equal(sc_collider_def_validate(&d), SC_ERR_NOT_FINITE);
}

/* The needle's tip as a sphere: free nodes inside it (plus the margin) get a contact on its
 * surface along their direction, nodes the probe already holds and fixed nodes none. */
static void a_tip_sphere_appends_contacts_of_the_nodes_it_reaches(void **state)
{
    (void)state;
    const float x[5] = {10.0f, 10.5f, 12.0f, 9.6f, 10.0f};
    const float y[5] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    const float z[5] = {5.0f, 5.0f, 5.0f, 5.0f, 4.4f};
    const uint8_t fixed[5] = {0, 0, 0, 1, 0};
    const float c[3] = {10.0f, 0.0f, 5.2f};
    g_set.count = 1u; /* node 4 is the probe's already */
    g_set.c[0].node = 4u;
    const uint32_t added = sc_collider_append_sphere(c, 1.0f, 0.1f, 5u, x, y, z, fixed, &g_set);
    assert_int_equal(added, 2u); /* nodes 0 and 1: 2 is out of reach, 3 fixed, 4 held */
    assert_int_equal(g_set.count, 3u);
    assert_int_equal(g_set.c[1].node, 0u);
    assert_int_equal(g_set.c[2].node, 1u);
    /* node 0 sits 0.2 mm above the centre: pushed up to the surface */
    assert_true(fabsf(g_set.c[1].p_mm[2] - 4.2f) < 1e-5f && fabsf(g_set.c[1].n[2] + 1.0f) < 1e-5f);
    /* node 1: along its direction, on the sphere */
    const float *p = g_set.c[2].p_mm;
    const float r = sqrtf((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                          (p[2] - c[2]) * (p[2] - c[2]));
    assert_true(fabsf(r - 1.0f) < 1e-5f);
    /* a penetrating node: positive depth against its contact plane */
    assert_true(sc_contact_depth_mm(&g_set.c[1], x[0], y[0], z[0]) > 0.7f);
    assert_int_equal(sc_collider_append_sphere(c, 0.0f, 0.1f, 5u, x, y, z, fixed, &g_set), 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(mpr_depth_and_direction_match_exact_distance_rounded_box),
        cmocka_unit_test(mpr_depth_and_direction_match_exact_distance_sphere),
        cmocka_unit_test(broad_phase_cost_does_not_grow_with_the_mesh),
        cmocka_unit_test(forces_push_out_along_the_normal_in_proportion_to_depth),
        cmocka_unit_test(lifted_or_implausible_probe_has_no_contact),
        cmocka_unit_test(a_tip_sphere_appends_contacts_of_the_nodes_it_reaches),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
