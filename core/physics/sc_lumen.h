/*
 * sc_lumen.h: blood-filled vessel lumens as pressure-volume chambers (the tissue step's lumen
 * pass), and the cardiac and respiratory drive of their pressures.
 *
 * A vessel is a connected region of tets (face neighbours, sc_mesh.tet_nbr) whose label has a
 * lumen law in config/sc_materials.h (SC_LUMEN_LIST: veins, arteries; a thrombus is solid
 * clot and has none). Its tets keep a soft filler material from the material table (the
 * solvers treat them as very soft solid, which keeps every tet well shaped); what holds the
 * vessel open is the lumen pressure, which this pass applies each frame as forces on the
 * lumen's boundary faces (faces towards a tet of another region; faces on the mesh's hull are
 * left out: the vessel continues beyond the box):
 *   f_node += dP A_face / 3 along the face's outward normal (out of the lumen), per face node.
 * dP is the lumen pressure above the rest state's (the mesh's rest shape is the equilibrium at
 * the vessel's mean blood pressure, so dP = 0 at rest and the rest stays an equilibrium).
 *
 * The pressure-volume law (a tube law, Shapiro 1977, in volume form): with s = (V0 - V) / V0
 * the lumen's volume strain (V the summed deformed volume of the region's tets, V0 at rest),
 *   g(s) = H tanh(B s / H)   s >= 0 (compressed): the wall, tensioned by the blood pressure,
 *                            holds the lumen round with stiffness B until the tissue around
 *                            presses with the vessel's blood pressure H = P_mean; beyond that
 *                            the wall buckles and the blood leaves the section (collapse);
 *   g(s) = B s               s < 0 (distended): the wall's stretch resists.
 *   dP = g(s) + d(t)         d(t): the drive, the blood pressure above its mean (pulse for
 *                            arteries, respiration and Valsalva for veins, sc_lumen_drive).
 * So a vein (H ~ 8 mmHg) collapses at a firm press and an artery (H ~ 93 mmHg) stays open, for
 * the reason a scanner shows: transmural pressure. A collapsed lumen's walls meet: the solvers'
 * volume floor (sc_fem.h, sc_msds_implicit.h floor_*: a tet below 1% of its rest volume meets a
 * stiff bulk term, implicit) keeps them from passing through each other; the law itself adds
 * no force there (g = H, bounded).
 *
 * Integration: the pressure is explicit (evaluated from the state at the start of the frame),
 * not linearised into the solvers' matrix. Why: its Jacobian dP/dV a a^T couples every node of
 * the lumen's boundary (rank one, dense), which the grid matrix's fixed stencil (sc_grid.h) cannot
 * hold without a second solve per frame (Sherman-Morrison: twice the CG cost); and the law is
 * bounded (|g| <= H on the compressed side), so an explicit force cannot inject unbounded energy.
 * Explicit alone would still overshoot where B exceeds the stiffness of the tissue around the
 * lumen (the lagged pressure of a frame pushes further than the tissue's answer to it), so the
 * applied pressure is a per-vessel state relaxed toward the law once per frame,
 *   p <- p + theta (g(s) - p) if that rises, else p <- g(s),   theta = 1 / (1 + B c),
 * with c = 2 (1 + nu) / E the volume compliance of a cylindrical hole in an infinite medium of
 * the softest material around the lumen (plane strain): an upper bound on the lumen's real
 * compliance (the box's fixed bottom, the probe's held nodes and the filler only stiffen it),
 * so the relaxed iteration's error factor 1 - theta (1 + B c_real) stays in [0, 1): monotone,
 * no oscillation, at the price of a few frames' lag where the tissue is much stiffer than the
 * bound assumes. A falling pressure is taken at once: a lumen let go (the probe lifted, or
 * jumped away between two frames) must not stay over-pressured for 1 / theta frames (it blew
 * the lumen up past the guard's bound in the robustness test); from below the relaxed rise is
 * monotone again. The law is bounded: s is clamped to [-1, 1], and faces of inverted (crushed)
 * tets are not loaded. The drive d(t) is fed forward (applied pressure p + d(t), unrelaxed):
 * through the relaxation a pulse was smoothed to 0.7% of the artery's area (theta 0.02 in the
 * neck phantom); fed forward the wall sees it in the frame it is due and the law answers the
 * volume change with its lag (3% area, 1.5% diameter peak to peak, test_vessel_drive).
 *
 * Sections (arteries): the law above is a wall's answer to its transmural pressure, and a
 * wall answers where it is pressed. An artery's blood pressure is the circulation's (the heart
 * and the whole arterial tree hold it; the segment in the box does not set it by its volume),
 * so its law is evaluated per section: the lumen is cut across its axis (the mesh axis along
 * which its rest extent is largest, relative to the box) into up to SC_LUMEN_SLICES slabs of at
 * least one cell, each with its own volume strain s, relaxed pressure and faces: the section
 * squeezed most answers with its own strain instead of the lumen's mean. Measured
 * (test_press_pulse, neck-ijv, MSDS, default mesh, 16 mm, pulse on): the whole lumen's law
 * answered 4.2-4.4 kPa at the landing, the middle section's 4.3-5.2 kPa (the end sections
 * 2.6-3.0 kPa), and the artery's least image-area ratio over the holds rose from 0.769 to
 * 0.783. A vein keeps one section (not tried sectioned: the press sweeps' vein figures are
 * measured with the whole-lumen law).
 *
 * Time: the drive's phases advance by frame_s (real seconds per frame, sc_lumen_set_frame_s;
 * the physics' own simulated time per frame is a solver setting, not the clock), so the pulse
 * runs at the set heart rate in the image.
 *
 * Memory: one label byte per tet (region) and SC_LUMEN_MAX vessels in the caller's sc_lumen
 * (SC_MAX_TETS + ~1.6 KB, of which 1 KB the sections: 8 B per section and vessel; the
 * Cortex-M7 image grew by 1,408 B with them and sc_msds.roller). Never allocates, never calls
 * the OS. Deterministic: fixed loop order over tets, float arithmetic only. Threads: one writer (the tissue step), whose
 * passes' ranges may run on the worker pool ("Workers" above).
 */
