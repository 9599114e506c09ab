/*
 * sc_tissue.h: the soft-tissue facade the engine calls once per frame.
 *
 * Owns the tet mesh and its node state, the material table, Algorithm 1's springs, the MSDS,
 * the FEM, the probe collider, the skin and the stability guard. One frame:
 *   1. place the probe (pose of the probe frame in the volume frame) or lift it (NULL);
 *   2. contacts of the tet mesh's nodes with the probe (sc_collider.h, libccd MPR);
 *   3. MSDS, default (def.msds.integrator SC_MSDS_IMPLICIT): one backward Euler step of the
 *      frame's simulated time (iterations x dt) with def.fem.cg_iterations CG iterations and
 *      the probe's contacts as kinematic nodes, exactly as the FEM below (sc_msds_implicit.h);
 *      MSDS, explicit (SC_MSDS_EXPLICIT, the paper): def.msds.iterations explicit Euler
 *      steps (dt each); after every step each node
 *      that penetrates its contact plane gets the repulsion that removes the penetration in
 *      that step (SC_TISSUE_CONTACT_PROJECT, default: x onto the plane, inward normal
 *      velocity removed), or, with SC_TISSUE_CONTACT_PENALTY, the paper's spring-like
 *      repulsion kappa * depth * normal before every step (kappa = contact_stiffness_ratio *
 *      the node's mass-equivalent stiffness m / mass_per_stiffness, sc_msds.h; softer, the
 *      tissue sinks into the probe);
 *      FEM: one implicit step of length iterations * dt (the same simulated time per frame
 *      as the MSDS) with def.fem.cg_iterations CG iterations; nodes in the probe or on its surface
 *      (depth > -SC_TISSUE_CONTACT_HOLD_MM) are moved onto the surface as kinematic
 *      (Dirichlet) nodes (sc_fem_step_kinematic), so a static probe does not make a surface
 *      node chatter, and a node is released as soon as the probe moves away from it;
 *   2b. the lumen pass (SC_PHYS_LUMEN, sc_lumen.h): every vessel's volume, its pressure from
 *      the pressure-volume law and the cardiac/respiratory drive, as forces on the lumen's
 *      boundary nodes (external forces of the step below, cleared after it);
 *   4. the skin MSDS (sc_skin.h) with the same collider;
 *   5. stability guard: any non-finite position or velocity, a node displaced by more than
 *      the box diagonal, or (explicit MSDS) kinetic energy above the energy of every spring stretched
 *      by its own length, resets the tissue and the skin to rest, counts the fault and makes
 *      the step return SC_ERR_PHYS_UNSTABLE: the diverged state never reaches the image; the
 *      reason is kept in stats.last_fault (sc_tissue_guard) and the engine logs it. The next
 *      frame starts from rest, nothing stays frozen here (the engine's repeated-reset freeze
 *      clears itself after a hold time without a reset, sc_engine.c).
 * Boundary: the box bottom and bone are fixed, the box sides on rollers (sc_material.h); the
 * FEM and the implicit MSDS honour the rollers, the explicit MSDS holds those nodes whole.
 * Switching MSDS <-> FEM at run time changes only which solver advances the shared sc_nodes:
 * the shape and the velocities carry over, nothing is reallocated or rebuilt.
 *
 * Memory: one caller-owned sc_tissue (about 9.7 MB at the default limits: the MSDS, the
 * FEM's grid and Algorithm 1's springs; sizeof printed by bench-physics; static storage or
 * locked memory). Never allocates, never calls the OS.
 * Deterministic: same definition, case and pose sequence give bit-identical states
 * (sc_tissue_state_hash). Threads: one writer; readers (B-scan) read t->nodes between steps.
 */
#ifndef SC_TISSUE_H
#define SC_TISSUE_H

#include <stdint.h>

#include "sc_collider.h"
#include "sc_fem.h"
#include "sc_lumen.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_msds.h"
#include "sc_pose.h"
#include "sc_skin.h"
#include "sc_springs.h"
#include "sc_volume.h"

/* FEM: a contact node is held on the probe surface while its depth is above -this (mm); a
 * probe lifted slower than this per frame (0.06 mm/s at 60 Hz) would drag the skin along */
#define SC_TISSUE_CONTACT_HOLD_MM 1e-3f

typedef enum sc_tissue_method {
    SC_TISSUE_MSDS = 0,
    SC_TISSUE_FEM = 1,
} sc_tissue_method;

/* How the MSDS answers a contact (the FEM always holds penetrating nodes on the surface). */
typedef enum sc_tissue_contact {
    SC_TISSUE_CONTACT_PROJECT = 0, /* repulsion that removes the penetration in one step */
    SC_TISSUE_CONTACT_PENALTY = 1, /* the paper's spring-like repulsion kappa * depth */
} sc_tissue_contact;

