/*
 * sc_bscan.h: B-mode image synthesis through the deformed tet mesh, streamed line by line
 * (paper section IV).
 *
 * Per pixel: its position in the deformed mesh is found, the containing tet's barycentric
 * coordinates carry it to the rest configuration, and the case volume is sampled there
 * (trilinear). Pixels outside the mesh are sampled rigidly (at their own position); a pixel whose
 * rest position carries the label SC_LABEL_OUTSIDE (air above the skin) is dark, and without
 * probe contact the whole image is dark, as a real probe in air shows. Beyond the case volume
 * (deeper than it, or beside it) the tissue continues: the 6 mm slab along the face the pixel is
 * beyond, mirrored back and forth (vessels deeper inside are not mirrored out; where the slab
 * holds bone, the voxel straight across the face is repeated: a shadow stays a shadow), darkened by
 * 0.5 dB per mm outside, so there is no black "no data" band; above its top face (air) the top
 * voxels are repeated. Such pixels carry the label SC_LABEL_OUTSIDE, so the compression measure
 * ignores them. Then display processing (gain, 8-band time-gain compensation, dynamic range) and
 * each scan line leaves through the HAL display as soon as it is computed.
 *
 * Three mappers, chosen at run time, that agree up to ties on tet faces:
 * - SC_BSCAN_MAP_ORACLE: per pixel, every tet of the mesh is tried (test oracle; slow).
 * - SC_BSCAN_MAP_REGIONS: the paper's path: the tets cut by the image plane, binned into R
 *   regions (groups of scan lines); per line, recursive subdivision between the end pixels,
 *   linear interpolation of rest positions where both ends fall in the same tet.
 * - SC_BSCAN_MAP_WALK (default, fastest): each scan line is a straight ray; it enters the mesh
 *   through a boundary triangle (found among the boundary triangles cut by the image plane) and
 *   walks from tet to face neighbour, the exit parameter of each tet coming from its
 *   barycentric coordinates along the ray; inside a tet the rest position is affine in the
 *   sample index. Where the deformed mesh folds (a tet on the way is inverted or flat, as
 *   under a firm press where a vein's walls meet, or the line starts inside the mesh), the
 *   walker locates the next sample among the tets cut by the plane (the region path's bins)
 *   and walks on from the tet found; samples covered by inverted tets only take the deepest
 *   of those. A line the walker still cannot trust (a walk over SC_BSCAN_MAX_WALK_STEPS, a
 *   degenerate exit) is redone by the region path.
 *
 * Folds: a point of a folded mesh lies in more than one tet (the fold's layers). All three
 * mappers prefer a positively oriented tet (tissue that is there) to an inverted one (a
 * layer turned inside out); among several the oracle takes the one that holds the point
 * deepest (largest smallest barycentric coordinate), the walker stays on the layer it walks,
 * the region path takes the first it finds: inside a fold they may differ, elsewhere they agree
 * up to ties on faces.
 *
 * The compression measure comes from the same pass: for each label, the image area whose rest
 * position has that label now, against the area with that label in the rigid (undeformed) slice
 * at the same pose: the instructor's "did the vein collapse?". The reference extends
 * rest_margin_mm above the probe face (every 4th sample there), so that a vessel the probe has
 * pushed down into view counts whole at rest; with a press deeper than the margin the part above
 * it is missing from the reference (the ratio then overstates what is left). The default
 * margin, 60 mm (the top of its range; formerly 15 mm, which a 16 mm press already exceeded),
 * covers a press down to the bottom of any mesh box; it costs one label lookup per 4 samples
 * (0.25 mm each) per line above the face.
 *
 * Memory: all state in the caller's sc_bscan, sized by config/sc_config.h (about 2 MB with the
 * default limits). Never allocates, never calls the OS. Threads: one writer. Deterministic:
 * float32 throughout, no data-dependent order; identical inputs give identical images.
 */
#ifndef SC_BSCAN_H
#define SC_BSCAN_H

#include <stdint.h>

