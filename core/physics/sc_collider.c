/* sc_collider.c: probe collider (sphere / rounded box) with libccd MPR; see sc_collider.h. */
#include "sc_collider.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include <ccd/ccd.h>

#include "sc_assert.h"
#include "sc_err.h"

sc_collider_def sc_collider_default_def(void)
{
    sc_collider_def d;
    d.shape = SC_COLLIDER_ROUNDED_BOX;
    d.sphere_radius_mm = 10.0f;
    d.half_mm[0] = 20.0f;
    d.half_mm[1] = 5.0f;
    d.half_mm[2] = 10.0f;
    d.round_radius_mm = 2.0f;
    d.margin_mm = 0.5f;
    return d;
}

int sc_collider_def_validate(const sc_collider_def *d)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(d->sphere_radius_mm) || !isfinite(d->half_mm[0]) || !isfinite(d->half_mm[1]) ||
        !isfinite(d->half_mm[2]) || !isfinite(d->round_radius_mm) || !isfinite(d->margin_mm)) {
        return SC_ERR_NOT_FINITE;
    }
    if (d->margin_mm < 0.0f || d->margin_mm > 100.0f) {
        return SC_ERR_RANGE;
    }
    switch (d->shape) {
    case SC_COLLIDER_SPHERE:
        return (d->sphere_radius_mm > 0.0f && d->sphere_radius_mm < 1000.0f) ? SC_OK
                                                                           : SC_ERR_RANGE;
    case SC_COLLIDER_ROUNDED_BOX:
        if (d->round_radius_mm < 0.0f) {
            return SC_ERR_RANGE;
        }
        for (uint32_t i = 0; i < 3u; i++) {
            if (!(d->half_mm[i] > d->round_radius_mm) || d->half_mm[i] > 1000.0f) {
                return SC_ERR_RANGE;
            }
        }
        return SC_OK;
    default:
        return SC_ERR_INVALID_ARG;
    }
}

int sc_collider_init(sc_collider *c, const sc_collider_def *def)
{
    if (c == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_collider_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    c->def = *def;
    c->active = 0;
    c->pool = NULL;
    c->to_vol = sc_xform_identity();
    c->to_probe = sc_xform_identity();
    if (def->shape == SC_COLLIDER_SPHERE) {
        c->core_half_mm[0] = c->core_half_mm[1] = c->core_half_mm[2] = 0.0f;
        c->center_probe_mm[2] = -def->sphere_radius_mm;
    } else {
        for (uint32_t i = 0; i < 3u; i++) {
            c->core_half_mm[i] = def->half_mm[i] - def->round_radius_mm;
        }
        c->center_probe_mm[2] = -def->half_mm[2];
    }
    c->center_probe_mm[0] = 0.0f;
    c->center_probe_mm[1] = 0.0f;
    return SC_OK;
}

int sc_collider_set_pose(sc_collider *c, const sc_pose *pose)
{
    SC_ASSERT(c != NULL);
    c->active = 0;
    if (pose == NULL) {
        return SC_OK;
    }
    for (uint32_t i = 0; i < 3u; i++) {
        if (!isfinite(pose->pos_mm[i])) {
            return SC_ERR_POSE_IMPLAUSIBLE;
        }
    }
    const float n2 = sc_quat_norm2(pose->q);
    if (!isfinite(n2) || fabsf(n2 - 1.0f) > 1e-3f) {
        return SC_ERR_POSE_IMPLAUSIBLE;
    }
    c->to_vol = sc_xform_from_pose(pose);
    c->to_probe = sc_xform_inverse(&c->to_vol);
    c->active = 1;
    return SC_OK;
}

/* ---- libccd objects ---------------------------------------------------------------------- */

typedef struct ccd_probe {
    const sc_collider *c;
    double inflate_mm; /* sphere radius added to the core (rounding + margin) */
    double hint[3];    /* interior point that MPR starts its ray from (volume frame) */
} ccd_probe;

typedef struct ccd_point {
    double p[3];
} ccd_point;

static void probe_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    const ccd_probe *o = obj;
    const sc_collider *c = o->c;
    const float *r = c->to_vol.r;
    /* direction in the probe frame: R^T dir */
    double dl[3];
    for (uint32_t i = 0; i < 3u; i++) {
        dl[i] = (double)r[i] * dir->v[0] + (double)r[3u + i] * dir->v[1] +
                (double)r[6u + i] * dir->v[2];
    }
    const double len = sqrt(dl[0] * dl[0] + dl[1] * dl[1] + dl[2] * dl[2]);
    double sl[3];
    for (uint32_t i = 0; i < 3u; i++) {
        const double h = (double)c->core_half_mm[i];
        sl[i] = (double)c->center_probe_mm[i] + (dl[i] > 0.0 ? h : (dl[i] < 0.0 ? -h : 0.0));
        if (len > 0.0) {
            sl[i] += o->inflate_mm * dl[i] / len;
        }
    }
    for (uint32_t i = 0; i < 3u; i++) {
        out->v[i] = (double)r[3u * i] * sl[0] + (double)r[3u * i + 1u] * sl[1] +
                    (double)r[3u * i + 2u] * sl[2] + (double)c->to_vol.t_mm[i];
    }
}

