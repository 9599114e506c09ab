/*
 * sc_test_tissue_scene.h: the clinical block scene of the physics tests, reusable by other
 * tests (B-scan): a block (volume frame, skin at z = 0) of fat over muscle with a soft vein
 * and a stiff artery side by side at the same depth, both running along y (the probe's
 * elevation axis), under a linear probe centred over both.
 * Test code: uses static storage for the volume (one scene at a time).
 */
#ifndef SC_TEST_TISSUE_SCENE_H
#define SC_TEST_TISSUE_SCENE_H

#include <stdint.h>

#include "sc_mesh.h"
#include "sc_tissue.h"
#include "sc_pose.h"
#include "sc_volume.h"

typedef struct sc_test_scene_params {
    float size_mm[3];     /* block extent; origin at 0 */
    float fat_mm;         /* fat from the skin down to this depth, muscle below */
    float vessel_z_mm;    /* depth of both vessel axes */
    float vein_x_mm, vein_r_mm;
    float artery_x_mm, artery_r_mm;
    float probe_x_mm, probe_y_mm; /* probe face centre */
    float probe_half_mm[2];       /* probe face half extents (x aperture, y elevation) */
    float probe_round_mm;         /* edge rounding of the probe face */
    uint8_t vein_label;   /* SC_LABEL_VEIN, or SC_LABEL_THROMBUS for a thrombosed vein */
    uint32_t nx, ny, nz;  /* mesh nodes */
} sc_test_scene_params;

typedef struct sc_test_scene {
    sc_test_scene_params p;
    sc_volume vol;     /* points into static storage of the support library */
    sc_mesh_def mesh;  /* the block */
} sc_test_scene;

/* The default mesh box, 40 x 20 x 30 mm: fat down to 20 mm, muscle below; vein and artery of
 * radius 3 mm at 10 mm depth, x = 13 and 27 mm; probe face 36 x 12 mm with 1 mm rounded edges
 * centred at (20, 10) so that it covers both vessels (the scene of test_sc_fem.c); 0.5 mm
 * voxels, mesh 32 x 16 x 16. */
sc_test_scene_params sc_test_scene_default_params(void);

/* Build the scene (volume at 0.5 mm spacing, at most 129 x 49 x 81 voxels). */
void sc_test_scene_build(sc_test_scene *s, const sc_test_scene_params *p);

/* The scene's probe as a collider definition (rounded box). */
#include "sc_collider.h"
sc_collider_def sc_test_scene_collider(const sc_test_scene *s);

/* Probe pose pressing straight down (+z) with its face centre at depth face_z_mm, over the
 * vessels (identity orientation: probe x = volume x). */
sc_pose sc_test_scene_probe(const sc_test_scene *s, float face_z_mm);

/* The tissue definition of the scene: default solvers, the scene's mesh, its probe as the
 * collider, the skin over the top of the block, method m. */
sc_tissue_def sc_test_scene_tissue_def(const sc_test_scene *s, sc_tissue_method m);

#endif /* SC_TEST_TISSUE_SCENE_H */