#include "sc_acoustics.h"
#include "sc_config.h"
#include "sc_hal_display.h"
#include "sc_hal_pool.h"
#include "sc_labels.h"
#include "sc_mesh.h"
#include "sc_pose.h"
#include "sc_psf.h"
#include "sc_scan_geom.h"
#include "sc_volume.h"

_Static_assert(SC_BSCAN_TGC_BANDS == SC_DISPLAY_TGC_BANDS, "the frame record carries every band");

enum {
    SC_BSCAN_MAP_WALK = 0,
    SC_BSCAN_MAP_REGIONS = 1,
    SC_BSCAN_MAP_ORACLE = 2,
    SC_BSCAN_MAP_COUNT
};

/* Runtime settings. The volume's 8-bit values are read as log-compressed echo over
 * volume_range_db; the displayed value of intensity I at depth band b is
 *     255 * (I/255 * Rv - Rv + gain_db + tgc_db[b] + R) / R, clamped to 0..255,
 * with Rv = volume_range_db and R = dynamic_range_db (TGC interpolated linearly between band
 * centres). With gain 0, TGC 0 and R = Rv the display shows the volume values unchanged. */
typedef struct sc_bscan_def {
    sc_scan_def scan;
    uint32_t mapper;                  /* SC_BSCAN_MAP_* */
    uint32_t regions_n;               /* R of the region path, 1..SC_BSCAN_MAX_REGIONS */
    float gain_db;                    /* overall gain, [-60, 60] */
    float tgc_db[SC_BSCAN_TGC_BANDS]; /* per depth band, shallow first, [-60, 60] */
    float dynamic_range_db;           /* displayed range, [10, 120] */
    float volume_range_db;            /* range the volume's 0..255 stands for, [10, 120] */
    float focus_mm;            /* transmit focus below the probe face, (0, 300]: the display's
                                  focus marker (and the beam's narrowest point) */
    float rest_margin_mm;      /* the compression measure's rest reference extends this far above
                                  the probe face (tissue pushed into view), [0, 60] */
    uint32_t acoustics;        /* 1: beam-dependent acoustics along each line (sc_acoustics.h);
                                  0: the volume already holds them (real-patient volumes, the baked
                                  phantoms) */
    sc_acoustics_def acoustic; /* per-label table, frequency, TGC reference */
    uint32_t psf;              /* 1: speckle from the rest-configuration scatterer field and the
                                  beam's point spread (sc_psf.h; needs SC_BSCAN_PSF); 0: the
                                  volume's own texture */
    sc_psf_def psf_def;        /* pulse bandwidth, aperture, slice thickness, seed */
} sc_bscan_def;

/* Labels whose area the compression measure follows (all labels are counted). */
typedef struct sc_bscan_status {
    uint32_t frame_no;
    uint8_t contact;
    uint8_t areas_valid;                 /* 0: no contact or no label map */
    float area_now_mm2[SC_LABEL_COUNT];  /* image area by rest label, this frame */
    float area_rest_mm2[SC_LABEL_COUNT]; /* same pose, undeformed mesh */
    float area_ratio[SC_LABEL_COUNT];    /* now / rest; -1 where the rest area is 0 */
    float image_area_mm2;                /* the whole image (all labels, outside included) */
    uint32_t pixels_in_mesh;             /* this frame */
    uint32_t plane_hull_segments;        /* boundary triangles cut by the plane */
    uint32_t plane_tets;                 /* region path: tets cut by the plane */
    uint32_t walk_steps;                 /* walker: tet steps this frame */
    /* cumulative counters of degraded work (each stays exact or falls back, see .c) */
    uint32_t walk_aborts;      /* a line exceeded SC_BSCAN_MAX_WALK_STEPS */
    uint32_t event_overflows;  /* a line crossed the boundary > SC_BSCAN_MAX_LINE_EVENTS */
    uint32_t line_fallbacks;   /* lines the walker handed to the region path (a walk over its
                                  step limit, a degenerate exit) */
    uint32_t walk_relocations; /* folds the walker crossed by locating (inverted or flat tets,
                                  a line start inside the mesh) */
    uint32_t region_overflows; /* region path over its limits (walker result kept) */
    uint32_t display_errors;   /* display calls that returned an error */
} sc_bscan_status;

