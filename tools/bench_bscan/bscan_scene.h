/*
 * bscan_scene.h: a generated test case for the B-scan synthesis (tests and bench share it):
 * a volume with skin, fat, muscle, a vein and an artery, and prescribed smooth mesh
 * deformations (no physics needed). Header-only, host code (libm); not part of the core.
 *
 * Volume frame (mm): x lateral, y along the body, z depth; skin surface at z = 0 (z < 0 is air,
 * label OUTSIDE, intensity 0). The default mesh box (sc_mesh_default_def) spans x 0..40,
 * y 0..20, z 0..30. Vein: cylinder along y at (x 14, z 12), radius 4; artery at (x 27, z 13),
 * radius 3.
 */
#ifndef BSCAN_SCENE_H
#define BSCAN_SCENE_H

#include <math.h>
#include <stdint.h>

#include "sc_labels.h"
#include "sc_mesh.h"
#include "sc_pose.h"
#include "sc_volume.h"

#define SCN_SP_MM  0.5f
#define SCN_NX     121u /* x -10 .. 50 */
#define SCN_NY     61u  /* y -5 .. 25 */
#define SCN_NZ     151u /* z -5 .. 70 */
#define SCN_VOXELS (SCN_NX * SCN_NY * SCN_NZ)

#define SCN_VEIN_X 14.0f
#define SCN_VEIN_Z 12.0f
#define SCN_VEIN_R 4.0f
#define SCN_ART_X  27.0f
#define SCN_ART_Z  13.0f
#define SCN_ART_R  3.0f

typedef struct scn_volume {
    uint8_t vox[SCN_VOXELS];
    uint8_t lab[SCN_VOXELS];
    sc_volume v;
} scn_volume;

