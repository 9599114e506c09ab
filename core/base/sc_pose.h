/*
 * sc_pose.h: rigid poses and transforms (float32), shared by tracker, collider and imaging.
 *
 * A pose is a position in mm and a unit quaternion (w, x, y, z). An sc_xform is the same
 * rigid transform as a row-major 3x3 rotation and a translation in mm: p' = R p + t.
 * Frames: tracker -> mannequin/patient (registration) -> volume frame (sc_volume.h); the probe
 * frame has x along the aperture (scan lines), y across it (elevation), z along the beam.
 * All functions are pure, O(1), never allocate.
 */
#ifndef SC_POSE_H
#define SC_POSE_H

typedef struct sc_pose {
    float pos_mm[3];
    float q[4]; /* w, x, y, z; unit norm */
} sc_pose;

typedef struct sc_xform {
    float r[9];     /* row-major rotation */
    float t_mm[3];  /* translation */
} sc_xform;
/* passed by value through every stage: keep them small and unpadded */
_Static_assert(sizeof(sc_pose) == 28u, "sc_pose: 7 float32");
_Static_assert(sizeof(sc_xform) == 48u, "sc_xform: 12 float32");

sc_pose sc_pose_identity(void);
sc_xform sc_xform_identity(void);
sc_xform sc_xform_from_pose(const sc_pose *p);
/* a then b: (b o a)(p) = b(a(p)) */
sc_xform sc_xform_compose(const sc_xform *b, const sc_xform *a);
sc_xform sc_xform_inverse(const sc_xform *a);
void sc_xform_apply(const sc_xform *x, const float p[3], float out[3]);
void sc_xform_rotate(const sc_xform *x, const float v[3], float out[3]);
/* The pose (position, unit quaternion with w >= 0) of a rigid transform. O(1). */
sc_pose sc_pose_from_xform(const sc_xform *x);
/* Quaternion norm squared; a pose is plausible only near 1. */
float sc_quat_norm2(const float q[4]);
/* 1 when every element is finite and R is orthonormal within tol (rigid, det +1). */
int sc_xform_is_rigid(const sc_xform *x, float tol);

#endif /* SC_POSE_H */