/* MPR casts its ray from this interior point of the probe towards the node and returns the
 * surface it hits: starting from the point of the core box nearest to the node makes that ray
 * the exact minimal-translation direction of the swept box (the geometric centre would send
 * nodes near the ends of a long footprint out sideways). */
static void probe_center(const void *obj, ccd_vec3_t *out)
{
    const ccd_probe *o = obj;
    out->v[0] = o->hint[0];
    out->v[1] = o->hint[1];
    out->v[2] = o->hint[2];
}

/* Nearest point of the core box to the probe-frame point l; if l is inside the core, a point
 * 0.01 mm inward from l along the normal of the nearest core face. Result in the volume frame. */
static void core_hint(const sc_collider *c, const float l[3], double out[3])
{
    float q[3];
    float best = 1e30f;
    uint32_t best_axis = 0u;
    int inside = 1;
    for (uint32_t i = 0; i < 3u; i++) {
        const float rel = l[i] - c->center_probe_mm[i];
        const float h = c->core_half_mm[i];
        float cl = rel > h ? h : (rel < -h ? -h : rel);
        if (rel > h || rel < -h) {
            inside = 0;
        }
        const float gap = h - fabsf(rel);
        if (gap < best) {
            best = gap;
            best_axis = i;
        }
        q[i] = cl + c->center_probe_mm[i];
    }
    if (inside) {
        const float rel = l[best_axis] - c->center_probe_mm[best_axis];
        q[best_axis] = l[best_axis] - (rel >= 0.0f ? 0.01f : -0.01f);
    }
    float v[3];
    sc_xform_apply(&c->to_vol, q, v);
    out[0] = (double)v[0];
    out[1] = (double)v[1];
    out[2] = (double)v[2];
}

static void point_support(const void *obj, const ccd_vec3_t *dir, ccd_vec3_t *out)
{
    (void)dir;
    const ccd_point *o = obj;
    out->v[0] = o->p[0];
    out->v[1] = o->p[1];
    out->v[2] = o->p[2];
}

/* libccd's first search direction (GJK only; set for completeness): +x */
static void first_dir_x(const void *o1, const void *o2, ccd_vec3_t *dir)
{
    (void)o1;
    (void)o2;
    dir->v[0] = 1.0;
    dir->v[1] = 0.0;
    dir->v[2] = 0.0;
}

static void point_center(const void *obj, ccd_vec3_t *out)
{
    const ccd_point *o = obj;
    out->v[0] = o->p[0];
    out->v[1] = o->p[1];
    out->v[2] = o->p[2];
}

/* ---- detection --------------------------------------------------------------------------- */

static float inflate_of(const sc_collider *c)
{
    return (c->def.shape == SC_COLLIDER_SPHERE ? c->def.sphere_radius_mm
                                               : c->def.round_radius_mm) +
           c->def.margin_mm;
}

static void index_range(float lo, float hi, float origin, float cell, uint32_t n, uint32_t *i0,
                        uint32_t *i1)
{
    if (n <= 1u) {
        *i0 = 0u;
        *i1 = n; /* exclusive */
        return;
    }
    float a = floorf((lo - origin) / cell);
    float b = ceilf((hi - origin) / cell);
    if (!(a >= 0.0f)) {
        a = 0.0f;
    }
    if (!(b <= (float)(n - 1u))) {
        b = (float)(n - 1u);
    }
    if (!(b >= a) || a > (float)(n - 1u) || b < 0.0f) {
        *i0 = 0u;
        *i1 = 0u;
        return;
    }
    *i0 = (uint32_t)a;
    *i1 = (uint32_t)b + 1u;
}

