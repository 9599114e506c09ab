/*
 * sc_collider.h: the probe as a collider for the tissue mesh and the skin.
 *
 * Shapes (probe frame of sc_pose.h: x along the aperture, y elevation, z along the beam into
 * the body; the pose's origin is the centre of the probe face):
 *  - SC_COLLIDER_SPHERE: the paper's spherical collision volume, touching the face plane z = 0
 *    from above (centre at z = -radius).
 *  - SC_COLLIDER_ROUNDED_BOX: the real footprint of a linear probe: a box with rounded edges
 *    and corners (a box swept by a sphere), e.g. 40 mm x 10 mm face with 2 mm rounding, whose
 *    face is the plane z = 0 and whose body extends to z = -2 * half_mm[2].
 * Both are convex shapes given to libccd by their support functions; the narrow phase is
 * ccdMPRPenetration (MPR: penetration depth and direction) of each candidate node (a point)
 * against the shape inflated by margin_mm, so that nodes just outside the probe also get a
 * contact plane. A rounded box's nodes above its face plane (or within the margin below it)
 * take the face plane as their contact whatever MPR finds (the sliding face, sc_collider.c):
 * for them only whether the node is inside is needed, and that is closed form (the distance to
 * the core box below the inflation); this cut the collision of a 32x16x16 press frame from
 * 0.25 to 0.016 ms with the same contact sets (every stored hash unchanged). A contact is a plane (surface point, outward normal); during the frame's
 * solver iterations the penetration of a node is measured against that plane, so the
 * repulsion force f = kappa * max(0, depth) * normal follows the node at O(1) per contact.
 *
 * Broad phase: the node sets are regular grids (the tet mesh, the skin); the candidates are
 * the nodes whose REST position lies in the shape's bounding box widened by the margin and by
 * the largest current node displacement (max_disp_mm, which the caller tracks), so the cost
 * grows with the contact area (and the indentation), not with the mesh. A cheap test in the
 * probe frame drops candidates that cannot be within the margin before MPR is called.
 *
 * Memory: caller-owned structs; a contact set holds at most one contact per node
 * (SC_MAX_CONTACTS), so it cannot overflow. Never allocates (libccd's MPR neither), never
 * calls the OS. libccd runs in double precision (CCD_DOUBLE). Threads: one writer.
 */
#ifndef SC_COLLIDER_H
#define SC_COLLIDER_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_hal_pool.h"
#include "sc_pose.h"

/* Detection on a worker pool (sc_collider.pool): the candidate box's rows are cut into at most
 * SC_COLLIDER_CHUNKS chunks, by the box alone; a box of fewer than SC_COLLIDER_POOL_MIN
 * candidates runs serially. Either way the same contacts in the same order. */
#define SC_COLLIDER_CHUNKS 32u
#define SC_COLLIDER_POOL_MIN 2048u

typedef enum sc_collider_shape {
    SC_COLLIDER_SPHERE = 0,
    SC_COLLIDER_ROUNDED_BOX = 1,
} sc_collider_shape;

typedef struct sc_collider_def {
    sc_collider_shape shape;
    float sphere_radius_mm;  /* sphere: > 0 */
    float half_mm[3];        /* rounded box: half extents incl. rounding, each > round_radius */
    float round_radius_mm;   /* rounded box: edge/corner radius, >= 0 */
    float margin_mm;         /* contact search margin, >= 0 */
} sc_collider_def;

/* Regular node grid (rest positions) for the broad phase; positions of the nodes (deformed)
 * are passed separately. Node index i + nx (j + ny k). */
typedef struct sc_collider_grid {
    uint32_t nx, ny, nz;
    float origin_mm[3];
    float cell_mm[3];   /* > 0 (any value when the axis has 1 node) */
} sc_collider_grid;

typedef struct sc_contact {
    uint32_t node;
    float p_mm[3];  /* point on the probe surface, volume frame */
    float n[3];     /* outward unit normal of the probe surface there */
} sc_contact;