/* A boundary triangle of the mesh: face `face` (opposite that vertex) of tet `tet`. */
typedef struct sc_bscan_hull_face {
    uint32_t tet;
    uint32_t face;
} sc_bscan_hull_face;

/* A boundary triangle cut by the image plane: its 2D segment in the image frame (x, z). */
typedef struct sc_bscan_seg {
    float ax, az, bx, bz;
    float nx, nz; /* in-plane part of the outward normal */
    uint32_t tet;
    uint32_t face;
    int32_t line_lo, line_hi;
} sc_bscan_seg;

/* Region path: a tet cut by the plane and its box in the image frame (x, z); its maps come from
 * the tet cache of the line that tests it (sc_bscan_tcache). */
typedef struct sc_bscan_ptet {
    float xmin, xmax, zmin, zmax;
    uint32_t tet;   /* mesh tet */
    int32_t orient; /* 1 positively oriented, -1 inverted (a fold of the deformed mesh) */
} sc_bscan_ptet;

/* Samples [k0, k1) of a line inside the mesh; rest position in voxel units is a + k b. */
typedef struct sc_bscan_run {
    uint16_t k0, k1;
    float a[3], b[3];
} sc_bscan_run;

/* Walker cache: a tet's barycentric coordinates and rest position as affine functions of
 * the image-frame (x, z), valid for the frame `epoch`; the maps are set unless the tet is flat
 * (orient 0). The walker steps through positively oriented tets; the fold search (the region
 * bins) tests inverted ones too. */
typedef struct sc_bscan_tcache {
    uint32_t epoch, tet;
    int32_t orient;   /* 1 positively oriented, -1 inverted, 0 flat (no maps) */
    float lam[3][4];  /* lambda_i = lam[0][i] + lam[1][i] x + lam[2][i] z (face i's coordinate) */
    float rest[3][4]; /* rest position d = rest[0][d] + rest[1][d] x + rest[2][d] z; [3] 0 */
} sc_bscan_tcache;

/* Entries of the walker's tet cache (power of two). */
#ifndef SC_BSCAN_TET_CACHE
#define SC_BSCAN_TET_CACHE 4096u
#endif
_Static_assert((SC_BSCAN_TET_CACHE & (SC_BSCAN_TET_CACHE - 1u)) == 0u,
               "SC_BSCAN_TET_CACHE must be a power of two");

typedef struct sc_bscan_event {
    float s;       /* line parameter, samples */
    uint32_t seg;  /* index into segs */
    uint8_t entry; /* 1: the line enters the mesh here */
} sc_bscan_event;

/* What a line hook sees of one computed scan line (sc_bscan_set_line_hook): every sample's label
 * in the deformed configuration (the label at its rest position: a vessel squeezed shut has no
 * lumen samples left), and its rest position in voxel-index units: a + k b inside the mesh runs,
 * f0 + k fd elsewhere (rigid). Valid only during the call. */
typedef struct sc_bscan_line_view {
    uint32_t line, lines_n, samples_n;
    const uint8_t *labels;       /* samples_n labels */
    const sc_bscan_run *runs;    /* run_count runs, increasing k, disjoint */
    uint32_t run_count;
    float f0[3], fd[3];          /* rigid position of sample k: f0 + k fd (voxel units) */
    float org_x, org_z;          /* sample 0's position in the image frame (y = 0), mm */
    float dir_x, dir_z;          /* the line's direction in the image frame, mm per sample */
    uint8_t *out;                /* the displayed samples, before they leave: a hook may draw
                                  * into them (the tracked needle) */
    const sc_xform *img2vol;     /* image frame -> volume frame of this frame */
} sc_bscan_line_view;

/* Called once per computed line, in line order, with the probe in contact (never for a dark
 * frame); it must be bounded (it runs inside the imaging stage) and must not call back into b. */