typedef struct sc_tissue_def {
    sc_mesh_def mesh;
    sc_msds_def msds;         /* dt and iterations are used by both methods */
    sc_fem_def fem;
    sc_collider_def collider;
    sc_skin_def skin;
    uint8_t skin_enabled;     /* 0: no skin surface */
    sc_tissue_method method;  /* at start */
    sc_tissue_contact msds_contact;
} sc_tissue_def;

/* Why the stability guard reset the tissue (sc_tissue_stats.last_fault). */
typedef enum sc_tissue_guard {
    SC_TISSUE_GUARD_OK = 0,
    SC_TISSUE_GUARD_NOT_FINITE = 1,   /* a position or velocity is NaN or infinite */
    SC_TISSUE_GUARD_DISPLACEMENT = 2, /* a node moved further than the box diagonal */
    SC_TISSUE_GUARD_ENERGY = 3,       /* explicit MSDS kinetic energy above its runaway bound */
    SC_TISSUE_GUARD_SOLVER = 4,       /* the implicit solve (FEM or MSDS) was not finite */
    SC_TISSUE_GUARD_SKIN = 5,         /* the skin diverged */
} sc_tissue_guard;

typedef struct sc_tissue_stats {
    uint32_t frames;
    uint32_t faults;            /* guard resets since init */
    uint32_t last_fault;        /* sc_tissue_guard of the last reset (0: none yet) */
    uint32_t contacts;          /* tet-mesh contacts of the last frame */
    uint32_t kinematic;         /* FEM: nodes held on the probe surface in the last frame */
    uint32_t mpr_calls;         /* narrow-phase calls of the last frame (mesh + skin) */
    float max_disp_mm;          /* largest node displacement after the last frame */
} sc_tissue_stats;

/* Power iterations of the MSDS mass scaling per build step (100 in all, sc_msds.c). */
#ifndef SC_TISSUE_BUILD_POWER_ITS
#define SC_TISSUE_BUILD_POWER_ITS 10u
#endif

/* The phases of a build, in order (sc_tissue_build_step runs one, or one slice of the mass
 * scaling). */
typedef enum sc_tissue_build_phase {
    SC_TISSUE_BUILD_MESH = 0, /* grid and tets: O(tets) */
    SC_TISSUE_BUILD_LABELS,   /* each tet's label from the volume's label map: O(tets) */
    SC_TISSUE_BUILD_SPRINGS,  /* Algorithm 1: O(tets) */
    SC_TISSUE_BUILD_MSDS,     /* spring families, volume terms, masses: O(springs + nodes + tets) */
    SC_TISSUE_BUILD_MSDS_SCALE, /* the mass scaling's power iterations, at most
                                 * SC_TISSUE_BUILD_POWER_ITS per step: O(its x (9 N + tets)) */
    SC_TISSUE_BUILD_FEM,      /* pattern and assembly: O(tets) */
    SC_TISSUE_BUILD_CONTACT,  /* collider, skin, state at rest: O(nodes + skin) */
    SC_TISSUE_BUILD_DONE
} sc_tissue_build_phase;

typedef struct sc_tissue {
    sc_tissue_def def;
    uint8_t build_phase;         /* sc_tissue_build_phase; DONE once usable or after an error */
    uint8_t build_label;         /* default label of the build */
    const sc_volume *build_vol;  /* the build's label source (may be NULL) */
    sc_tissue_method method;
    sc_material_table mat;
    sc_mesh mesh;
    sc_nodes nodes;
    sc_msds msds;
    /* Algorithm 1's springs are read by the MSDS build phase alone (sc_msds_init_begin turns
     * them into its families) and the FEM is built after it: the two share their storage
     * (0.04 MB of the MCU's 0.5 MB, 1.3 MB per slot at 32x16x16). springs is meaningless once
     * SC_TISSUE_BUILD_FEM has run. */
    union {
        sc_springs springs;
        sc_fem fem;
    };
    sc_collider collider;
    sc_contact_set contacts;
    sc_skin skin;
#if SC_PHYS_LUMEN
    sc_lumen lumen; /* vessel lumens: pressure-volume law and drive (sc_lumen.h) */
#endif
    uint8_t kinematic[SC_MAX_NODES];
    const sc_pool_dev *pool; /* workers of the solvers (NULL: serial); sc_tissue_set_pool */
    float box_diag_mm;
    sc_tissue_stats stats;
    /* a second tool's tip pushing tissue (the tracked needle), sc_tissue_set_tip */
    uint8_t tip_active;
    float tip_mm[3];
    float tip_radius_mm;
    uint32_t tip_contacts; /* of the last step */
} sc_tissue;

/* Defaults: default mesh (32x16x16 over 40 x 20 x 30 mm), MSDS, default collider (linear
 * probe footprint), skin over the top of the box, FEM defaults. */
sc_tissue_def sc_tissue_default_def(void);