/* What a detection needs, for the rows of the candidate box (sc_collider_detect). */
typedef struct detect_ctx {
    const sc_collider *c;
    const sc_collider_grid *g;
    const float *x, *y, *z;
    const uint8_t *fixed;
    float infl;
    float lim[3];
    uint32_t r0[3], r1[3];
    uint32_t rows_per_chunk, chunks;
    uint32_t count[SC_COLLIDER_CHUNKS], cand[SC_COLLIDER_CHUNKS], mpr[SC_COLLIDER_CHUNKS];
    uint32_t base[SC_COLLIDER_CHUNKS];
    sc_contact *out; /* the set's contacts; chunk q writes from out + base[q] */
} detect_ctx;

/* The contacts of the candidate rows row0 .. row1 - 1 (row: (j, k) of the box, k major, the
 * nodes along i in order) into dst, in node order; returns their count. Every node's contact is
 * its own (MPR from a hint of its own): any split of the rows gives the same contacts. */
static uint32_t detect_rows(const detect_ctx *d, uint32_t row0, uint32_t row1, sc_contact *dst,
                            uint32_t *cand_out, uint32_t *mpr_out)
{
    const sc_collider *c = d->c;
    const sc_collider_grid *g = d->g;
    const float *x = d->x, *y = d->y, *z = d->z;
    const uint8_t *fixed = d->fixed;
    const uint32_t *r0 = d->r0, *r1 = d->r1;
    const float *lim = d->lim;
    /* CCD_INIT would reference ccdFirstDirDefault, which lives in libccd's ccd.c (GJK/EPA,
     * heap-allocating, not linked into the bare-metal image); MPR never calls first_dir. */
    ccd_t ccd;
    memset(&ccd, 0, sizeof(ccd));
    ccd.first_dir = first_dir_x;
    ccd.support1 = probe_support;
    ccd.center1 = probe_center;
    ccd.support2 = point_support;
    ccd.center2 = point_center;
    ccd.max_iterations = 100u;
    ccd.mpr_tolerance = 1e-6;
    ccd_probe probe = {c, (double)d->infl, {0.0, 0.0, 0.0}};
    uint32_t count = 0, cand = 0, mpr = 0;
    const int slide = c->def.shape == SC_COLLIDER_ROUNDED_BOX;
    const uint32_t nj = r1[1] - r0[1];
    for (uint32_t row = row0; row < row1; row++) {
        const uint32_t k = r0[2] + row / nj, j = r0[1] + row % nj;
        for (uint32_t i = r0[0]; i < r1[0]; i++) {
            const uint32_t n = i + g->nx * (j + g->ny * k);
            if (fixed != NULL && fixed[n] != 0u) {
                continue;
            }
            cand++;
            const float p[3] = {x[n], y[n], z[n]};
            float l[3];
            sc_xform_apply(&c->to_probe, p, l);
            /* conservative: outside the inflated shape's box in the probe frame */
            if (fabsf(l[0] - c->center_probe_mm[0]) > lim[0] ||
                fabsf(l[1] - c->center_probe_mm[1]) > lim[1] ||
                fabsf(l[2] - c->center_probe_mm[2]) > lim[2]) {
                continue;
            }
            /* Sliding face: a node inside the probe leaves through the face plane (the
             * probe came from outside the body, through the skin; tissue slides under a
             * gel-coated face), not through the nearest side wall or rounded edge: MPR's
             * shortest way out lets a probe that moves sideways at depth, or jumps
             * between two frames, bulldoze the tissue ahead of it until a node is pushed
             * out of the box (the guard's displacement reset, measured with `--script
             * sweep` on all three phantoms). */
            /* (also a contact within the margin above the face plane: a node left on
             * the face plane at the rounded rim lies just outside the rounding; with the
             * rounding's own plane it would not be held, would spring back into the
             * probe and chatter between the two every frame) */
            if (slide && l[2] < c->def.margin_mm) {
                /* such a node takes the face plane, so only whether it is in the inflated shape
                 * (the core box swept by a ball of the inflation) matters: exact in closed
                 * form, no MPR; MPR for the rest */
                float d2 = 0.0f;
                for (uint32_t a = 0; a < 3u; a++) {
                    const float e = fabsf(l[a] - c->center_probe_mm[a]) - c->core_half_mm[a];
                    d2 += e > 0.0f ? e * e : 0.0f;
                }
                if (!(d2 < d->infl * d->infl)) {
                    continue;
                }
                sc_contact *ct = &dst[count++];
                ct->node = n;
                const float lf[3] = {l[0], l[1], 0.0f};
                const float nz[3] = {0.0f, 0.0f, 1.0f};
                sc_xform_apply(&c->to_vol, lf, ct->p_mm);
                sc_xform_rotate(&c->to_vol, nz, ct->n);
                continue;
            }
            const ccd_point pt = {{(double)p[0], (double)p[1], (double)p[2]}};
            core_hint(c, l, probe.hint);
            ccd_real_t depth = 0.0;
            ccd_vec3_t dir, pos;
            mpr++;
            if (ccdMPRPenetration(&probe, &pt, &ccd, &depth, &dir, &pos) != 0) {
                continue;
            }
            const double dl =
                sqrt(dir.v[0] * dir.v[0] + dir.v[1] * dir.v[1] + dir.v[2] * dir.v[2]);
            if (!(dl > 0.0) || !isfinite(depth)) {
                continue;
            }
            /* moving the node by depth along dir reaches the inflated surface; the real
             * surface is margin closer */
            const double d_real = depth - (double)c->def.margin_mm;
            sc_contact *ct = &dst[count++];
            ct->node = n;
            for (uint32_t a = 0; a < 3u; a++) {
                const double u = dir.v[a] / dl;
                ct->n[a] = (float)u;
                ct->p_mm[a] = (float)((double)p[a] + d_real * u);
            }
        }
    }
    *cand_out = cand;
    *mpr_out = mpr;
    return count;
}