#ifndef SC_LUMEN_H
#define SC_LUMEN_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_hal_pool.h"
#include "sc_material.h"
#include "sc_mesh.h"

/* vessels per mesh (regions beyond are left solid filler and counted in sc_lumen.dropped) */
#ifndef SC_LUMEN_MAX
#define SC_LUMEN_MAX 8u
#endif

/* sections per artery along its axis (sc_lumen_vessel.slices; 8 B per section and vessel) */
#ifndef SC_LUMEN_SLICES
#define SC_LUMEN_SLICES 16u
#endif

/* Workers (hal/sc_hal_pool.h): the frame's passes (volumes, boundary forces, clear) run over
 * ranges of whole cells (5 tets each) chosen by the mesh alone: a mesh of at most
 * SC_LUMEN_SERIAL_NODES nodes (up to 32x16x16: every phantom and the paper's meshes) is one
 * range, the serial loop's order exactly; a larger one is cut into ranges of at least
 * (nx - 1)(ny - 1) + nx + 1 cells (so that ranges two apart share no node) and at most
 * SC_LUMEN_RANGES of them, their count taken down to a multiple of four (an even number per
 * phase: 20 at 48x24x24, 28 at 64x32x32, 24 at 40x16x28). The volumes: a partial sum per
 * range and vessel section in tet order, the partials added in range order by the caller; the
 * forces and the clear: the even ranges at the same time, then the odd ones (a node on a seam
 * after an odd range takes the next even range's faces first). A fixed order, the same for
 * every worker count; the per-range partials take SC_LUMEN_RANGES x 516 B (33 KB per tissue
 * slot on the host; the MCU, whose limits keep one range, sums on the stack as before: 16 B). */
#ifndef SC_LUMEN_SERIAL_NODES
#define SC_LUMEN_SERIAL_NODES 16384u
#endif
#ifndef SC_LUMEN_RANGES
#define SC_LUMEN_RANGES (SC_MAX_NODES > SC_LUMEN_SERIAL_NODES ? 64u : 1u)
#endif

typedef enum sc_lumen_kind {
    SC_LUMEN_NONE = 0,
    SC_LUMEN_VEIN = 1,
    SC_LUMEN_ARTERY = 2,
} sc_lumen_kind;

