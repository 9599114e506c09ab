/*
 * sc_mesh.h: the regular tetrahedral soft-tissue mesh and the node state both solvers share.
 *
 * A box of the case volume (volume frame, mm; see sc_volume.h) carries NX x NY x NZ nodes;
 * every cube of the grid is split into 5 tetrahedra with alternating orientation (by the parity
 * of i+j+k) so that the face diagonals of neighbouring cubes agree and faces conform.
 * 5x5x5 -> 125 nodes / 320 tets; 32x16x16 -> 8,192 nodes / 34,875 tets.
 * Node index: i + nx * (j + ny * k), i along x, j along y, k along z (depth; k = 0 is the skin
 * side, the top of the box, where the probe presses).
 *
 * Memory: everything in the caller's sc_mesh and sc_nodes, sized by config/sc_config.h.
 * Never allocates, never calls the OS. Threads: one writer.
 */
#ifndef SC_MESH_H
#define SC_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "sc_config.h"

#define SC_ALIGN_HOT _Alignas(64)

typedef struct sc_mesh_def {
    uint32_t nx, ny, nz;    /* nodes per axis, 2..SC_MAX_MESH_NX/NY/NZ */
    float origin_mm[3];     /* corner of the box with the smallest coordinates */
    float size_mm[3];       /* box extent, > 0 */
} sc_mesh_def;

/* Topology and rest configuration: written at case load, read-only at frame time. */
typedef struct sc_mesh {
    uint32_t nx, ny, nz;
    uint32_t node_count;
    uint32_t tet_count;
    float origin_mm[3];
    float cell_mm[3];
    SC_ALIGN_HOT float rest_x[SC_MAX_NODES]; /* rest positions, mm */
    SC_ALIGN_HOT float rest_y[SC_MAX_NODES];
    SC_ALIGN_HOT float rest_z[SC_MAX_NODES];
    uint32_t tet[SC_MAX_TETS][4];   /* node indices, positively oriented */
    int32_t tet_nbr[SC_MAX_TETS][4]; /* tet across the face opposite vertex v, -1 on the hull */
    uint8_t tet_label[SC_MAX_TETS]; /* majority label of the tet's volume */
    uint8_t node_fixed[SC_MAX_NODES]; /* 1: Dirichlet node (bone, box bottom and sides);
                                         else SC_MESH_ROLLER_* bits, see below */
} sc_mesh;

/* Per-axis supports (a face on rollers): node_fixed = a combination of these bits holds only
 * those axes of the node (FEM, implicit and explicit MSDS; the collider and the skin treat
 * any non-zero node_fixed as a fully fixed node). node_fixed == 1 is fully fixed. */
#define SC_MESH_ROLLER_X 2u
#define SC_MESH_ROLLER_Y 4u
#define SC_MESH_ROLLER_Z 8u
#define SC_MESH_FIXED_ALL 1u

/* The five tets of a grid cell in its corner numbering (corner bit 0: +x, bit 1: +y, bit 2: +z),
 * even cell (i + j + k of its lowest corner even), in sc_mesh_build's order: tet 5 c + q of
 * cell c has these corners (an odd cell: the corners a ^ 1, the template mirrored in x; the
 * vertex order within a tet may differ, the set does not): X(q, a, b, c, d). The MSDS kernels
 * and the grid solver (sc_grid.h) rely on it; sc_msds_init and sc_grid_init check the mesh. */
#define SC_MESH_CELL_TETS(X)                                                                       \
    X(0, 0u, 1u, 2u, 4u)                                                                           \
    X(1, 3u, 2u, 1u, 7u)                                                                           \
    X(2, 5u, 4u, 7u, 1u)                                                                           \
    X(3, 6u, 7u, 4u, 2u)                                                                           \
    X(4, 1u, 2u, 4u, 7u)

/* Deformed state shared by MSDS and FEM so that switching keeps the shape (float32 SoA). */
typedef struct sc_nodes {
    SC_ALIGN_HOT float x[SC_MAX_NODES]; /* deformed positions, mm */
    SC_ALIGN_HOT float y[SC_MAX_NODES];
    SC_ALIGN_HOT float z[SC_MAX_NODES];
    SC_ALIGN_HOT float vx[SC_MAX_NODES]; /* velocities, mm/s */
    SC_ALIGN_HOT float vy[SC_MAX_NODES];
    SC_ALIGN_HOT float vz[SC_MAX_NODES];
    SC_ALIGN_HOT float fx[SC_MAX_NODES]; /* external forces (collider), N */
    SC_ALIGN_HOT float fy[SC_MAX_NODES];
    SC_ALIGN_HOT float fz[SC_MAX_NODES];
} sc_nodes;
/* nine float32 rows, each on its own hot alignment: nothing else lives in the node state */
_Static_assert(sizeof(sc_nodes) >= 9u * sizeof(float) * SC_MAX_NODES &&
                   sizeof(sc_nodes) < 9u * (sizeof(float) * SC_MAX_NODES + 64u),
               "sc_nodes is nine aligned float32 rows");
_Static_assert(offsetof(sc_nodes, y) % 64u == 0u && offsetof(sc_nodes, vx) % 64u == 0u &&
                   offsetof(sc_nodes, fx) % 64u == 0u,
               "node rows start on cache lines");

/* Default definition: 32x16x16 nodes over a 40 x 20 x 30 mm box at the origin. */
sc_mesh_def sc_mesh_default_def(void);

/* Build topology, rest positions and face neighbours of the regular 5-tet mesh. Labels are
 * set to 0 and no node is fixed (see the material module for both). O(tets). Never allocates.
 * Errors: SC_ERR_INVALID_ARG, SC_ERR_MESH_DIMS (counts outside 2..limits), SC_ERR_NOT_FINITE,
 * SC_ERR_RANGE (non-positive size), SC_ERR_MESH_ORIENTATION (a tet not positive: a bug). */
int sc_mesh_build(sc_mesh *m, const sc_mesh_def *def);

/* Copy rest positions into the deformed state, zero velocities and external forces. O(nodes). */
void sc_nodes_reset_to_rest(sc_nodes *n, const sc_mesh *m);

/* Signed volume (mm^3) of the tet with node indices tet[] in the SoA positions x, y, z
 * (positive when positively oriented). O(1), never allocates, cannot fail. */
float sc_mesh_tet_volume_mm3(const float *x, const float *y, const float *z,
                             const uint32_t tet[4]);

#endif /* SC_MESH_H */
