/*
 * sc_material.h: tissue materials per label, and their assignment to the tet mesh.
 *
 * A material table has one row per label value (config/sc_labels.h): Young's modulus (Pa),
 * Poisson ratio, density (kg/m^3). The default rows come from config/sc_materials.h; a case
 * may carry its own. sc_material_assign() gives every tet the majority label of its volume in
 * the case's label map and fixes the Dirichlet nodes: nodes inside bone and on the bottom of the
 * box (k = nz - 1) fully (node_fixed 1), those on its four sides (i = 0, nx - 1; j = 0, ny - 1)
 * on rollers (SC_MESH_ROLLER_X / _Y: the normal axis held; the tissue slides along the cut).
 * The top (k = 0, skin side) is free: the probe presses there.
 *
 * Memory: caller-owned structs only. Never allocates, never calls the OS. Threads: one writer
 * (load time); the table is read-only at frame time.
 */
#ifndef SC_MATERIAL_H
#define SC_MATERIAL_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_mesh.h"
#include "sc_volume.h"

typedef struct sc_material {
    float e_pa;          /* Young's modulus, Pa: finite, > 0 */
    float poisson;       /* Poisson ratio: [0, 0.5) */
    float density_kg_m3; /* finite, > 0 */
} sc_material;

typedef struct sc_material_table {
    uint32_t count; /* rows used: labels 0..count-1; 1..SC_MAX_LABELS */
    sc_material row[SC_MAX_LABELS];
} sc_material_table;

/* Barycentric sample points per tet for the majority label (order-3 lattice: 20 points). */
#define SC_MATERIAL_TET_SAMPLES 20u

/* The default table of config/sc_materials.h (SC_LABEL_COUNT rows). O(labels). */
void sc_material_table_default(sc_material_table *t);

/* Check every used row (finite, E > 0, 0 <= nu < 0.5, rho > 0) and the count.
 * O(labels). Errors: SC_ERR_INVALID_ARG (NULL), SC_ERR_CASE_MATERIAL (a bad row or count). */
int sc_material_table_validate(const sc_material_table *t);

/* Label each tet with the majority label of SC_MATERIAL_TET_SAMPLES points of its rest volume
 * (nearest voxel of vol->labels; ties go to the smaller label; points outside the grid count
 * as SC_LABEL_OUTSIDE; vol == NULL or vol->labels == NULL labels every tet default_label),
 * then set node_fixed (bone under the node, box bottom and sides). O(tets * samples + nodes).
 * Never allocates. Errors: SC_ERR_INVALID_ARG (NULL mesh/table), SC_ERR_CASE_LABEL (a label
 * the table has no row for; the mesh labels are then incomplete and must not be used). */
int sc_material_assign(sc_mesh *m, const sc_volume *vol, const sc_material_table *t,
                       uint8_t default_label);

/* Label of the voxel nearest to p (volume frame, mm); SC_LABEL_OUTSIDE outside the grid or
 * without a label map. O(1). */
uint8_t sc_material_label_at(const sc_volume *vol, const float p_mm[3]);

#endif /* SC_MATERIAL_H */