/* Arterial pressure waveform over one cardiac cycle (normalised 0 diastolic .. 1 systolic). */
typedef enum sc_lumen_wave {
    SC_LUMEN_WAVE_ARTERIAL = 0, /* upstroke in 15% of the cycle, exponential run-off with a
                                   dicrotic notch (default) */
    SC_LUMEN_WAVE_SINE = 1,     /* 0.5 - 0.5 cos(2 pi phase) */
} sc_lumen_wave;

/* The drive of the lumen pressures (blood pressures above their means). */
typedef struct sc_lumen_drive {
    float heart_rate_bpm;   /* 0 (no pulse) or 20..250 */
    float pulse_pa;         /* arterial systolic - diastolic, 0..20 kPa */
    uint8_t wave;           /* sc_lumen_wave */
    float resp_rate_bpm;    /* breaths per minute, 0 (none) or 4..60 */
    float resp_pa;          /* venous respiratory swing (amplitude), 0..5 kPa */
    float valsalva_pa;      /* venous pressure rise during a Valsalva manoeuvre, 0..10 kPa */
    uint8_t valsalva;       /* 1: manoeuvre held (sc_lumen_set_valsalva) */
} sc_lumen_drive;

/* One lumen law (config/sc_materials.h SC_LUMEN_LIST). */
typedef struct sc_lumen_law {
    uint8_t kind;      /* sc_lumen_kind; SC_LUMEN_NONE: the label is solid */
    float hold_pa;     /* H: the mean blood pressure, > 0 */
    float bulk_pa;     /* B: the lumen's stiffness against volume change, > 0 */
} sc_lumen_law;

typedef struct sc_lumen_vessel {
    uint8_t label;
    uint8_t kind;
    uint32_t tets;
    float hold_pa, bulk_pa;
    float theta;        /* relaxation of the applied pressure (above) */
    float v0_mm3;       /* rest volume */
    float v_mm3;        /* volume at the start of the last frame */
    float p_pa;         /* relaxed law pressure g(s) (state; a sectioned lumen: its largest) */
    float drive_pa;     /* d(t) of the last frame */
    /* sections (arteries, see "Sections" above): the law per slab of the lumen across its
     * axis; 1: the whole lumen is one section (veins) */
    uint8_t slices;
    uint8_t axis;       /* 0 x, 1 y, 2 z: the axis the lumen runs along */
    float lo_mm;        /* the lumen's rest extent's start along axis */
    float slab_mm;      /* section length along axis */
    float s_v0[SC_LUMEN_SLICES]; /* rest volume per section */
    float s_p[SC_LUMEN_SLICES];  /* relaxed law pressure per section (state) */
} sc_lumen_vessel;

typedef struct sc_lumen {
    uint32_t count;                 /* vessels */
    uint32_t dropped;               /* regions beyond SC_LUMEN_MAX (left solid) */
    sc_lumen_vessel v[SC_LUMEN_MAX];
    sc_lumen_law law[SC_MAX_LABELS];
    sc_lumen_drive drive;
    float frame_s;                  /* real time per frame, s */
    float heart_phase, resp_phase;  /* 0..1 */
    float wave_mean;                /* mean of the arterial waveform over a cycle */
    uint32_t faces;                 /* lumen boundary faces loaded in the last frame */
    uint8_t enabled;                /* 0: the pass does nothing (vessels as solid filler) */
    /* workers ("Workers" above): the pool (NULL: serial; set by the owner after init), the
     * split (set by sc_lumen_init) and the per-range partials of the last frame */
    const sc_pool_dev *pool;
    uint32_t ranges;                /* 1 .. SC_LUMEN_RANGES */
    uint32_t span_tets;             /* tets per range (whole cells) */
#if SC_LUMEN_RANGES > 1
    float part_vol[SC_LUMEN_RANGES][SC_LUMEN_MAX][SC_LUMEN_SLICES];
#endif
    uint32_t part_faces[SC_LUMEN_RANGES];
    uint8_t region[SC_MAX_TETS];    /* vessel of each tet, 1..count; 0: none */
#if SC_LUMEN_RANGES > 1
    /* The lumens' tets in tet order, each packed with what does not change after
     * sc_lumen_init: the tet (bits 0..19), its section (20..24), the faces it loads (25..28:
     * no lumen across them); range r's from list_start[r]. The frame's passes read these
     * instead of scanning the region bytes and finding the sections and the faces again, and
     * the forces take the volume pass's own volumes (list_vol): the same operations in the same
     * order (a 64x32x32 press on two workers spent 1 ms a frame in these passes). The MCU, whose
     * limits keep one range, scans as before (its SRAM has no room for 8 bytes a tet). */
    uint32_t list_start[SC_LUMEN_RANGES + 1u];
    uint32_t list[SC_MAX_TETS];
    float list_vol[SC_MAX_TETS];   /* the last volume pass's tet volumes, mm^3, list order */
#endif
} sc_lumen;

