/* test_sc_pose.c: rigid transforms: pose <-> matrix round trips, composition, inverse. */
#include "sc_test.h"

#include <math.h>

#include "sc_pose.h"

static sc_pose axis_angle(float ax, float ay, float az, float angle, float tx, float ty, float tz)
{
    const float n = sqrtf(ax * ax + ay * ay + az * az);
    const float s = sinf(angle / 2.0f) / n;
    sc_pose p = {.pos_mm = {tx, ty, tz}, .q = {cosf(angle / 2.0f), ax * s, ay * s, az * s}};
    return p;
}

static void pose_matrix_round_trip_for_many_rotations(void **state)
{
    (void)state;
    /* angles spanning every branch of the matrix-to-quaternion conversion */
    const float angles[] = {0.0f, 0.3f, 1.5f, 2.9f, 3.14159f};
    const float axes[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, -2, 3}, {-1, 0.5f, 0.2f}};
    for (size_t a = 0; a < sizeof(angles) / sizeof(angles[0]); a++) {
        for (size_t k = 0; k < sizeof(axes) / sizeof(axes[0]); k++) {
            sc_pose p = axis_angle(axes[k][0], axes[k][1], axes[k][2], angles[a], 1, -2, 3);
            sc_xform x = sc_xform_from_pose(&p);
            assert_true(sc_xform_is_rigid(&x, 1e-5f));
            sc_pose back = sc_pose_from_xform(&x);
            /* q and -q are the same rotation: compare as matrices (float round-off 1e-5) */
            sc_xform x2 = sc_xform_from_pose(&back);
            for (int i = 0; i < 9; i++) {
                assert_true(fabsf(x.r[i] - x2.r[i]) < 1e-5f);
            }
            assert_true(fabsf(sqrtf(sc_quat_norm2(back.q)) - 1.0f) < 1e-6f);
            assert_true(back.q[0] >= 0.0f);
        }
    }
}

static void compose_with_inverse_is_identity(void **state)
{
    (void)state;
    sc_pose p = axis_angle(1, 2, 3, 0.7f, 10, 20, -5);
    sc_xform x = sc_xform_from_pose(&p);
    sc_xform xi = sc_xform_inverse(&x);
    sc_xform id = sc_xform_compose(&xi, &x);
    const float pt[3] = {3, -4, 5};
    float out[3];
    sc_xform_apply(&id, pt, out);
    for (int i = 0; i < 3; i++) {
        assert_true(fabsf(out[i] - pt[i]) < 1e-4f);
    }
    /* composition order: (b o a)(p) = b(a(p)) */
    sc_pose q = axis_angle(0, 0, 1, 1.0f, 1, 0, 0);
    sc_xform b = sc_xform_from_pose(&q);
    sc_xform ba = sc_xform_compose(&b, &x);
    float t1[3], t2[3];
    sc_xform_apply(&x, pt, t1);
    sc_xform_apply(&b, t1, t2);
    sc_xform_apply(&ba, pt, t1);
    for (int i = 0; i < 3; i++) {
        assert_true(fabsf(t1[i] - t2[i]) < 1e-4f);
    }
}

static void non_rigid_and_non_finite_transforms_are_detected(void **state)
{
    (void)state;
    sc_xform x = sc_xform_identity();
    assert_true(sc_xform_is_rigid(&x, 1e-6f));
    x.r[0] = 2.0f; /* scaling */
    assert_false(sc_xform_is_rigid(&x, 1e-4f));
    x = sc_xform_identity();
    x.r[0] = -1.0f; /* reflection: det -1 */
    assert_false(sc_xform_is_rigid(&x, 1e-4f));
    x = sc_xform_identity();
    x.t_mm[1] = NAN;
    assert_false(sc_xform_is_rigid(&x, 1e-4f));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pose_matrix_round_trip_for_many_rotations),
        cmocka_unit_test(compose_with_inverse_is_identity),
        cmocka_unit_test(non_rigid_and_non_finite_transforms_are_detected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
