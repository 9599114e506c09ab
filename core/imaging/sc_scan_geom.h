/*
 * sc_scan_geom.h: where the pixels of a B-scan lie, for a linear or a curvilinear probe.
 *
 * The image frame (mm) is the probe's imaging plane: x lateral (along the aperture), y = 0 on
 * the plane (elevation), z depth along the beam, origin at the centre of the probe face. The
 * image-to-probe calibration (an sc_xform, as tracked-ultrasound tools call it) carries image
 * coordinates into the probe frame (sc_pose.h: x along the aperture, y elevation, z beam);
 * identity by default.
 *
 * Both geometries have straight scan lines: line l is the point set
 *     p(l, k) = start(l) + k * step(l),   k = 0 .. samples_n - 1  (sample index),
 * which the B-scan mapper exploits (the map from the deformed to the rest configuration is
 * affine along a line inside one tetrahedron).
 * - Linear: lines_n parallel lines over width_mm; line centres at x = -w/2 + (l + 1/2) w / n,
 *   samples at z = (k + 1/2) depth / samples_n.
 * - Curvilinear: a convex array of radius radius_mm with its centre of curvature (the apex)
 *   at z = -radius_mm; lines fan out over sector_deg at angles -s/2 + (l + 1/2) s / n from the
 *   apex; sample k at radius r = radius + (k + 1/2) depth / samples_n.
 *
 * Memory: the caller's sc_scan_geom (per-line tables sized by SC_MAX_SCAN_LINES). Never
 * allocates, never calls the OS. Threads: one writer; readers after init.
 */
#ifndef SC_SCAN_GEOM_H
#define SC_SCAN_GEOM_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_pose.h"

enum {
    SC_SCAN_GEOM_LINEAR = 0, /* = sc_display_frame_info.geometry_id = sc_canproto SC_SCAN_* */
    SC_SCAN_GEOM_CURVILINEAR = 1,
};

typedef struct sc_scan_def {
    uint32_t kind;           /* SC_SCAN_GEOM_LINEAR or SC_SCAN_GEOM_CURVILINEAR */
    uint32_t lines_n;        /* 2..SC_MAX_SCAN_LINES */
    uint32_t samples_n;      /* 2..SC_MAX_SCAN_SAMPLES */
    float depth_mm;          /* imaging depth from the probe face, (0, 300] */
    float width_mm;          /* linear: aperture width, (0, 200] */
    float radius_mm;         /* curvilinear: radius of the probe face, (0, 200] */
    float sector_deg;        /* curvilinear: fan angle, (0, 170] */
    sc_xform image_to_probe; /* calibration; must be rigid */
} sc_scan_def;

/* Derived per-line tables (image frame, mm). */
typedef struct sc_scan_geom {
    sc_scan_def def;
    float sample_mm;                     /* distance between samples along a line */
    float start_x_mm[SC_MAX_SCAN_LINES]; /* first sample of each line */
    float start_z_mm[SC_MAX_SCAN_LINES];
    float step_x_mm[SC_MAX_SCAN_LINES]; /* one sample further along the line */
    float step_z_mm[SC_MAX_SCAN_LINES];
    float sample_area_mm2[SC_MAX_SCAN_SAMPLES]; /* area a pixel of sample k stands for */
    float s_min;      /* lowest line parameter (in samples) of interest: linear -samples_n (one
                         depth behind the face), curvilinear the apex */
    float line_first; /* linear: x of line 0; curvilinear: angle of line 0 (rad) */
    float line_pitch; /* linear: mm between lines; curvilinear: rad between lines */
} sc_scan_geom;

/* Linear probe: 256 lines x 512 samples, 38 mm wide, 60 mm deep, identity calibration. */
sc_scan_def sc_scan_default_def(void);
/* Curvilinear probe: 128 lines x 512 samples, radius 40 mm, 60 degrees, 80 mm deep. */
sc_scan_def sc_scan_curvilinear_default_def(void);

/* Validate def and fill the per-line tables. O(lines + samples), bounded by
 * SC_MAX_SCAN_LINES + SC_MAX_SCAN_SAMPLES. Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL), SC_ERR_IMG_GEOMETRY (kind, counts or sizes out of range,
 * not finite, calibration not rigid). On error g is unchanged. */
int sc_scan_geom_init(sc_scan_geom *g, const sc_scan_def *def);

/* Image-frame position of sample k of line l (y is 0). O(1). l, k must be in range. */
void sc_scan_geom_pixel(const sc_scan_geom *g, uint32_t l, uint32_t k, float out_mm[3]);

/* Lines whose points may meet the image-frame point (x, z), as an inclusive index range
 * [*lo, *hi] widened by one line to each side (a conservative filter; the caller tests the
 * line exactly). Returns 0 when no line can meet it. O(1). */
int sc_scan_geom_line_range(const sc_scan_geom *g, float xmin, float xmax, float zmin, float zmax,
                            int32_t *lo, int32_t *hi);

#endif /* SC_SCAN_GEOM_H */