static void job_detect(void *arg, uint32_t q)
{
    detect_ctx *d = (detect_ctx *)arg;
    const uint32_t rows = (d->r1[2] - d->r0[2]) * (d->r1[1] - d->r0[1]);
    const uint32_t a = q * d->rows_per_chunk;
    const uint32_t b = a + d->rows_per_chunk < rows ? a + d->rows_per_chunk : rows;
    d->count[q] = detect_rows(d, a, b, d->out + d->base[q], &d->cand[q], &d->mpr[q]);
}

void sc_collider_detect(const sc_collider *c, const sc_collider_grid *g, const float *x,
                        const float *y, const float *z, const uint8_t *fixed,
                        float max_disp_mm, sc_contact_set *out)
{
    SC_ASSERT(c != NULL && g != NULL && out != NULL);
    SC_ASSERT(g->nx * g->ny * g->nz <= SC_MAX_CONTACTS);
    out->count = 0u;
    out->candidates = 0u;
    out->mpr_calls = 0u;
    if (!c->active) {
        return;
    }
    detect_ctx d;
    d.c = c;
    d.g = g;
    d.x = x;
    d.y = y;
    d.z = z;
    d.fixed = fixed;
    const float infl = inflate_of(c);
    d.infl = infl;
    const float widen = infl + (isfinite(max_disp_mm) && max_disp_mm > 0.0f ? max_disp_mm : 0.0f);
    /* AABB of the core box (or centre) in the volume frame, widened */
    float lo[3], hi[3], cen[3];
    sc_xform_apply(&c->to_vol, c->center_probe_mm, cen);
    for (uint32_t i = 0; i < 3u; i++) {
        const float *r = &c->to_vol.r[3u * i];
        const float ext = fabsf(r[0]) * c->core_half_mm[0] + fabsf(r[1]) * c->core_half_mm[1] +
                          fabsf(r[2]) * c->core_half_mm[2];
        lo[i] = cen[i] - ext - widen;
        hi[i] = cen[i] + ext + widen;
    }
    index_range(lo[0], hi[0], g->origin_mm[0], g->cell_mm[0], g->nx, &d.r0[0], &d.r1[0]);
    index_range(lo[1], hi[1], g->origin_mm[1], g->cell_mm[1], g->ny, &d.r0[1], &d.r1[1]);
    index_range(lo[2], hi[2], g->origin_mm[2], g->cell_mm[2], g->nz, &d.r0[2], &d.r1[2]);
    for (uint32_t i = 0; i < 3u; i++) {
        d.lim[i] = c->core_half_mm[i] + infl;
    }
    const uint32_t width = d.r1[0] - d.r0[0];
    const uint32_t rows = (d.r1[2] - d.r0[2]) * (d.r1[1] - d.r0[1]);
    if (width == 0u || rows == 0u) {
        return;
    }
    d.out = out->c;
    if (c->pool == NULL || rows * width < SC_COLLIDER_POOL_MIN) {
        /* serial: one chunk, straight into the set */
        out->count = detect_rows(&d, 0u, rows, out->c, &out->candidates, &out->mpr_calls);
        return;
    }
    /* on the pool: the rows cut into at most SC_COLLIDER_CHUNKS chunks (by the box alone, not
     * the workers); chunk q writes from the first slot that the candidates before it could
     * fill (the box holds at most SC_MAX_CONTACTS nodes), then the chunks' contacts are moved
     * together in chunk order: the serial loop's set */
    d.rows_per_chunk = (rows + SC_COLLIDER_CHUNKS - 1u) / SC_COLLIDER_CHUNKS;
    d.chunks = (rows + d.rows_per_chunk - 1u) / d.rows_per_chunk;
    for (uint32_t q = 0; q < d.chunks; q++) {
        d.base[q] = q * d.rows_per_chunk * width;
    }
    sc_pool_run(c->pool, job_detect, &d, d.chunks);
    uint32_t count = 0;
    for (uint32_t q = 0; q < d.chunks; q++) {
        if (d.count[q] > 0u && d.base[q] != count) {
            memmove(&out->c[count], &out->c[d.base[q]], (size_t)d.count[q] * sizeof out->c[0]);
        }
        count += d.count[q];
        out->candidates += d.cand[q];
        out->mpr_calls += d.mpr[q];
    }
    out->count = count;
}