static inline uint32_t scn_hash(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

static inline void scn_make_volume(scn_volume *s)
{
    s->v.dim[0] = SCN_NX;
    s->v.dim[1] = SCN_NY;
    s->v.dim[2] = SCN_NZ;
    s->v.spacing_mm[0] = s->v.spacing_mm[1] = s->v.spacing_mm[2] = SCN_SP_MM;
    s->v.origin_mm[0] = -10.0f;
    s->v.origin_mm[1] = -5.0f;
    s->v.origin_mm[2] = -5.0f;
    s->v.voxels = s->vox;
    s->v.labels = s->lab;
    for (uint32_t k = 0; k < SCN_NZ; k++) {
        for (uint32_t j = 0; j < SCN_NY; j++) {
            for (uint32_t i = 0; i < SCN_NX; i++) {
                const uint32_t idx = i + SCN_NX * (j + SCN_NY * k);
                const float x = -10.0f + (float)i * SCN_SP_MM;
                const float y = -5.0f + (float)j * SCN_SP_MM;
                const float z = -5.0f + (float)k * SCN_SP_MM;
                uint8_t lab;
                float base;
                const float dv = hypotf(x - SCN_VEIN_X, z - SCN_VEIN_Z);
                const float da = hypotf(x - SCN_ART_X, z - SCN_ART_Z);
                if (z < 0.0f) {
                    lab = SC_LABEL_OUTSIDE;
                    base = 0.0f;
                } else if (z < 1.0f) {
                    lab = SC_LABEL_SKIN;
                    base = 200.0f;
                } else if (dv < SCN_VEIN_R) {
                    lab = SC_LABEL_VEIN;
                    base = 12.0f;
                } else if (da < SCN_ART_R) {
                    lab = SC_LABEL_ARTERY;
                    base = 18.0f;
                } else if (dv < SCN_VEIN_R + 0.6f || da < SCN_ART_R + 0.6f) {
                    lab = SC_LABEL_MUSCLE; /* bright vessel wall */
                    base = 215.0f;
                } else if (z < 6.0f + 1.5f * sinf(0.2f * x)) {
                    lab = SC_LABEL_FAT;
                    base = 85.0f;
                } else {
                    lab = SC_LABEL_MUSCLE;
                    base = 130.0f + 25.0f * sinf(0.9f * x + 0.4f * y) * cosf(0.7f * z);
                }
                float speckle = 0.0f;
                if (lab != SC_LABEL_OUTSIDE) {
                    speckle = (float)(scn_hash(idx) & 63u) - 31.5f;
                }
                float val =
                    base + (lab == SC_LABEL_VEIN || lab == SC_LABEL_ARTERY ? 0.2f : 0.8f) * speckle;
                val = val < 0.0f ? 0.0f : (val > 255.0f ? 255.0f : val);
                s->vox[idx] = (uint8_t)(val + 0.5f);
                s->lab[idx] = lab;
            }
        }
    }
}

enum { SCN_DEFORM_NONE, SCN_DEFORM_DENT, SCN_DEFORM_SQUASH_VEIN, SCN_DEFORM_WOBBLE };

/* Displacement of a rest point for a prescribed deformation of strength a (mm). All fields
 * keep every tet positively oriented for the strengths used (d(z + uz)/dz > 0, small shear). */
static inline void scn_displacement(int kind, float a, float x, float y, float z, float u[3])
{
    u[0] = u[1] = u[2] = 0.0f;
    switch (kind) {
    case SCN_DEFORM_DENT: {
        /* a probe dent of depth a at (20, 10), decaying with depth, with a little bulge */
        const float g =
            expf(-((x - 20.0f) * (x - 20.0f)) / 64.0f - ((y - 10.0f) * (y - 10.0f)) / 36.0f);
        const float h = (1.0f - z / 30.0f) * (1.0f - z / 30.0f);
        u[2] = a * g * h;
        u[0] = 0.08f * a * (x - 20.0f) / 8.0f * g * (z / 30.0f) * (1.0f - z / 30.0f) * 4.0f;
        break;
    }
    case SCN_DEFORM_SQUASH_VEIN: {
        /* compress the band z 7..17 towards z = 12 near x = 14 by up to a factor (1 - a) */
        const float c = expf(-((x - SCN_VEIN_X) * (x - SCN_VEIN_X)) / 64.0f) * a;
        const float dz = z - SCN_VEIN_Z;
        float w;
        if (dz < -5.0f) {
            w = -5.0f * (z / (SCN_VEIN_Z - 5.0f));
        } else if (dz > 5.0f) {
            w = 5.0f * (30.0f - z) / (30.0f - SCN_VEIN_Z - 5.0f);
        } else {
            w = dz;
        }
        u[2] = -c * w;
        break;
    }
    case SCN_DEFORM_WOBBLE:
        u[0] = 0.35f * a * sinf(0.31f * y + 0.23f * z) * sinf(0.2f * x);
        u[1] = 0.30f * a * sinf(0.27f * x + 0.19f * z);
        u[2] = 0.40f * a * sinf(0.21f * x + 0.17f * y) * sinf(0.19f * z);
        break;
    default:
        break;
    }
}

static inline void scn_deform(const sc_mesh *m, sc_nodes *n, int kind, float a)
{
    sc_nodes_reset_to_rest(n, m);
    for (uint32_t i = 0; i < m->node_count; i++) {
        float u[3];
        scn_displacement(kind, a, m->rest_x[i], m->rest_y[i], m->rest_z[i], u);
        n->x[i] += u[0];
        n->y[i] += u[1];
        n->z[i] += u[2];
    }
}

/* Probe at (x, y, z) mm, beam along +z of the volume, tilted by tilt_deg about the y axis. */
static inline sc_xform scn_probe(float x, float y, float z, float tilt_deg)
{
    const float a = tilt_deg * 3.14159265f / 180.0f;
    const float c = cosf(a), s = sinf(a);
    sc_xform t = {.r = {c, 0.0f, s, 0.0f, 1.0f, 0.0f, -s, 0.0f, c}, .t_mm = {x, y, z}};
    return t;
}

#endif /* BSCAN_SCENE_H */