typedef struct sc_contact_set {
    uint32_t count;
    uint32_t candidates;  /* nodes tested by the cheap test in the last detection */
    uint32_t mpr_calls;   /* narrow-phase calls in the last detection */
    sc_contact c[SC_MAX_CONTACTS];
} sc_contact_set;

typedef struct sc_collider {
    sc_collider_def def;
    int active;          /* 0: no contact (probe lifted / no pose) */
    sc_xform to_vol;     /* probe -> volume */
    sc_xform to_probe;   /* volume -> probe */
    float core_half_mm[3]; /* box swept by the sphere of radius round_radius_mm */
    float center_probe_mm[3];
    const sc_pool_dev *pool; /* workers of the detection (NULL: serial); init sets NULL, the
                              * owner may set it (sc_tissue_set_pool) */
} sc_collider;

/* Linear probe: 40 x 10 mm face, 2 mm rounding, 20 mm body, 0.5 mm margin. */
sc_collider_def sc_collider_default_def(void);

/* Finite, positive sizes. O(1). Errors: SC_ERR_INVALID_ARG (NULL, unknown shape),
 * SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_collider_def_validate(const sc_collider_def *def);

/* Validate and store the definition; inactive. O(1). Errors: as validate. */
int sc_collider_init(sc_collider *c, const sc_collider_def *def);

/* Place the probe (pose of the probe frame in the volume frame), or lift it (pose NULL).
 * A non-finite or non-unit pose lifts the probe and returns SC_ERR_POSE_IMPLAUSIBLE. O(1). */
int sc_collider_set_pose(sc_collider *c, const sc_pose *pose);

/* Find the contacts of the grid's nodes (positions x, y, z) into out (cleared first).
 * Cost: O(candidates) cheap tests + O(near nodes) MPR calls, candidates bounded by the nodes in
 * the shape's box widened by margin and max_disp_mm (at most nx*ny*nz). Never allocates.
 * Inactive collider: no contacts. Nodes with fixed[i] != 0 (may be NULL) are skipped.
 * Preconditions (SC_ASSERT): grid within SC_MAX_CONTACTS nodes. */
void sc_collider_detect(const sc_collider *c, const sc_collider_grid *g, const float *x,
                        const float *y, const float *z, const uint8_t *fixed,
                        float max_disp_mm, sc_contact_set *out);

/* A second tool's tip (the tracked needle) as a sphere of radius r_mm at c_mm (volume frame):
 * appends to out (not cleared) a contact for every free node (fixed[i] == 0, fixed may be NULL)
 * within r_mm + margin_mm of the centre that out does not hold yet: the point on the sphere
 * along the node's direction from the centre, the outward normal that direction (straight up,
 * -z, for a node at the centre), so the tip pushes tissue aside as the probe's face does.
 * Stops at SC_MAX_CONTACTS. Returns the contacts added. O(nodes + added * out->count).
 * Never allocates. */
uint32_t sc_collider_append_sphere(const float c_mm[3], float r_mm, float margin_mm,
                                   uint32_t node_count, const float *x, const float *y,
                                   const float *z, const uint8_t *fixed, sc_contact_set *out);

/* Signed penetration (mm, > 0 inside the probe) of a point against a contact plane. O(1). */
float sc_contact_depth_mm(const sc_contact *ct, float x, float y, float z);

/* Add the repulsion forces kappa[node] * kappa_scale * max(0, depth) * normal (N, kappa in
 * N/mm) of every contact to fx, fy, fz (caller zeroes them). O(contacts). */
void sc_contact_add_forces(const sc_contact_set *s, const float *x, const float *y,
                           const float *z, const float *kappa_n_per_mm, float kappa_scale,
                           float *fx, float *fy, float *fz);

/* Zero fx, fy, fz at the contact nodes only. O(contacts). */
void sc_contact_clear_forces(const sc_contact_set *s, float *fx, float *fy, float *fz);

/* Exact signed distance of a point (volume frame) to the collider's surface (mm, < 0 inside);
 * a reference for tests and for the FEM's kinematic contact. O(1). Inactive: +huge. */
float sc_collider_signed_distance_mm(const sc_collider *c, const float p_mm[3]);

#endif /* SC_COLLIDER_H */
