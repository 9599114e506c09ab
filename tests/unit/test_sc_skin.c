/* test_sc_skin.c: anchored single-layer skin MSDS (paper section V). */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_collider.h"
#include "sc_err.h"
#include "sc_skin.h"

static sc_skin g_skin;

static sc_collider sphere_at(float z_mm)
{
    sc_collider c;
    sc_collider_def d = sc_collider_default_def();
    d.shape = SC_COLLIDER_SPHERE;
    d.sphere_radius_mm = 8.0f;
    assert_int_equal(sc_collider_init(&c, &d), SC_OK);
    sc_pose p = sc_pose_identity();
    p.pos_mm[0] = 20.0f;
    p.pos_mm[1] = 10.0f;
    p.pos_mm[2] = z_mm; /* lowest point of the sphere */
    assert_int_equal(sc_collider_set_pose(&c, &p), SC_OK);
    return c;
}

static void skin_at_rest_stays_at_rest(void **state)
{
    (void)state;
    sc_skin_def d = sc_skin_default_def();
    assert_int_equal(sc_skin_init(&g_skin, &d), SC_OK);
    sc_collider lifted = sphere_at(-5.0f);
    for (int f = 0; f < 500; f++) {
        sc_skin_step(&g_skin, &lifted);
    }
    assert_true(sc_skin_max_displacement_mm(&g_skin) <= 0.0f);
}

/* The paper's Fig. 6/7: the sphere pressed 2 mm into the surface pushes the particles in
 * contact down (the surface deforms away from the sphere) while the anchors resist; when the
 * sphere lifts, the surface returns to rest. */
static void sphere_dents_the_skin_and_it_returns_when_lifted(void **state)
{
    (void)state;
    sc_skin_def d = sc_skin_default_def();
    assert_int_equal(sc_skin_init(&g_skin, &d), SC_OK);
    for (int f = 0; f < 20; f++) {
        sc_collider c = sphere_at(-0.5f + 2.5f * (float)(f + 1) / 20.0f);
        sc_skin_step(&g_skin, &c);
    }
    sc_collider c = sphere_at(2.0f);
    for (int f = 0; f < 30; f++) {
        sc_skin_step(&g_skin, &c);
    }
    /* the particle under the sphere's lowest point */
    const uint32_t mid = 16u + 32u * 8u;
    const float dent = g_skin.z[mid] - g_skin.rest_z[mid];
    /* contact stiffness ratio 0.5 of the local springs: the particle stays inside the sphere
     * by a fraction of the dent; it must be pushed at least half way, never through */
    assert_true(dent > 1.0f && dent <= 2.0f + 1e-3f);
    /* far particles hardly move (anchored): the corner */
    assert_true(fabsf(g_skin.z[0] - g_skin.rest_z[0]) < 0.05f);
    print_message("skin dent under a 2 mm press: %.3f mm, contacts %u\n", (double)dent,
                  g_skin.contacts.count);
    sc_collider lifted = sphere_at(-5.0f);
    for (int f = 0; f < 10; f++) { /* 2 s of simulated time */
        sc_skin_step(&g_skin, &lifted);
    }
    /* over-damped anchors (gamma = 0.1 k, k/m = 1 / (mass scaling) per unit): 2 s is many
     * time constants; 0.01 mm is 0.5% of the dent */
    assert_true(sc_skin_max_displacement_mm(&g_skin) <= 0.01f);
    assert_true(sc_skin_is_finite(&g_skin));
}

static void skin_definitions_are_validated(void **state)
{
    (void)state;
    sc_skin_def d = sc_skin_default_def();
    assert_int_equal(sc_skin_def_validate(&d), SC_OK);
    d.nx = 1u;
    assert_int_equal(sc_skin_def_validate(&d), SC_ERR_MESH_DIMS);
    d = sc_skin_default_def();
    d.ny = SC_MAX_SKIN_NY + 1u;
    assert_int_equal(sc_skin_def_validate(&d), SC_ERR_MESH_DIMS);
    d = sc_skin_default_def();
    d.k_anchor_n_per_mm = 0.0f;
    assert_int_equal(sc_skin_def_validate(&d), SC_ERR_RANGE);
    d = sc_skin_default_def();
    d.dt_s = 0.1f; /* explicit Euler beyond its stability bound */
    assert_int_equal(sc_skin_def_validate(&d), SC_ERR_RANGE);
    d = sc_skin_default_def();
    d.z_mm = NAN;
    assert_int_equal(sc_skin_def_validate(&d), SC_ERR_NOT_FINITE);
    assert_int_equal(sc_skin_init(NULL, &d), SC_ERR_INVALID_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(skin_at_rest_stays_at_rest),
        cmocka_unit_test(sphere_dents_the_skin_and_it_returns_when_lifted),
        cmocka_unit_test(skin_definitions_are_validated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