float sc_contact_depth_mm(const sc_contact *ct, float x, float y, float z)
{
    return ct->n[0] * (ct->p_mm[0] - x) + ct->n[1] * (ct->p_mm[1] - y) +
           ct->n[2] * (ct->p_mm[2] - z);
}

void sc_contact_add_forces(const sc_contact_set *s, const float *x, const float *y,
                           const float *z, const float *kappa_n_per_mm, float kappa_scale,
                           float *fx, float *fy, float *fz)
{
    for (uint32_t q = 0; q < s->count; q++) {
        const sc_contact *ct = &s->c[q];
        const uint32_t n = ct->node;
        const float d = sc_contact_depth_mm(ct, x[n], y[n], z[n]);
        if (d > 0.0f) {
            const float f = kappa_n_per_mm[n] * kappa_scale * d;
            fx[n] += f * ct->n[0];
            fy[n] += f * ct->n[1];
            fz[n] += f * ct->n[2];
        }
    }
}

void sc_contact_clear_forces(const sc_contact_set *s, float *fx, float *fy, float *fz)
{
    for (uint32_t q = 0; q < s->count; q++) {
        const uint32_t n = s->c[q].node;
        fx[n] = 0.0f;
        fy[n] = 0.0f;
        fz[n] = 0.0f;
    }
}

float sc_collider_signed_distance_mm(const sc_collider *c, const float p_mm[3])
{
    if (!c->active) {
        return 1e30f;
    }
    float l[3];
    sc_xform_apply(&c->to_probe, p_mm, l);
    const float rad =
        c->def.shape == SC_COLLIDER_SPHERE ? c->def.sphere_radius_mm : c->def.round_radius_mm;
    float q[3], out2 = 0.0f, inmax = -1e30f;
    for (uint32_t i = 0; i < 3u; i++) {
        q[i] = fabsf(l[i] - c->center_probe_mm[i]) - c->core_half_mm[i];
        const float qp = q[i] > 0.0f ? q[i] : 0.0f;
        out2 += qp * qp;
        inmax = q[i] > inmax ? q[i] : inmax;
    }
    const float box = sqrtf(out2) + (inmax < 0.0f ? inmax : 0.0f);
    return box - rad;
}

uint32_t sc_collider_append_sphere(const float c_mm[3], float r_mm, float margin_mm,
                                   uint32_t node_count, const float *x, const float *y,
                                   const float *z, const uint8_t *fixed, sc_contact_set *out)
{
    if (c_mm == NULL || out == NULL || !(r_mm > 0.0f) || !(margin_mm >= 0.0f)) {
        return 0u;
    }
    const float reach = r_mm + margin_mm, reach2 = reach * reach;
    const uint32_t before = out->count;
    uint32_t added = 0u;
    for (uint32_t i = 0; i < node_count; i++) {
        if (fixed != NULL && fixed[i]) {
            continue;
        }
        const float dx = x[i] - c_mm[0], dy = y[i] - c_mm[1], dz = z[i] - c_mm[2];
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (!(d2 < reach2)) {
            continue;
        }
        int held = 0;
        for (uint32_t k = 0; k < before && !held; k++) {
            held = out->c[k].node == i;
        }
        if (held) {
            continue; /* the probe already holds it */
        }
        if (out->count >= SC_MAX_CONTACTS) {
            break;
        }
        const float d = sqrtf(d2);
        float n[3] = {0.0f, 0.0f, -1.0f};
        if (d > 1e-6f) {
            n[0] = dx / d;
            n[1] = dy / d;
            n[2] = dz / d;
        }
        sc_contact *ct = &out->c[out->count++];
        ct->node = i;
        for (uint32_t a = 0; a < 3u; a++) {
            ct->p_mm[a] = c_mm[a] + r_mm * n[a];
            ct->n[a] = n[a];
        }
        added++;
    }
    return added;
}