typedef void (*sc_bscan_line_hook_fn)(void *ctx, const sc_bscan_line_view *view);

/* The rest reference above the probe face (the compression measure's margin) of the last frame
 * and what it was computed from: it depends on the pose and the volume only, not on the mesh,
 * so a frame with the same pose (bit for bit: a held probe), the same volume (labels pointer,
 * dimensions, origin, spacing) and settings takes the counts instead of labelling the margin
 * again. Forgotten by sc_bscan_set_def and sc_bscan_attach_mesh (a case switch). */
typedef struct sc_bscan_margin_memo {
    uint32_t valid;
    sc_xform pose; /* probe -> volume */
    const uint8_t *labels;
    uint32_t dim[3];
    float origin_mm[3], spacing_mm[3];
    uint32_t margin_n;
    uint32_t n[SC_LABEL_COUNT];
    int32_t k[SC_LABEL_COUNT];
} sc_bscan_margin_memo;

/* Counters of one range of lines (the status's work counters), added to the status in range
 * order after the frame's lines. */
typedef struct sc_bscan_counts {
    uint32_t pixels_in_mesh, walk_steps, walk_aborts, event_overflows, line_fallbacks,
        walk_relocations, region_overflows;
} sc_bscan_counts;

/* Label counts of the compression measure (integers: their sums do not depend on the order). */
typedef struct sc_bscan_area_acc {
    uint32_t now_n[SC_LABEL_COUNT], now_k[SC_LABEL_COUNT];
    uint32_t rest_n[SC_LABEL_COUNT], rest_k[SC_LABEL_COUNT];
    /* rest reference above the probe face (negative sample indices, every 4th sample) */
    uint32_t margin_n[SC_LABEL_COUNT];
    int32_t margin_k[SC_LABEL_COUNT];
} sc_bscan_area_acc;

#if SC_BSCAN_RANGES > 1
/* One range of a frame's lines on the worker pool (sc_bscan_set_pool): its own scratch, so that
 * ranges run at the same time on different workers; the walker's tet cache is a slice of the
 * shared one (SC_BSCAN_TET_CACHE / SC_BSCAN_RANGES entries each). About 6.6 KB plus
 * SC_BSCAN_RANGE_RUNS x 28 B and SC_BSCAN_RANGE_ACTIVE x 4 B. */
typedef struct sc_bscan_range {
    uint32_t l0, l1;    /* lines [l0, l1) */
    uint32_t done_to;   /* lines [l0, done_to) computed (their output stored) */
    uint32_t stopped;   /* 1: the rest of the range needs the caller (see sc_bscan.c) */
    uint32_t run_used;  /* runs of the stored lines (a line hook reads them at emission) */
    uint32_t regions_need; /* a line of the range wanted the region bins */
    sc_bscan_counts counts;
    sc_bscan_area_acc acc;
    uint32_t active_n;
    uint32_t active[SC_BSCAN_RANGE_ACTIVE];
    sc_bscan_event events[SC_BSCAN_MAX_LINE_EVENTS];
    uint8_t rest_label[SC_MAX_SCAN_SAMPLES];
    SC_ALIGN_HOT uint32_t pos_h[3][SC_MAX_SCAN_SAMPLES + 8u];
    sc_bscan_run runs[SC_BSCAN_RANGE_RUNS];
} sc_bscan_range;
#endif