/* Build everything for a case: mesh, labels from vol's label map (see sc_material_assign;
 * vol may be NULL: every tet gets default_label), springs, MSDS, FEM, collider, skin; state
 * at rest. Call at case load. Cost: O(tets + nodes + springs) plus the FEM's assembly.
 * Never allocates. Errors: SC_ERR_INVALID_ARG, and the errors of sc_mesh_build,
 * sc_material_table_validate, sc_material_assign, sc_springs_from_tets, sc_msds_init,
 * sc_fem_init, sc_collider_init, sc_skin_init. */
int sc_tissue_init(sc_tissue *t, const sc_tissue_def *def, const sc_volume *vol,
                   const sc_material_table *mat, uint8_t default_label);

/* The same build in phases (sc_tissue_build_phase), for a case switch prepared between frames
 * while another tissue runs: begin validates and keeps the inputs (vol must stay valid until the
 * last step; O(1)); each step runs the next phase (its cost above) and returns 0 (more
 * phases), 1 (built, state at rest), or the phase's error (then the tissue is unusable until
 * built again). Step errors: SC_ERR_STATE (no build begun), and those of sc_tissue_init. */
int sc_tissue_build_begin(sc_tissue *t, const sc_tissue_def *def, const sc_volume *vol,
                          const sc_material_table *mat, uint8_t default_label);
int sc_tissue_build_step(sc_tissue *t);

/* Run one frame with the probe at *probe (volume frame), or no contact (probe == NULL).
 * Cost: MSDS O(iterations * 14 N + iterations * contacts); FEM: see sc_fem_step; collider
 * O(contact-area candidates); skin O(iterations * skin particles); guard O(N).
 * Never allocates. Returns 0, SC_ERR_POSE_IMPLAUSIBLE (pose refused: frame run without
 * contact), or SC_ERR_PHYS_UNSTABLE (the guard reset the tissue to rest). */
int sc_tissue_step(sc_tissue *t, const sc_pose *probe);

/* The tracked needle's tip for the next steps: a sphere of radius_mm at tip_mm (volume frame)
 * whose contacts join the probe's (sc_collider_append_sphere), so the tip pushes tissue; active
 * 0 removes it. O(1); the step then costs O(nodes) more. Never fails (bad values: inactive). */
void sc_tissue_set_tip(sc_tissue *t, int active, const float tip_mm[3], float radius_mm);

/* Switch the solver; the current shape and velocities are kept. O(1) (O(N) on the FEM side:
 * kinematic flags cleared). Errors: SC_ERR_INVALID_ARG (unknown method). */
int sc_tissue_set_method(sc_tissue *t, sc_tissue_method m);

/* Change dt and iterations (both methods) at run time. O(N) if the mass scaling changes.
 * Errors: as sc_msds_def_validate. */
int sc_tissue_set_msds_def(sc_tissue *t, const sc_msds_def *def);

/* Back to rest (nodes, skin, contacts, kinematic flags). O(N). */
void sc_tissue_reset(sc_tissue *t);

/* The worker pool the solvers split their loops over (hal/sc_hal_pool.h; NULL: serial), kept
 * until changed (sc_tissue_build_begin sets NULL: call it after). Results are bit-identical
 * for every worker count. O(1). */
void sc_tissue_set_pool(sc_tissue *t, const sc_pool_dev *pool);

/* FNV-1a 64 over positions and velocities of the nodes and the skin. O(N). */
uint64_t sc_tissue_state_hash(const sc_tissue *t);

/* The force the tissue pushes back on the probe after the last step (N, volume frame, out[3]
 * may be NULL), as its magnitude: the elastic force K (x - X) of the tissue at the nodes in
 * contact with the probe, summed (the implicit methods hold those nodes on the probe, so that
 * force is the probe's reaction; on the free nodes it is balanced). K is the matrix the last
 * implicit step assembled (for the corotated FEM its rotated blocks: an estimate that is exact
 * for the linear FEM at equilibrium); the skin layer's share is not included. Returns 0 with no
 * contact, -1 (not available) for the explicit MSDS (it has no assembled K) or an unbuilt
 * tissue. O(contacts x 27) block reads, bounded by SC_MAX_CONTACTS, on the tissue's worker pool
 * (ranges of 256 contacts summed in order: the same bits for any worker count; up to 256
 * contacts the serial sum's). Never allocates. */
float sc_tissue_probe_force_n(const sc_tissue *t, float out[3]);

#if SC_PHYS_LUMEN
/* The lumens' drive (heart rate, pulse pressure, waveform, respiration, Valsalva), see
 * sc_lumen.h. Errors: SC_ERR_INVALID_ARG (NULL), sc_lumen_drive_validate's. O(1). */
int sc_tissue_set_drive(sc_tissue *t, const sc_lumen_drive *d);
/* Start (on != 0) or end a Valsalva manoeuvre: the veins distend. O(1). */
void sc_tissue_set_valsalva(sc_tissue *t, int on);
/* Real seconds per frame for the drive's clock (the engine's frame period). SC_ERR_RANGE. */
int sc_tissue_set_frame_s(sc_tissue *t, float frame_s);
#endif

#endif /* SC_TISSUE_H */