/* The laws of config/sc_materials.h, per label (SC_LUMEN_NONE elsewhere). O(labels). */
void sc_lumen_laws_default(sc_lumen_law law[SC_MAX_LABELS]);

/* The drive of config/sc_materials.h (heart rate, pulse pressure, respiration, Valsalva). */
sc_lumen_drive sc_lumen_drive_default(void);

/* Check a drive's ranges (above). O(1). Errors: SC_ERR_INVALID_ARG (NULL, unknown wave),
 * SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_lumen_drive_validate(const sc_lumen_drive *d);

/* The passes' ranges ("Workers" above) of a grid mesh of nx x ny x nz nodes: *ranges (1 up to
 * SC_LUMEN_SERIAL_NODES nodes) of *span_cells cells each (the last one shorter); ranges two
 * apart share no node. By the mesh alone (test_sc_grid_split checks every mesh within the
 * limits). */
void sc_lumen_split(uint32_t nx, uint32_t ny, uint32_t nz, uint32_t *ranges,
                    uint32_t *span_cells);

/* Find the vessels of a labelled mesh (flood fill over face neighbours, tets of a label with a
 * lumen law), their rest volumes and relaxations (theta from the softest tet across the
 * lumen's boundary, mat); pressures zero, phases zero, the default drive, frame_s 1 /
 * SC_FRAME_RATE_DEFAULT_HZ, enabled, the split of the passes ("Workers"), no pool (NULL). Call at case load after sc_material_assign.
 * O(tets). Never allocates. Errors: SC_ERR_INVALID_ARG (NULL, a label outside the table). */
int sc_lumen_init(sc_lumen *l, const sc_mesh *m, const sc_material_table *mat);

/* Pressures back to zero and phases to the start of a cycle (tissue reset). O(vessels). */
void sc_lumen_reset(sc_lumen *l);

/* Set the drive (sc_lumen_drive_validate's errors; the old drive stays). O(1). */
int sc_lumen_set_drive(sc_lumen *l, const sc_lumen_drive *d);

/* Start (on != 0) or end a Valsalva manoeuvre. O(1). */
void sc_lumen_set_valsalva(sc_lumen *l, int on);

/* Real seconds per frame for the drive's clock: finite, 1e-4..1. Errors: SC_ERR_RANGE. */
int sc_lumen_set_frame_s(sc_lumen *l, float frame_s);

/* The frame's lumen pass, before the solver step: advance the drive by frame_s, measure each
 * vessel's volume in the current state, relax its pressure, and add the boundary forces to
 * n->fx/fy/fz (which the solvers read as external forces). O(tets), on l->pool ("Workers").
 * Deterministic: the same bits for every worker count. */
void sc_lumen_apply(sc_lumen *l, const sc_mesh *m, sc_nodes *n);

/* Zero the external forces of every lumen boundary node (after the solver step). O(tets), on
 * l->pool. */
void sc_lumen_clear(const sc_lumen *l, const sc_mesh *m, sc_nodes *n);

/* The drive's blood pressure above the mean now, for a vessel kind (Pa). O(1). */
float sc_lumen_drive_pa(const sc_lumen *l, uint8_t kind);

/* Summed deformed volume of vessel k (1-based region id) in positions x, y, z. O(tets). */
float sc_lumen_volume_mm3(const sc_lumen *l, const sc_mesh *m, const float *x, const float *y,
                          const float *z, uint32_t k);

#endif /* SC_LUMEN_H */
