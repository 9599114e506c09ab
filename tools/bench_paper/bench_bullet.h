/* bench_bullet.h: the peer a C/C++ user would pick, Bullet's soft body (btSoftBody, Debian's
 * libbullet-dev 3.24, single precision), built on the same nodes and tets as our mesh and pressed
 * by the same probe, behind a C interface so that bench_paper.c stays C. The only C++ of the
 * project (tools/bench_paper/bench_bullet.cpp); compiled only when Bullet is found at configure
 * time (BENCH_HAVE_BULLET), otherwise these calls report "not built".
 *
 * What Bullet is asked to do per frame (the fair-comparison statement, docs/performance.md):
 *   - btSoftRigidDynamicsWorld, gravity 0 (the press alone deforms, as in our scene);
 *   - one soft body: a node per mesh node (lengths in mm), one tetra per mesh tet (appendTetra) and one
 *     link per distinct tet edge (appendLink; the links are what Bullet's position solver
 *     moves), total mass 1000 kg/m^3 x the box volume spread over the nodes, the mesh's fixed
 *     nodes (bottom and sides) with mass 0 (Bullet's pinned nodes), link stiffness kLST = 1,
 *     damping kDP = 0.1, collision margin 0.5 mm;
 *   - the probe: a kinematic btBoxShape, the probe face's 36 x 12 mm (half extents 18, 6,
 *     10 mm, margin 0.5 mm), moved each frame to the same pose as our probe (press from 0.5 mm
 *     above the skin to 3 mm in over 30 frames, then held); soft-rigid collision SDF_RS
 *     (Bullet's default), contact hardness kCHR = 1;
 *   - one stepSimulation(1/60 s, maxSubSteps 0) per frame: one internal step of 1/60 s with
 *     piterations = 10 position-solver iterations (our solvers run 10 CG iterations per frame),
 *     viterations = 0, diterations = 0 (Bullet's defaults), on one thread (btSoftBody's CPU
 *     solver has no worker threads).
 */
#ifndef BENCH_BULLET_H
#define BENCH_BULLET_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bb_mesh {
    uint32_t nodes, tets;
    const float *x, *y, *z;     /* rest positions, mm (volume frame: z depth, skin at z = 0) */
    const uint32_t (*tet)[4];   /* node indices */
    const uint8_t *fixed;       /* non-zero: held (Bullet: mass 0) */
    float box_mm[3];            /* the block's extent, for the total mass */
    float probe_xy_mm[2];       /* probe face centre */
    float probe_half_mm[2];     /* probe face half extents */
} bb_mesh;

typedef struct bb_sim bb_sim;

/* 1 when Bullet was built in. */
int bb_available(void);

/* Build the world and the soft body; NULL on failure with a message in err. */
bb_sim *bb_create(const bb_mesh *m, char *err, size_t errn);

/* Place the probe face at depth face_z_mm (same convention as sc_test_scene_probe). */
void bb_set_probe(bb_sim *s, float face_z_mm);

/* One frame: stepSimulation(1/60, 0). */
void bb_step(bb_sim *s);

/* Largest node displacement from rest (mm), and the links Bullet holds (for the report). */
double bb_max_disp_mm(const bb_sim *s);
uint32_t bb_links(const bb_sim *s);

void bb_destroy(bb_sim *s);

#ifdef __cplusplus
}
#endif

#endif /* BENCH_BULLET_H */
