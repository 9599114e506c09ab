/*
 * sc_skin.h: the skin surface (paper section V): a single-layer triangle mesh simulated as its
 * own MSDS, every particle anchored to its rest position by a zero-length spring.
 *
 * The surface is a regular grid of nx x ny particles over a rectangle at depth z_mm (volume
 * frame), each quad split into two triangles along the (i, j)-(i+1, j+1) diagonal; every
 * triangle edge is a Voigt spring (k_edge, gamma = 0.1 k as in Algorithm 1) and every particle
 * has a zero-length Voigt anchor (k_anchor, gamma = 0.1 k) to its rest position. The same
 * collider as the tissue pushes the particles in contact (sc_collider.h); when the probe
 * lifts, the anchors return the surface to rest (the paper's Fig. 6).
 * Integration: explicit Euler exactly as sc_msds (eqs. 3-5, new velocity in eq. 5), with the
 * same mass scaling for stability: m = mass_per_stiffness_s2 * (sum of k at the particle),
 * and a mass-proportional drag (friction, an external force of eq. 2) for the slow modes.
 * Units: mm, s, N, kg.
 *
 * Memory: caller-owned, sized by SC_MAX_SKIN_NX x SC_MAX_SKIN_NY (float32 SoA, 21 floats per
 * particle plus a contact set). Never allocates, never calls the OS. Threads: one writer.
 */
#ifndef SC_SKIN_H
#define SC_SKIN_H

#include <stdint.h>

#include "sc_collider.h"
#include "sc_config.h"
#include "sc_mesh.h"

typedef struct sc_skin_def {
    uint32_t nx, ny;          /* particles per axis, 2..SC_MAX_SKIN_NX/NY */
    float origin_mm[2];       /* corner (x, y) */
    float size_mm[2];         /* extent, > 0 */
    float z_mm;               /* depth of the surface (volume frame) */
    float k_edge_n_per_mm;    /* edge spring constant, > 0 */
    float k_anchor_n_per_mm;  /* anchor spring constant, > 0 */
    float dt_s;               /* Euler step, > 0 */
    uint32_t iterations;      /* steps per frame, 1..SC_PHYS_ITERATIONS_MAX */
    float mass_per_stiffness_s2; /* mass scaling, > 0, stability as in sc_msds.h */
    float contact_stiffness_ratio; /* contact spring / sum of k at a particle, >= 0 */
    float drag_per_s;         /* mass-proportional drag (friction of eq. 2), >= 0 */
} sc_skin_def;

#define SC_SKIN_FAMILIES 3u

typedef struct sc_skin {
    sc_skin_def def;
    uint32_t count;
    uint32_t off[SC_SKIN_FAMILIES];
    SC_ALIGN_HOT float rest_x[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float rest_y[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float rest_z[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float x[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float y[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float z[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float vx[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float vy[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float vz[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float fx[SC_MAX_SKIN_NODES]; /* external (contact) forces, N */
    SC_ALIGN_HOT float fy[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float fz[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float k_fam[SC_SKIN_FAMILIES][SC_MAX_SKIN_NODES]; /* N/mm, 0: no spring */
    SC_ALIGN_HOT float l0_fam[SC_SKIN_FAMILIES][SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float ksum_n_per_mm[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float inv_mass[SC_MAX_SKIN_NODES]; /* 1e3 / m */
    SC_ALIGN_HOT float mass_kg[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float ax[SC_MAX_SKIN_NODES]; /* scratch: net force of a step, N */
    SC_ALIGN_HOT float ay[SC_MAX_SKIN_NODES];
    SC_ALIGN_HOT float az[SC_MAX_SKIN_NODES];
    sc_contact_set contacts;
} sc_skin;

/* Defaults: 32 x 16 particles over the default mesh top (40 x 20 mm at z = 0), k_edge
 * 0.02 N/mm, k_anchor 0.01 N/mm, dt 0.01 s, 20 iterations, mass scaling 2e-3 s^2,
 * contact ratio 0.5, drag 10 /s (the anchored surface's slowest mode has k/m about 40 /s^2:
 * with gamma = 0.1 k alone it rings for seconds; 10 /s makes it about critically damped). */
sc_skin_def sc_skin_default_def(void);

/* Finite, ranges, explicit stability. O(1). Errors: SC_ERR_INVALID_ARG, SC_ERR_NOT_FINITE,
 * SC_ERR_RANGE, SC_ERR_MESH_DIMS (counts). */
int sc_skin_def_validate(const sc_skin_def *def);

/* Build the surface at rest. O(particles). Errors: as validate. */
int sc_skin_init(sc_skin *s, const sc_skin_def *def);

/* Back to rest, velocities and forces zero. O(particles). */
void sc_skin_reset(sc_skin *s);

/* One frame: contacts with the collider (rest-grid broad phase widened by max_disp_mm), then
 * def.iterations Euler steps with the repulsion forces re-evaluated on the contact planes at
 * every step. O(iterations * particles + contacts). Never allocates, cannot fail. */
void sc_skin_step(sc_skin *s, const sc_collider *c);

/* Largest distance of a particle from its rest position (mm); NaN propagates as +inf.
 * O(particles). */
float sc_skin_max_displacement_mm(const sc_skin *s);

/* 1 if every position and velocity is finite. O(particles). */
int sc_skin_is_finite(const sc_skin *s);

#endif /* SC_SKIN_H */