typedef struct sc_bscan {
    sc_bscan_def def;
    const sc_pool_dev *pool; /* NULL: lines one after the other on the caller */
    sc_bscan_line_hook_fn line_hook; /* NULL: none (sc_bscan_set_line_hook) */
    void *line_hook_ctx;
    sc_scan_geom geom;
    float lut_a; /* display: out = lut_a * I + lut_b[k] */
    float lut_b[SC_MAX_SCAN_SAMPLES];
    int64_t lut_b_fx[SC_MAX_SCAN_SAMPLES]; /* lut_b in 38.26 fixed point, + 1/2 */
    /* mesh boundary, from sc_bscan_attach_mesh */
    uint32_t hull_count;
    uint32_t mesh_tets;
    uint32_t mesh_grid; /* 1: sc_mesh_build's cell layout (tets 5c..5c+4 of cell c, corners of
                           c): the region bins find the plane's tets cell row by cell row */
    sc_bscan_hull_face hull[SC_BSCAN_MAX_HULL_FACES];
    /* per frame: nodes in the image frame (x, y = distance to the plane, z), SoA */
    SC_ALIGN_HOT float qx[SC_MAX_NODES];
    SC_ALIGN_HOT float qy[SC_MAX_NODES];
    SC_ALIGN_HOT float qz[SC_MAX_NODES];
    /* walker: plane segments, bucketed by first line, and the active set of a line sweep */
    uint32_t seg_count;
    sc_bscan_seg segs[SC_BSCAN_MAX_HULL_FACES];
    uint32_t seg_start[SC_MAX_SCAN_LINES + 1u];
    uint32_t seg_sorted[SC_BSCAN_MAX_HULL_FACES];
    uint32_t active[SC_BSCAN_MAX_HULL_FACES];
    sc_bscan_event events[SC_BSCAN_MAX_LINE_EVENTS];
    uint32_t epoch;
    sc_bscan_tcache tcache[SC_BSCAN_TET_CACHE];
    /* region path */
    uint32_t ptet_count;    /* plane tets found (the pool's parts leave gaps between their runs) */
    uint32_t regions_state; /* this frame: 0 not built, 1 built, 2 over the limits */
    sc_bscan_ptet ptets[SC_BSCAN_MAX_PLANE_TETS];
    uint8_t ptet_region[SC_BSCAN_MAX_PLANE_TETS][2]; /* its first and last line's regions */
    uint32_t region_start[SC_BSCAN_MAX_REGIONS + 1u];
    uint32_t region_refs[SC_BSCAN_MAX_REGION_REFS];
    float region_box[SC_BSCAN_MAX_REGIONS][4]; /* xmin, xmax, zmin, zmax of its tets */
    /* one line in flight: the runs of samples inside the mesh (the rest is rigid), the
     * labels and the displayed samples */
    uint32_t run_count;
    sc_bscan_run runs[SC_MAX_SCAN_SAMPLES];
    uint8_t line_label[SC_MAX_SCAN_SAMPLES];
    uint8_t line_out[SC_MAX_SCAN_SAMPLES];
    /* the line's sampling positions, one 32-bit word per axis and sample (sc_bscan_kern.h's
     * line sampler: one call per line), padded to a multiple of 8 */
    SC_ALIGN_HOT uint32_t pos_h[3][SC_MAX_SCAN_SAMPLES + 8u];
    sc_acoustics acou; /* tables of def.acoustic for this geometry and range */
    sc_bscan_margin_memo margin_memo; /* the last frame's rest reference above the face */
#if SC_BSCAN_PSF
    sc_psf psf; /* speckle pass: kernels and the lines in flight */
#endif
    uint32_t regions_last; /* the last frame's walker built the region bins (pool path: built
                              before the ranges run, as a range cannot build them) */
#if SC_BSCAN_RANGES > 1
    /* pool path: the ranges, and the frame's lines until they leave in order */
    sc_bscan_range range[SC_BSCAN_RANGES];
    uint16_t line_run0[SC_MAX_SCAN_LINES]; /* a stored line's first run in its range's runs */
    uint16_t line_runs[SC_MAX_SCAN_LINES];
    /* the region bins on the pool: each part's count (then cursor) and box of each bin */
    uint32_t part_cnt[SC_BSCAN_RANGES][SC_BSCAN_MAX_REGIONS];
    float part_box[SC_BSCAN_RANGES][SC_BSCAN_MAX_REGIONS][4];
    uint8_t frame_out[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
    uint8_t frame_label[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
#endif
    sc_bscan_status status;
} sc_bscan;

/* Defaults: the linear probe of sc_scan_default_def(), walker, R = 32, gain 0, TGC 0,
 * 60 dB displayed over a 60 dB volume (the volume shown unchanged), acoustics off with the
 * table of sc_acoustics_default_def(). */
sc_bscan_def sc_bscan_default_def(void);

/* Validate def and set up the geometry and display tables; forgets any attached mesh.
 * O(lines + samples). Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL), SC_ERR_IMG_GEOMETRY (scan geometry), SC_ERR_RANGE
 * (mapper, regions_n, gain/TGC/range, focus, acoustics flag or table out of range),
 * SC_ERR_NOT_FINITE. On error b is not usable (call again with a valid def). */
int sc_bscan_init(sc_bscan *b, const sc_bscan_def *def);

/* Change runtime settings (geometry, depth, mapper, gain, TGC, range, R) between frames,
 * keeping the attached mesh. O(lines + samples). Never allocates. Errors as sc_bscan_init; on
 * error the previous settings stay. */
int sc_bscan_set_def(sc_bscan *b, const sc_bscan_def *def);

/* Record the boundary triangles of a built mesh (at case load). O(tets), bounded by
 * SC_MAX_TETS. Never allocates. Errors: SC_ERR_INVALID_ARG, SC_ERR_NO_SPACE (more boundary
 * triangles than SC_BSCAN_MAX_HULL_FACES). */
int sc_bscan_attach_mesh(sc_bscan *b, const sc_mesh *mesh);

/* Synthesize one frame and stream it: frame_begin, every line as soon as it is computed,
 * frame_end; update the status (compression measure). mesh/nodes may be NULL (no mesh: every
 * pixel rigid); the mesh must be the attached one. probe_to_volume: probe frame -> volume
 * frame. contact 0: a dark frame (still streamed).
 * Cost, walker: O(nodes + hull faces + lines * (crossed tets + samples)); region path:
 * O(tets + lines * samples * tets per region) worst case; oracle O(pixels * tets). Bounded by
 * SC_MAX_NODES, SC_MAX_TETS, SC_MAX_SCAN_LINES, SC_MAX_SCAN_SAMPLES, SC_BSCAN_MAX_WALK_STEPS.
 * Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL b/volume/probe/display, volume without voxels or with an
 * axis of fewer than 2 voxels, mesh not the attached one), SC_ERR_CASE_TRANSFORM (probe transform
 * not rigid or not finite), or the first error a display call returned (the frame is still computed
 * and streamed to the end). */
int sc_bscan_frame(sc_bscan *b, const sc_mesh *mesh, const sc_nodes *nodes, const sc_volume *volume,
                   const sc_xform *probe_to_volume, int contact, const sc_display_dev *display,
                   uint32_t frame_no);

/* Set (or clear with NULL) the per-line hook, e.g. colour Doppler (sc_doppler.h); kept across
 * sc_bscan_set_def, cleared by sc_bscan_init. O(1). Never fails (NULL b: nothing happens). */
void sc_bscan_set_line_hook(sc_bscan *b, sc_bscan_line_hook_fn fn, void *ctx);

/* Run the lines of the following frames on a worker pool (NULL: one after the other on the
 * caller, as without a pool); kept across sc_bscan_set_def, cleared by sc_bscan_init. With a pool
 * of more than one worker and SC_BSCAN_RANGES > 1 the lines are cut into ranges fixed by the line
 * count alone (min(SC_BSCAN_RANGES, lines)), each mapped and sampled by one job with its own
 * scratch, and leave through the display in line order (the line hook called there, in line
 * order) once every range is done; the image and the status are bit-identical to the serial
 * path's for every worker count. The speckle pass (def.psf) couples neighbouring lines: its
 * frames stay serial. O(1). Never fails (NULL b: nothing happens). */
void sc_bscan_set_pool(sc_bscan *b, const sc_pool_dev *pool);

/* Status of the last frame (compression measure, work counters). O(1). */
const sc_bscan_status *sc_bscan_status_get(const sc_bscan *b);

#endif /* SC_BSCAN_H */
