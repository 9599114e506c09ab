/* sc_bscan.c: B-scan synthesis through the deformed mesh, see sc_bscan.h.
 *
 * Frame pipeline: (1) image -> volume transform; (2) deformed nodes into the image frame
 * (x lateral, y = signed distance to the image plane, z depth): every later test is 2D or a
 * sign of y; (3) mapper preparation (boundary segments for the walker, plane tets and regions
 * for the paper's path); (4) per line: rigid positions, mapper overwrites the pixels inside the
 * mesh with rest positions, then sampling, display processing, label areas, display line.
 *
 * Sampling positions are kept in voxel-index units (x - origin) / spacing so the sampler does
 * no unit conversion.
 */
#include "sc_bscan.h"
#include "sc_bscan_kern.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"

/* Barycentric tolerance of point location (region path and oracle): a pixel on a face is in
 * both tets; the rest map is continuous there, so either answer is right. */
#define SC_BSCAN_LAMBDA_EPS 1e-5f

/* Darkening of the tissue continued beyond the case volume, dB per mm outside it: about half
 * the uncompensated two-way loss of soft tissue at 7.5 MHz (0.7 dB/cm/MHz x 2 x 7.5 = 1 dB/mm),
 * so the continuation fades over a few cm instead of ending in a black edge. */
#define SC_BSCAN_BEYOND_DB_PER_MM 0.5f
/* Thickness of the slab along a face that the continuation repeats (mirrored back and forth):
 * thin enough that vessels and bone surfaces inside the volume are not mirrored out, thick
 * enough that the repetition is not a streak. */
#define SC_BSCAN_BEYOND_SLAB_MM 6.0f

/* ---- settings --------------------------------------------------------------------------- */

sc_bscan_def sc_bscan_default_def(void)
{
    sc_bscan_def d;
    d.scan = sc_scan_default_def();
    d.mapper = SC_BSCAN_MAP_WALK;
    d.regions_n = SC_BSCAN_REGIONS_DEFAULT;
    d.gain_db = 0.0f;
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        d.tgc_db[i] = 0.0f;
    }
    d.dynamic_range_db = 60.0f;
    d.volume_range_db = 60.0f;
    d.focus_mm = 20.0f; /* a 7.5 MHz linear probe's usual transmit focus */
    d.rest_margin_mm = 60.0f; /* the range's top: deeper than any mesh box the limits allow
                                 a press into (the appliance's 64x32x32 boxes are 30-45 mm) */
    d.acoustics = 0u;
    d.acoustic = sc_acoustics_default_def();
    d.psf = 0u;
    d.psf_def = sc_psf_default_def();
    return d;
}

static int db_ok(float v, float lo, float hi)
{
    return v >= lo && v <= hi;
}

static int check_def(const sc_bscan_def *d)
{
    if (!isfinite(d->gain_db) || !isfinite(d->dynamic_range_db) || !isfinite(d->volume_range_db) ||
        !isfinite(d->rest_margin_mm) || !isfinite(d->focus_mm)) {
        return SC_ERR_NOT_FINITE;
    }
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        if (!isfinite(d->tgc_db[i])) {
            return SC_ERR_NOT_FINITE;
        }
        if (!db_ok(d->tgc_db[i], -60.0f, 60.0f)) {
            return SC_ERR_RANGE;
        }
    }
    if (d->mapper >= (uint32_t)SC_BSCAN_MAP_COUNT || d->regions_n < 1u ||
        d->regions_n > SC_BSCAN_MAX_REGIONS || !db_ok(d->gain_db, -60.0f, 60.0f) ||
        !db_ok(d->dynamic_range_db, 10.0f, 120.0f) || !db_ok(d->volume_range_db, 10.0f, 120.0f) ||
        !db_ok(d->rest_margin_mm, 0.0f, 60.0f) || d->acoustics > 1u ||
        d->psf > (SC_BSCAN_PSF ? 1u : 0u) || !(d->focus_mm > 0.0f) ||
        d->focus_mm > 300.0f) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* Display table: out = a * I + b[k] (see sc_bscan_def). */
static void build_lut(sc_bscan *b)
{
    const sc_bscan_def *d = &b->def;
    const float rng = d->dynamic_range_db;
    b->lut_a = d->volume_range_db / rng;
    const float band_mm = d->scan.depth_mm / (float)SC_BSCAN_TGC_BANDS;
    for (uint32_t k = 0; k < d->scan.samples_n; k++) {
        const float depth = ((float)k + 0.5f) * b->geom.sample_mm;
        float t = depth / band_mm - 0.5f;
        float tgc;
        if (!(t > 0.0f)) {
            tgc = d->tgc_db[0];
        } else if (t >= (float)(SC_BSCAN_TGC_BANDS - 1u)) {
            tgc = d->tgc_db[SC_BSCAN_TGC_BANDS - 1u];
        } else {
            const uint32_t i = (uint32_t)t;
            const float f = t - (float)i;
            tgc = d->tgc_db[i] + f * (d->tgc_db[i + 1u] - d->tgc_db[i]);
        }
        b->lut_b[k] = 255.0f * (d->gain_db + tgc + rng - d->volume_range_db) / rng;
        /* 38.26 with the rounding half folded in (see sample_fx) */
        b->lut_b_fx[k] = (int64_t)floorf(b->lut_b[k] * 1024.0f + 512.0f + 0.5f) * 65536;
    }
}

int sc_bscan_set_def(sc_bscan *b, const sc_bscan_def *def)
{
    if (b == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    int rc = check_def(def);
    if (rc != SC_OK) {
        return rc;
    }
    sc_scan_geom g_new;
    rc = sc_scan_geom_init(&g_new, &def->scan);
    if (rc != SC_OK) {
        return rc;
    }
    sc_acoustics acou;
    rc = sc_acoustics_init(&acou, &def->acoustic, g_new.sample_mm, def->dynamic_range_db);
    if (rc != SC_OK) {
        return rc;
    }
#if SC_BSCAN_PSF
    if (def->psf != 0u) {
        rc = sc_psf_setup(&b->psf, &def->psf_def, &def->scan, &g_new, def->focus_mm,
                          def->acoustic.frequency_mhz, def->dynamic_range_db);
        if (rc != SC_OK) {
            return rc;
        }
    }
#endif
    b->acou = acou;
    b->margin_memo.valid = 0u;
    b->geom = g_new;
    b->def = *def;
    build_lut(b);
    return SC_OK;
}

int sc_bscan_init(sc_bscan *b, const sc_bscan_def *def)
{
    if (b == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    b->hull_count = 0u;
    b->mesh_tets = 0u;
    b->seg_count = 0u;
    b->ptet_count = 0u;
    b->epoch = 1u;
    for (uint32_t i = 0; i < SC_BSCAN_TET_CACHE; i++) {
        b->tcache[i].epoch = 0u;
    }
    memset(&b->status, 0, sizeof b->status);
    b->line_hook = NULL;
    b->line_hook_ctx = NULL;
    b->pool = NULL;
    b->regions_last = 0u;
    return sc_bscan_set_def(b, def);
}

/* 1 when the mesh has sc_mesh_build's layout: nx * ny * nz nodes numbered i + nx (j + ny k),
 * nx at most 64 (a row of nodes fits a 64-bit mask), tets 5 c .. 5 c + 4 of cell
 * c = i + (nx - 1) (j + (ny - 1) k) with their vertices among the cell's corners. */
static uint32_t mesh_is_grid(const sc_mesh *m)
{
    const uint32_t nx = m->nx, ny = m->ny, nz = m->nz;
    if (nx < 2u || ny < 2u || nz < 2u || nx > 64u || nx > SC_MAX_MESH_NX ||
        ny > SC_MAX_MESH_NY || nz > SC_MAX_MESH_NZ || m->node_count != nx * ny * nz ||
        m->tet_count != 5u * (nx - 1u) * (ny - 1u) * (nz - 1u)) {
        return 0u;
    }
    for (uint32_t t = 0; t < m->tet_count; t++) {
        const uint32_t c = t / 5u;
        const uint32_t ci = c % (nx - 1u), cj = (c / (nx - 1u)) % (ny - 1u),
                       ck = c / ((nx - 1u) * (ny - 1u));
        for (uint32_t v = 0; v < 4u; v++) {
            const uint32_t n = m->tet[t][v];
            if (n >= m->node_count) {
                return 0u;
            }
            const uint32_t i = n % nx, j = (n / nx) % ny, k = n / (nx * ny);
            if (i - ci > 1u || j - cj > 1u || k - ck > 1u) { /* unsigned: also below */
                return 0u;
            }
        }
    }
    return 1u;
}

int sc_bscan_attach_mesh(sc_bscan *b, const sc_mesh *mesh)
{
    if (b == NULL || mesh == NULL || mesh->tet_count > SC_MAX_TETS) {
        return SC_ERR_INVALID_ARG;
    }
    uint32_t n = 0;
    for (uint32_t t = 0; t < mesh->tet_count; t++) {
        for (uint32_t v = 0; v < 4u; v++) {
            if (mesh->tet_nbr[t][v] < 0) {
                if (n >= SC_BSCAN_MAX_HULL_FACES) {
                    b->hull_count = 0u;
                    b->mesh_tets = 0u;
                    return SC_ERR_NO_SPACE;
                }
                b->hull[n].tet = t;
                b->hull[n].face = v;
                n++;
            }
        }
    }
    b->hull_count = n;
    b->margin_memo.valid = 0u; /* a case switch: the volume may be another under the same pointer */
    b->mesh_tets = mesh->tet_count;
    b->mesh_grid = mesh_is_grid(mesh);
    return SC_OK;
}

void sc_bscan_set_pool(sc_bscan *b, const sc_pool_dev *pool)
{
    if (b != NULL) {
        b->pool = pool;
    }
}

void sc_bscan_set_line_hook(sc_bscan *b, sc_bscan_line_hook_fn fn, void *ctx)
{
    if (b != NULL) {
        b->line_hook = fn;
        b->line_hook_ctx = fn != NULL ? ctx : NULL;
    }
}

const sc_bscan_status *sc_bscan_status_get(const sc_bscan *b)
{
    return &b->status;
}

/* ---- per-frame context -------------------------------------------------------------------- */

typedef struct frame_ctx {
    sc_xform img2vol;  /* image frame -> volume frame */
    float vo[3];       /* volume origin, mm */
    float inv_sp[3];   /* 1 / spacing */
    uint32_t n;        /* samples per line */
    uint32_t margin_n; /* samples of the rest reference above the face */
    /* current line: its index and, in the image frame, its origin and direction */
    uint32_t line;
    float ox, oz, dx, dz;
    /* current line, voxel-index units: rigid position of sample k is f0 + k * fd */
    float f0[3], fd[3];
} frame_ctx;

/* The scratch of the line in flight and the walker's state along a run of lines: the
 * sc_bscan's own on the serial path (and for a range the caller finishes), a range's own on the
 * pool path (sc_bscan_set_pool). Everything a line writes goes through it; the sc_bscan is then
 * read only, except by a serial one (the region bins built on first need, a plane tet's maps
 * on its first test). */
typedef struct line_w {
    sc_bscan *b;
    sc_bscan_run *runs; /* this line's runs, run_count of them */
    uint32_t run_count;
    uint8_t *label; /* this line's labels: deformed (what the hook sees) */
    uint8_t *rest;  /* the rest labels for the counts: label itself (serial) or a copy */
    uint8_t *out;   /* this line's displayed samples */
    uint32_t (*pos_h)[SC_MAX_SCAN_SAMPLES + 8u];
    sc_bscan_event *events;
    uint32_t *active; /* the walker's boundary segments that reach the current line */
    uint32_t active_n, active_cap;
    sc_bscan_tcache *tcache; /* the walker's tet cache (a power-of-two slice) */
    uint32_t tmask;
    sc_bscan_counts *cnt;
    uint32_t *regions_need; /* set when a line wanted the region bins */
    int serial; /* nothing else runs: may build the region bins, call the hook, the speckle pass */
    int stop;   /* a range's line needs what only a serial one may do: handed to the caller */
} line_w;

/* mm (volume frame) -> voxel-index units */
static void to_vox(const frame_ctx *c, const float p_mm[3], float out[3])
{
    for (uint32_t d = 0; d < 3u; d++) {
        out[d] = (p_mm[d] - c->vo[d]) * c->inv_sp[d];
    }
}

static uint32_t first_k(float s, uint32_t n)
{
    if (!(s > 0.0f)) {
        return 0u;
    }
    if (s >= (float)n) {
        return n;
    }
    /* ceil without the libm call (0 < s < n here) */
    const uint32_t k = (uint32_t)s;
    return (float)k < s ? k + 1u : k;
}

/* A run of samples [k0, k1) inside the mesh whose sampling position (voxel units) is
 * a + k b. Mappers emit runs in increasing k, without overlap. */
static inline void emit_run(line_w *w, uint32_t k0, uint32_t k1, const float a[3],
                            const float bb[3])
{
    /* runs are disjoint and increasing: at most one per sample */
    SC_VALIDATE(k0 < k1 && k1 <= SC_MAX_SCAN_SAMPLES && w->run_count < SC_MAX_SCAN_SAMPLES);
    SC_VALIDATE(w->run_count == 0u || w->runs[w->run_count - 1u].k1 <= k0);
    sc_bscan_run *r = &w->runs[w->run_count++];
    r->k0 = (uint16_t)k0;
    r->k1 = (uint16_t)k1;
    for (uint32_t d = 0; d < 3u; d++) {
        r->a[d] = a[d];
        r->b[d] = bb[d];
    }
}

/* Barycentric coordinates of a tet in the image frame as affine functions of the point:
 * lambda_i(p) = alpha[i] + g[i] . p. Returns 1 for a positively oriented tet, -1 for an
 * inverted one (still a valid point location), 0 for a degenerate (flat) one. */
/* The edges from vertex 0, the rows of the adjugate of [e1 e2 e3] ((e2 x e3, e3 x e1, e1 x e2))
 * and the determinant: tet_affine's first part, also the region bins' orientation test. */
static inline float tet_edges_det(const sc_bscan *b, const uint32_t tv[4], float e[3][3],
                                  float r[3][3])
{
    const float x0 = b->qx[tv[0]], y0 = b->qy[tv[0]], z0 = b->qz[tv[0]];
    for (uint32_t i = 0; i < 3u; i++) {
        e[i][0] = b->qx[tv[i + 1u]] - x0;
        e[i][1] = b->qy[tv[i + 1u]] - y0;
        e[i][2] = b->qz[tv[i + 1u]] - z0;
    }
    for (uint32_t i = 0; i < 3u; i++) {
        const float *a = e[(i + 1u) % 3u], *c = e[(i + 2u) % 3u];
        r[i][0] = a[1] * c[2] - a[2] * c[1];
        r[i][1] = a[2] * c[0] - a[0] * c[2];
        r[i][2] = a[0] * c[1] - a[1] * c[0];
    }
    return e[0][0] * r[0][0] + e[0][1] * r[0][1] + e[0][2] * r[0][2];
}

/* The orientation tet_affine returns, without the maps. */
static int tet_orient(const sc_bscan *b, const uint32_t tv[4])
{
    float e[3][3], r[3][3];
    const float det = tet_edges_det(b, tv, e, r);
    if (!(fabsf(det) > 1e-12f)) {
        return 0;
    }
    return det > 0.0f ? 1 : -1;
}

static int tet_affine(const sc_bscan *b, const uint32_t tv[4], float alpha[4], float g[4][3])
{
    const float x0 = b->qx[tv[0]], y0 = b->qy[tv[0]], z0 = b->qz[tv[0]];
    /* rows of the inverse of [e1 e2 e3]: (e2 x e3, e3 x e1, e1 x e2) / det */
    float e[3][3], r[3][3];
    const float det = tet_edges_det(b, tv, e, r);
    if (!(fabsf(det) > 1e-12f)) {
        return 0;
    }
    const int sign = det > 0.0f ? 1 : -1;
    const float inv = 1.0f / det;
    float sa = 0.0f, sg[3] = {0.0f, 0.0f, 0.0f};
    for (uint32_t i = 0; i < 3u; i++) {
        for (uint32_t d = 0; d < 3u; d++) {
            g[i + 1u][d] = r[i][d] * inv;
            sg[d] += g[i + 1u][d];
        }
        alpha[i + 1u] = -(g[i + 1u][0] * x0 + g[i + 1u][1] * y0 + g[i + 1u][2] * z0);
        sa += alpha[i + 1u];
    }
    alpha[0] = 1.0f - sa;
    for (uint32_t d = 0; d < 3u; d++) {
        g[0][d] = -sg[d];
    }
    return sign;
}

/* ---- walker ------------------------------------------------------------------------------ */

/* Boundary triangles cut by the image plane, as 2D segments, bucketed by their first line. */
/* fminf and fmaxf without the libm call (the portable x86-64 build does not inline them):
 * a NaN argument gives the other one, as theirs; among equal values (+0, -0) either, which
 * the comparisons these boxes serve do not tell apart. */
static inline float min_f(float a, float b)
{
    return (b < a || isnan(a)) ? b : a;
}
static inline float max_f(float a, float b)
{
    return (b > a || isnan(a)) ? b : a;
}

#define SC_BSCAN_HULL_AHEAD 16u

/* The segments of hull faces h0 .. h1 - 1, written from segs[h0] on (a face gives at most one):
 * their number. */
static uint32_t hull_segments(sc_bscan *b, const sc_mesh *m, uint32_t h0, uint32_t h1)
{
    uint32_t ns = h0;
    for (uint32_t h = h0; h < h1; h++) {
#if defined(__GNUC__)
        /* the hull's tets are all over the tet array (4.8 MB at 64x32x32): the corners of the
         * face SC_BSCAN_HULL_AHEAD on asked for now, so that their load does not wait */
        if (h + SC_BSCAN_HULL_AHEAD < h1) {
            __builtin_prefetch(m->tet[b->hull[h + SC_BSCAN_HULL_AHEAD].tet], 0, 1);
        }
#endif
        const uint32_t t = b->hull[h].tet, v = b->hull[h].face;
        uint32_t f[3], fi = 0;
        for (uint32_t w = 0; w < 4u; w++) {
            if (w != v) {
                f[fi++] = m->tet[t][w];
            }
        }
        const uint32_t pos = (uint32_t)(b->qy[f[0]] > 0.0f) + (uint32_t)(b->qy[f[1]] > 0.0f) +
                             (uint32_t)(b->qy[f[2]] > 0.0f);
        if (pos == 0u || pos == 3u) {
            continue;
        }
        /* the two edges whose ends differ in class; the cut point is computed from the lower
         * node index so that both triangles sharing an edge get the identical point */
        float px[2] = {0.0f, 0.0f}, pz[2] = {0.0f, 0.0f}; /* both set: np reaches 2 */
        uint32_t np = 0;
        for (uint32_t a = 0; a < 3u; a++) {
            uint32_t i = f[a], j = f[(a + 1u) % 3u];
            if ((b->qy[i] > 0.0f) == (b->qy[j] > 0.0f)) {
                continue;
            }
            if (j < i) {
                const uint32_t s = i;
                i = j;
                j = s;
            }
            const float tt = b->qy[i] / (b->qy[i] - b->qy[j]);
            px[np] = b->qx[i] + tt * (b->qx[j] - b->qx[i]);
            pz[np] = b->qz[i] + tt * (b->qz[j] - b->qz[i]);
            np++;
        }
        SC_ASSERT(np == 2u);
        /* outward normal: away from the tet's fourth vertex */
        const uint32_t n0 = f[0], n1 = f[1], n2 = f[2], nv = m->tet[t][v];
        const float e1[3] = {b->qx[n1] - b->qx[n0], b->qy[n1] - b->qy[n0], b->qz[n1] - b->qz[n0]};
        const float e2[3] = {b->qx[n2] - b->qx[n0], b->qy[n2] - b->qy[n0], b->qz[n2] - b->qz[n0]};
        float nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
        const float side = nrm[0] * (b->qx[nv] - b->qx[n0]) + nrm[1] * (b->qy[nv] - b->qy[n0]) +
                           nrm[2] * (b->qz[nv] - b->qz[n0]);
        if (side > 0.0f) {
            nrm[0] = -nrm[0];
            nrm[2] = -nrm[2];
        }
        int32_t lo, hi;
        if (!sc_scan_geom_line_range(&b->geom, min_f(px[0], px[1]), max_f(px[0], px[1]),
                                     min_f(pz[0], pz[1]), max_f(pz[0], pz[1]), &lo, &hi)) {
            continue;
        }
        sc_bscan_seg *s = &b->segs[ns++];
        s->ax = px[0];
        s->az = pz[0];
        s->bx = px[1];
        s->bz = pz[1];
        s->nx = nrm[0];
        s->nz = nrm[2];
        s->tet = t;
        s->face = v;
        s->line_lo = lo;
        s->line_hi = hi;
    }
    return ns - h0;
}

#if SC_BSCAN_RANGES > 1
/* The hull faces on the pool: part p takes faces [h0, h1) of an even split and writes their
 * segments from segs[h0] on; the parts are then moved together in part order, which is the hull's
 * order: the serial pass's segments in its order. */
typedef struct seg_job {
    sc_bscan *b;
    const sc_mesh *m;
    uint32_t parts;
    uint32_t n[SC_BSCAN_RANGES];
} seg_job;

static void hull_part(const seg_job *j, uint32_t p, uint32_t *h0, uint32_t *h1)
{
    const uint64_t hc = j->b->hull_count;
    *h0 = (uint32_t)(((uint64_t)p * hc) / j->parts);
    *h1 = (uint32_t)(((uint64_t)(p + 1u) * hc) / j->parts);
}

static void job_segments(void *arg, uint32_t p)
{
    seg_job *j = (seg_job *)arg;
    uint32_t h0, h1;
    hull_part(j, p, &h0, &h1);
    j->n[p] = hull_segments(j->b, j->m, h0, h1);
}
#endif

static void build_segments(sc_bscan *b, const sc_mesh *m)
{
    const uint32_t lines = b->def.scan.lines_n;
    uint32_t ns = 0;
#if SC_BSCAN_RANGES > 1
    if (sc_pool_workers(b->pool) > 1u) {
        /* 64x32x32, two workers: 0.13 ms a frame on the caller alone */
        seg_job j = {.b = b, .m = m, .parts = SC_BSCAN_RANGES};
        sc_pool_run(b->pool, job_segments, &j, j.parts);
        for (uint32_t p = 0; p < j.parts; p++) {
            uint32_t h0, h1;
            hull_part(&j, p, &h0, &h1);
            if (h0 != ns && j.n[p] > 0u) {
                memmove(&b->segs[ns], &b->segs[h0], j.n[p] * sizeof b->segs[0]);
            }
            ns += j.n[p];
        }
    } else
#endif
    {
        ns = hull_segments(b, m, 0u, b->hull_count);
    }
    b->seg_count = ns;
    /* counting sort by first line */
    for (uint32_t l = 0; l <= lines; l++) {
        b->seg_start[l] = 0u;
    }
    for (uint32_t i = 0; i < ns; i++) {
        b->seg_start[(uint32_t)b->segs[i].line_lo + 1u]++;
    }
    for (uint32_t l = 0; l < lines; l++) {
        b->seg_start[l + 1u] += b->seg_start[l];
    }
    for (uint32_t i = 0; i < ns; i++) {
        /* seg_start[lo] doubles as the fill cursor, restored below */
        b->seg_sorted[b->seg_start[(uint32_t)b->segs[i].line_lo]++] = i;
    }
    for (uint32_t l = lines; l > 0u; l--) {
        b->seg_start[l] = b->seg_start[l - 1u];
    }
    b->seg_start[0] = 0u;
}

/* a sorts before b: by s, entries first on ties, then by segment index (a total order) */
static inline int event_before(const sc_bscan_event *a, const sc_bscan_event *b)
{
    return a->s < b->s ||
           (!(a->s > b->s) && (a->entry > b->entry || (a->entry == b->entry && a->seg < b->seg)));
}

/* Crossings of line l (ray O + s D in the image frame) with the active segments, sorted by s
 * (entries first on ties, then by segment index: deterministic). Returns the count. */
static uint32_t line_events(line_w *w, uint32_t l, const frame_ctx *c)
{
    const sc_bscan *b = w->b;
    uint32_t na = w->active_n;
    if (na + (b->seg_start[l + 1u] - b->seg_start[l]) > w->active_cap) {
        w->stop = 1; /* a range's active list is full (a serial one holds every segment) */
        return 0u;
    }
    for (uint32_t i = b->seg_start[l]; i < b->seg_start[l + 1u]; i++) {
        w->active[na++] = b->seg_sorted[i];
    }
    const float dd = c->dx * c->dx + c->dz * c->dz;
    uint32_t ne = 0;
    int overflow = 0;
    for (uint32_t i = 0; i < na;) {
        const uint32_t si = w->active[i];
        const sc_bscan_seg *s = &b->segs[si];
        if (s->line_hi < (int32_t)l) {
            w->active[i] = w->active[--na];
            continue;
        }
        i++;
        const float sa = c->dx * (s->az - c->oz) - c->dz * (s->ax - c->ox);
        const float sb = c->dx * (s->bz - c->oz) - c->dz * (s->bx - c->ox);
        if ((sa > 0.0f) == (sb > 0.0f)) {
            continue;
        }
        const float t = sa / (sa - sb);
        const float qx = s->ax + t * (s->bx - s->ax) - c->ox;
        const float qz = s->az + t * (s->bz - s->az) - c->oz;
        const float sp = (qx * c->dx + qz * c->dz) / dd;
        if (!(sp >= b->geom.s_min)) { /* (a NaN too: the order below is then total) */
            continue;
        }
        sc_bscan_event ev = {
            .s = sp, .seg = si, .entry = (uint8_t)(s->nx * c->dx + s->nz * c->dz < 0.0f)};
        if (ne >= SC_BSCAN_MAX_LINE_EVENTS) {
            /* over the limit: the first SC_BSCAN_MAX_LINE_EVENTS in the order below are kept
             * (whatever the order of the active list: a range of lines rebuilds it) */
            overflow = 1;
            if (!event_before(&ev, &w->events[ne - 1u])) {
                continue;
            }
            ne--;
        }
        /* insertion sort: lists are short (2..8 typically) */
        uint32_t j = ne++;
        while (j > 0u) {
            const sc_bscan_event *p = &w->events[j - 1u];
            if (event_before(p, &ev)) {
                break;
            }
            w->events[j] = *p;
            j--;
        }
        w->events[j] = ev;
    }
    if (overflow) {
        w->cnt->event_overflows++;
    }
    w->active_n = na;
    return ne;
}

/* The active list of line l before its own segments are added: the segments that start
 * before l and reach it (as a run of lines from line 0 leaves it, in another order: the events
 * do not depend on it). Returns 0 when they do not fit (a range's list). O(segments). */
static int active_at(line_w *w, uint32_t l)
{
    const sc_bscan *b = w->b;
    uint32_t na = 0;
    for (uint32_t i = 0; i < b->seg_start[l]; i++) {
        const uint32_t si = b->seg_sorted[i];
        if (b->segs[si].line_hi >= (int32_t)l) {
            if (na >= w->active_cap) {
                return 0;
            }
            w->active[na++] = si;
        }
    }
    w->active_n = na;
    return 1;
}

/* tet_cached's miss: tet t's maps into entry tc */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static const sc_bscan_tcache *
tet_fill(const sc_bscan *b, const sc_mesh *m, uint32_t t, sc_bscan_tcache *tc)
{
    tc->epoch = b->epoch;
    tc->tet = t;
    const uint32_t *tv = m->tet[t];
    float al[4], g[4][3];
    tc->orient = tet_affine(b, tv, al, g);
    if (tc->orient == 0) {
        return tc;
    }
    for (uint32_t i = 0; i < 4u; i++) {
        tc->lam[0][i] = al[i];
        tc->lam[1][i] = g[i][0];
        tc->lam[2][i] = g[i][2];
    }
    for (uint32_t j = 0; j < 3u; j++) {
        tc->rest[j][0] = 0.0f;
        tc->rest[j][1] = 0.0f;
        tc->rest[j][2] = 0.0f;
        tc->rest[j][3] = 0.0f;
        for (uint32_t i = 0; i < 4u; i++) {
            tc->rest[j][0] += tc->lam[j][i] * m->rest_x[tv[i]];
            tc->rest[j][1] += tc->lam[j][i] * m->rest_y[tv[i]];
            tc->rest[j][2] += tc->lam[j][i] * m->rest_z[tv[i]];
        }
    }
    return tc;
}

/* The plane-affine maps of tet t for this frame, from a direct-mapped cache (adjacent scan
 * lines cross the same tets). Hit or miss, the values are the same: computed by one function
 * from the same inputs. The hit inline, in the walker's step and the fold search's tests. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline const sc_bscan_tcache *
tet_cached(line_w *w, const sc_mesh *m, uint32_t t)
{
    const sc_bscan *b = w->b;
    sc_bscan_tcache *tc = &w->tcache[t & w->tmask];
    if (tc->epoch == b->epoch && tc->tet == t) {
        return tc;
    }
    return tet_fill(b, m, t, tc);
}

static int build_regions(sc_bscan *b, const sc_mesh *m);
static void map_line_regions(line_w *w, const sc_mesh *m, uint32_t l, const frame_ctx *c);
static int32_t locate_deepest(line_w *w, const sc_mesh *m, uint32_t r, float x, float z);
static void fill_run(line_w *w, const sc_mesh *m, const frame_ctx *c, uint32_t ta, uint32_t a,
                     uint32_t z);
static uint32_t region_of_line(uint32_t l, uint32_t lines, uint32_t regions);

/* Where the walk cannot go on through face neighbours (a fold: an inverted or flat tet next),
 * the samples from ks on are located among the tets cut by the plane: a sample inside a
 * positively oriented tet ends the search (*t_out, *s_out: the walk goes on from there); one
 * covered by inverted tets only takes the deepest of them; one in no tet has left the mesh.
 * Returns 1 with the tet to walk on from, 0 when the line left the mesh or ended (*s_out: where),
 * -1 when the region bins are over their limits (the caller falls back). fill_first: the first
 * sample is filled from the tet found whatever its orientation (a walk that relocated at this
 * sample and could not move on: no loop). O(samples located x tets of the line's region). */
/* The region bins for a line that wants them: built on first need by a serial run of lines;
 * a range on the pool cannot build them (other ranges read them): it stops (w->stop) and the
 * caller does this line and the rest of the range. Returns 1 when they are usable. */
static int regions_ready(line_w *w, const sc_mesh *m)
{
    sc_bscan *b = w->b;
    *w->regions_need = 1u;
    if (b->regions_state == 0u) {
        if (!w->serial) {
            w->stop = 1;
            return 0;
        }
        b->regions_state = build_regions(b, m) ? 1u : 2u;
    }
    return b->regions_state == 1u;
}

static int relocate(line_w *w, const sc_mesh *m, const frame_ctx *c, uint32_t ks, uint32_t *k,
                    int fill_first, uint32_t *t_out, float *s_out)
{
    sc_bscan *b = w->b;
    if (!regions_ready(w, m)) {
        return -1;
    }
    const uint32_t r = region_of_line(c->line, b->def.scan.lines_n, b->def.regions_n);
    for (uint32_t kk = ks < *k ? *k : ks; kk < c->n; kk++) {
        const int32_t pi =
            locate_deepest(w, m, r, c->ox + (float)kk * c->dx, c->oz + (float)kk * c->dz);
        if (pi < 0) {
            *s_out = (float)kk;
            return 0;
        }
        const sc_bscan_ptet *p = &b->ptets[pi];
        if (p->orient > 0 && !fill_first) {
            *t_out = p->tet;
            *s_out = (float)kk;
            return 1;
        }
        fill_run(w, m, c, (uint32_t)pi, kk, kk);
        *k = kk + 1u;
        fill_first = 0;
    }
    *s_out = (float)c->n;
    return 0;
}

/* Four floats of the walker's step (a tet's four faces, or a point's three coordinates and a
 * pad), lane by lane the same IEEE operations as the scalar expressions they replace: GCC's
 * vectors where there are any (SSE, NEON; lowered to scalar code elsewhere), arrays otherwise
 * (and in the one-lane build, -DSC_VEC_SCALAR, which tests that path). */
#if defined(__GNUC__) && !defined(SC_VEC_SCALAR)
#define SC_W4_VECTOR 1
#else
#define SC_W4_VECTOR 0
#endif
#if SC_W4_VECTOR
typedef float w4 __attribute__((vector_size(16)));
static inline w4 w4_ld(const float *p)
{
    w4 v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline w4 w4_splat(float x)
{
    const w4 v = {x, x, x, x};
    return v;
}
#define W4_LANE(v, i) ((v)[i])
#else
typedef struct w4 {
    float l[4];
} w4;
static inline w4 w4_ld(const float *p)
{
    w4 v;
    memcpy(v.l, p, sizeof v.l);
    return v;
}
static inline w4 w4_splat(float x)
{
    const w4 v = {{x, x, x, x}};
    return v;
}
#define W4_LANE(v, i) ((v).l[i])
#endif
/* a + b x + c y, and b x + c y, lane by lane */
static inline w4 w4_affine(w4 a, w4 b, w4 c, float x, float y)
{
#if SC_W4_VECTOR
    return (a + b * w4_splat(x)) + c * w4_splat(y);
#else
    w4 r;
    for (uint32_t i = 0; i < 4u; i++) {
        r.l[i] = (a.l[i] + b.l[i] * x) + c.l[i] * y;
    }
    return r;
#endif
}
static inline w4 w4_lin(w4 b, w4 c, float x, float y)
{
#if SC_W4_VECTOR
    return b * w4_splat(x) + c * w4_splat(y);
#else
    w4 r;
    for (uint32_t i = 0; i < 4u; i++) {
        r.l[i] = b.l[i] * x + c.l[i] * y;
    }
    return r;
#endif
}
/* (a - o) s and a s, lane by lane */
static inline w4 w4_subs(w4 a, w4 o, w4 sc)
{
#if SC_W4_VECTOR
    return (a - o) * sc;
#else
    w4 r;
    for (uint32_t i = 0; i < 4u; i++) {
        r.l[i] = (a.l[i] - o.l[i]) * sc.l[i];
    }
    return r;
#endif
}
static inline w4 w4_mul(w4 a, w4 sc)
{
#if SC_W4_VECTOR
    return a * sc;
#else
    w4 r;
    for (uint32_t i = 0; i < 4u; i++) {
        r.l[i] = a.l[i] * sc.l[i];
    }
    return r;
#endif
}

/* Walk the current line from tet t, entered through local face f_in (4: none) at line
 * parameter s_in, writing the rest positions of the samples from *k on. Returns the parameter
 * where the walk left the mesh (or >= n when it reached the end of the line). */
static float walk(line_w *w, const sc_mesh *m, const frame_ctx *c, uint32_t t, uint32_t f_in,
                  float s_in, uint32_t *k_io, uint32_t *steps_io, int *trouble)
{
    const uint32_t n = c->n;
    /* the sample and step counts in registers (the runs' stores may alias what they point
     * at), written back at the one way out */
    uint32_t k = *k_io, steps = *steps_io;
    float out = (float)n; /* where the walk left the mesh: n at the line's end or in trouble */
    /* the line in locals: the cache's stores cannot alias them */
    const float ox = c->ox, oz = c->oz, dx = c->dx, dz = c->dz;
    const float vo4[4] = {c->vo[0], c->vo[1], c->vo[2], 0.0f};
    const float sp4[4] = {c->inv_sp[0], c->inv_sp[1], c->inv_sp[2], 0.0f};
    const w4 vo = w4_ld(vo4), isp = w4_ld(sp4);
    uint32_t reloc_k = UINT32_MAX; /* the sample of the last relocation */
    uint32_t k_in = first_k(s_in, n); /* first_k(s_in), carried from the last step's exit */
    for (;;) {
        if (steps >= SC_BSCAN_MAX_WALK_STEPS) {
            w->cnt->walk_aborts++;
            *trouble = 1;
            break;
        }
        steps++;
        const sc_bscan_tcache *tc = tet_cached(w, m, t);
        if (tc->orient != 1) {
            /* flat or inverted: a fold; locate the samples from here on and walk on */
            uint32_t tn = 0;
            float sn = 0.0f;
            const uint32_t ks = k_in;
            uint32_t kr = k;
            const int rr = relocate(w, m, c, ks, &kr, ks == reloc_k && k <= ks, &tn, &sn);
            k = kr;
            if (rr < 0) {
                *trouble = 1;
                break;
            }
            if (rr == 0) {
                out = sn;
                break;
            }
            w->cnt->walk_relocations++;
            reloc_k = (uint32_t)sn;
            t = tn;
            f_in = 4u;
            s_in = sn;
            k_in = first_k(s_in, n);
            continue;
        }
        const w4 l1 = w4_ld(tc->lam[1]), l2 = w4_ld(tc->lam[2]);
        const w4 av = w4_affine(w4_ld(tc->lam[0]), l1, l2, ox, oz), bv = w4_lin(l1, l2, dx, dz);
        const float a[4] = {W4_LANE(av, 0), W4_LANE(av, 1), W4_LANE(av, 2), W4_LANE(av, 3)};
        const float be[4] = {W4_LANE(bv, 0), W4_LANE(bv, 1), W4_LANE(bv, 2), W4_LANE(bv, 3)};
        /* exit: the face whose coordinate reaches 0 first, s_i = -a_i / be_i over be_i < 0;
         * compared by cross-multiplication (be_i be_j > 0), one division at the end. Selects,
         * not branches: which face it is does not follow a pattern the predictor learns. */
        uint32_t f_out = 4u;
        float af = 0.0f, bf = 0.0f; /* a and be of f_out */
        for (uint32_t i = 0; i < 4u; i++) {
            const int take =
                (i != f_in) & (be[i] < 0.0f) & ((f_out == 4u) | (a[i] * bf > af * be[i]));
            f_out = take ? i : f_out;
            af = take ? a[i] : af;
            bf = take ? be[i] : bf;
        }
        if (f_out == 4u) {
            *trouble = 1; /* no way out along the ray: degenerate */
            break;
        }
        float s_out = -af / bf;
        if (s_out < s_in) {
            s_out = s_in;
        }
        const uint32_t k0 = k_in < k ? k : k_in;
        const uint32_t k1 = first_k(s_out, n);
        if (k1 > k0) {
            /* rest position along the ray inside this tet: A + s B (mm), then voxel units */
            const w4 r1 = w4_ld(tc->rest[1]), r2 = w4_ld(tc->rest[2]);
            const w4 ra = w4_affine(w4_ld(tc->rest[0]), r1, r2, ox, oz);
            const w4 vbv = w4_mul(w4_lin(r1, r2, dx, dz), isp), vav = w4_subs(ra, vo, isp);
            const float va[3] = {W4_LANE(vav, 0), W4_LANE(vav, 1), W4_LANE(vav, 2)};
            const float vb[3] = {W4_LANE(vbv, 0), W4_LANE(vbv, 1), W4_LANE(vbv, 2)};
            emit_run(w, k0, k1, va, vb); /* to_vox's (p - vo) inv_sp, lane by lane */
            k = k1;
        }
        const int32_t nb = m->tet_nbr[t][f_out];
        if (s_out >= (float)n || nb < 0) {
            out = s_out;
            break;
        }
        const uint32_t u = (uint32_t)nb;
        uint32_t back = 4u;
        for (uint32_t v = 0; v < 4u; v++) {
            back = m->tet_nbr[u][v] == (int32_t)t ? v : back;
        }
        t = u;
        f_in = back;
        s_in = s_out;
        k_in = k1;
    }
    *k_io = k;
    *steps_io = steps;
    return out;
}

static void map_line_walk(line_w *w, const sc_mesh *m, uint32_t l, const frame_ctx *c)
{
    sc_bscan *const b = w->b;
    const uint32_t ne = line_events(w, l, c);
    uint32_t k = 0, steps = 0, ei = 0;
    int trouble = 0;
    if (ne > 0u && !w->events[0].entry) {
        /* the line starts inside the mesh (behind the face) or the boundary is folded: the
         * walk starts by locating the first pixel. Also when that exit lies behind the first
         * pixel: under a pressed face the skin's boundary triangles lie in the face's plane,
         * so the crossing is at s ~ 0 and its side (entry or exit) is a rounding, cell by
         * cell; skipping it left whole lines unmapped (bars in a rocked frame, 9 lines wide:
         * test_bscan_folds). A line that does start outside costs one point location. */
        ei = 1u;
        uint32_t t0 = 0;
        float s0 = 0.0f;
        const int rr = relocate(w, m, c, 0u, &k, 0, &t0, &s0);
        float sx = s0;
        if (rr < 0) {
            trouble = 1;
        } else if (rr > 0) {
            w->cnt->walk_relocations++;
            sx = walk(w, m, c, t0, 4u, s0, &k, &steps, &trouble);
        }
        while (ei < ne && w->events[ei].s < sx - 1e-3f) {
            ei++;
        }
    }
    while (!trouble && ei < ne && k < c->n) {
        const sc_bscan_event *e = &w->events[ei++];
        if (!e->entry) {
            continue;
        }
        if (e->s >= (float)c->n) {
            break;
        }
        const sc_bscan_seg *s = &b->segs[e->seg];
        const float sx = walk(w, m, c, s->tet, s->face, e->s, &k, &steps, &trouble);
        /* boundary crossings before the exit are behind us */
        while (ei < ne && w->events[ei].s < sx - 1e-3f) {
            ei++;
        }
    }
    w->cnt->walk_steps += steps;
    if (trouble && !w->stop) {
        /* inverted or flat tets, a folded boundary, a line starting inside the mesh: this
         * line goes through point location (the region path), which needs none of it */
        if (regions_ready(w, m)) {
            w->run_count = 0u;
            map_line_regions(w, m, l, c);
            w->cnt->line_fallbacks++;
        } else if (!w->stop) {
            w->cnt->region_overflows++;
        }
    }
}

/* ---- region path (paper section IV) ---------------------------------------------------- */

static uint32_t region_of_line(uint32_t l, uint32_t lines, uint32_t regions)
{
    return (l * regions) / lines;
}

/* Index of the lowest set bit of x != 0. */
static inline uint32_t sc_ctz64(uint64_t x)
{
#if defined(__GNUC__)
    return (uint32_t)__builtin_ctzll(x);
#else
    uint32_t n = 0;
    while ((x & 1u) == 0u) {
        x >>= 1;
        n++;
    }
    return n;
#endif
}

_Static_assert(SC_BSCAN_MAX_REGIONS <= 256u, "a plane tet's regions are bytes");

/* Tet t into the plane tets when the plane cuts it (not flat, in front of some line): 0 when
 * the plane tets are over their limit. */
static int add_plane_tet(sc_bscan *b, const sc_mesh *m, uint32_t t, uint32_t *np_io,
                         uint32_t limit)
{
    const uint32_t np = *np_io;
    const uint32_t *tv = m->tet[t];
    uint32_t pos = 0;
    for (uint32_t v = 0; v < 4u; v++) {
        pos += (uint32_t)(b->qy[tv[v]] > 0.0f);
    }
    if (pos == 0u || pos == 4u) {
        /* all on one side; a tet with a face in the plane (three y = 0, one < 0) counts
         * through its neighbour on the other side */
        return 1;
    }
    const int orient = tet_orient(b, tv);
    if (orient == 0) {
        return 1;
    }
    float xmin = b->qx[tv[0]], xmax = xmin, zmin = b->qz[tv[0]], zmax = zmin;
    for (uint32_t v = 1; v < 4u; v++) {
        xmin = min_f(xmin, b->qx[tv[v]]);
        xmax = max_f(xmax, b->qx[tv[v]]);
        zmin = min_f(zmin, b->qz[tv[v]]);
        zmax = max_f(zmax, b->qz[tv[v]]);
    }
    int32_t lo, hi;
    if (!sc_scan_geom_line_range(&b->geom, xmin, xmax, zmin, zmax, &lo, &hi)) {
        return 1;
    }
    if (np >= limit) {
        return 0;
    }
    sc_bscan_ptet *p = &b->ptets[np];
    p->tet = t;
    p->orient = orient;
    p->xmin = xmin;
    p->xmax = xmax;
    p->zmin = zmin;
    p->zmax = zmax;
    /* the regions of its first and last line (here, on the pool's parts, not in the caller's
     * binning: two divisions a tet) */
    const uint32_t lines = b->def.scan.lines_n, regions = b->def.regions_n;
    b->ptet_region[np][0] = (uint8_t)region_of_line((uint32_t)lo, lines, regions);
    b->ptet_region[np][1] = (uint8_t)region_of_line((uint32_t)hi, lines, regions);
    *np_io = np + 1u;
    return 1;
}

/* The plane tets of a grid mesh's cells between node layers k_begin - 1 .. k_end - 1: the cells
 * with corners on both sides of the plane, found from 64-bit masks of the node rows (bit i:
 * y > 0), two layers of rows at a time: O(nodes) plus the cut cells' tets instead of a pass over
 * every tet; the same tets in the same (ascending) order, as a tet cut by the plane has its
 * corners among its cell's. Written from ptets[*np_io] on, below limit; 0 when over it. */
static int cut_layers(sc_bscan *b, const sc_mesh *m, uint32_t k_begin, uint32_t k_end,
                      uint32_t *np_io, uint32_t limit)
{
    const uint32_t nx = m->nx, ny = m->ny;
    uint64_t rows[2][SC_MAX_MESH_NY];
    const uint64_t cells_x = ((uint64_t)1 << (nx - 1u)) - 1u; /* nx <= 64 */
    for (uint32_t k = k_begin - 1u; k < k_end; k++) {
        uint64_t *cur = rows[k & 1u];
        for (uint32_t j = 0; j < ny; j++) {
            const float *qy = &b->qy[nx * (j + ny * k)];
            uint64_t mk = 0;
            for (uint32_t i = 0; i < nx; i++) {
                mk |= (uint64_t)(qy[i] > 0.0f) << i;
            }
            cur[j] = mk;
        }
        if (k + 1u == k_begin) {
            continue;
        }
        const uint64_t *prev = rows[(k - 1u) & 1u];
        for (uint32_t j = 0; j + 1u < ny; j++) {
            const uint64_t any = prev[j] | prev[j + 1u] | cur[j] | cur[j + 1u];
            const uint64_t all = prev[j] & prev[j + 1u] & cur[j] & cur[j + 1u];
            uint64_t cut = (any | (any >> 1)) & ~(all & (all >> 1)) & cells_x;
            const uint32_t c0 = (nx - 1u) * (j + (ny - 1u) * (k - 1u));
            while (cut != 0u) {
                const uint32_t i = sc_ctz64(cut);
                cut &= cut - 1u;
                for (uint32_t t = 5u * (c0 + i); t < 5u * (c0 + i) + 5u; t++) {
                    if (!add_plane_tet(b, m, t, np_io, limit)) {
                        return 0;
                    }
                }
            }
        }
    }
    return 1;
}

/* box bx (xmin, xmax, zmin, zmax) grown by the box x0 .. x1, z0 .. z1 */
static void box_grow(float bx[4], float x0, float x1, float z0, float z1)
{
    bx[0] = min_f(bx[0], x0);
    bx[1] = max_f(bx[1], x1);
    bx[2] = min_f(bx[2], z0);
    bx[3] = max_f(bx[3], z1);
}

/* The region bins' census of plane tets i0 .. i1 - 1: cnt[r] += the tets of region r, box[r]
 * grown by their boxes. */
static void bin_count(const sc_bscan *b, uint32_t i0, uint32_t i1, uint32_t *cnt, float (*box)[4])
{
    for (uint32_t i = i0; i < i1; i++) {
        const uint32_t r0 = b->ptet_region[i][0], r1 = b->ptet_region[i][1];
        const sc_bscan_ptet *p = &b->ptets[i];
        for (uint32_t r = r0; r <= r1; r++) {
            cnt[r]++;
            box_grow(box[r], p->xmin, p->xmax, p->zmin, p->zmax);
        }
    }
}

/* Plane tets i0 .. i1 - 1 into the bins: region r's next ones at cur[r] on (advanced). */
static void bin_fill(sc_bscan *b, uint32_t i0, uint32_t i1, uint32_t *cur)
{
    for (uint32_t i = i0; i < i1; i++) {
        const uint32_t r0 = b->ptet_region[i][0], r1 = b->ptet_region[i][1];
        for (uint32_t r = r0; r <= r1; r++) {
            b->region_refs[cur[r]++] = i;
        }
    }
}

static void boxes_empty(float (*box)[4], uint32_t regions)
{
    for (uint32_t r = 0; r < regions; r++) {
        box[r][0] = INFINITY;
        box[r][1] = -INFINITY;
        box[r][2] = INFINITY;
        box[r][3] = -INFINITY;
    }
}

/* The bins from the census of `parts` runs of plane tets (run p: cnt[p], box[p]): region_start,
 * region_box, and cnt[p][r] turned into run p's cursor in bin r (run after run: the tets'
 * order). Returns the references in all. */
static uint32_t bins_place(sc_bscan *b, uint32_t parts, uint32_t (*cnt)[SC_BSCAN_MAX_REGIONS],
                           float (*box)[SC_BSCAN_MAX_REGIONS][4])
{
    const uint32_t regions = b->def.regions_n;
    uint32_t total = 0;
    boxes_empty(b->region_box, regions);
    for (uint32_t r = 0; r < regions; r++) {
        b->region_start[r] = total;
        for (uint32_t p = 0; p < parts; p++) {
            const uint32_t c = cnt[p][r];
            cnt[p][r] = total; /* run p's part of bin r starts here */
            total += c;
            const float *pb = box[p][r];
            box_grow(b->region_box[r], pb[0], pb[1], pb[2], pb[3]);
        }
    }
    b->region_start[regions] = total;
    return total;
}

#if SC_BSCAN_RANGES > 1
/* The cut layers and the bins on the pool. Part p takes a share of the node layers, writes its
 * tets from ptets[p * cap] on (cap: its share of the capacity) and counts them by region; the
 * caller places each part's run of each region's bin (part after part: tet order), and the parts
 * then fill their runs. So a region's bin lists the serial pass's tets in its order (their
 * indices are where the parts wrote them: nothing is moved), and its box bounds the same boxes. */
typedef struct cut_job {
    sc_bscan *b;
    const sc_mesh *m;
    uint32_t parts, cap;
    uint32_t n[SC_BSCAN_RANGES];
    uint8_t ok[SC_BSCAN_RANGES];
} cut_job;

static void job_cut(void *arg, uint32_t p)
{
    cut_job *j = (cut_job *)arg;
    const uint32_t layers = j->m->nz - 1u;
    const uint32_t k0 = 1u + (uint32_t)(((uint64_t)p * layers) / j->parts);
    const uint32_t k1 = 1u + (uint32_t)(((uint64_t)(p + 1u) * layers) / j->parts);
    uint32_t np = p * j->cap;
    j->ok[p] = (uint8_t)(k0 >= k1 || cut_layers(j->b, j->m, k0, k1, &np, (p + 1u) * j->cap));
    j->n[p] = np - p * j->cap;
    sc_bscan *b = j->b;
    const uint32_t regions = b->def.regions_n;
    for (uint32_t r = 0; r < regions; r++) {
        b->part_cnt[p][r] = 0u;
    }
    boxes_empty(b->part_box[p], regions);
    if (j->ok[p]) {
        bin_count(b, p * j->cap, np, b->part_cnt[p], b->part_box[p]);
    }
}

static void job_fill(void *arg, uint32_t p)
{
    cut_job *j = (cut_job *)arg;
    bin_fill(j->b, p * j->cap, p * j->cap + j->n[p], j->b->part_cnt[p]);
}

/* The pool's pass (sc_bscan_frame's regions on two workers and more): 1 with the bins built, 0
 * over the limits, -1 when a part went over its share (the caller's pass decides). */
static int regions_pool(sc_bscan *b, const sc_mesh *m)
{
    /* 64x32x32 on two workers: the cut 0.51-0.56 ms a frame on the caller alone, the bins
     * 0.13 ms */
    cut_job j;
    j.b = b;
    j.m = m;
    j.parts = m->nz - 1u < SC_BSCAN_RANGES ? m->nz - 1u : SC_BSCAN_RANGES;
    j.cap = SC_BSCAN_MAX_PLANE_TETS / j.parts;
    sc_pool_run(b->pool, job_cut, &j, j.parts);
    uint32_t np = 0;
    for (uint32_t p = 0; p < j.parts; p++) {
        if (!j.ok[p]) {
            return -1;
        }
        np += j.n[p];
    }
    b->ptet_count = np;
    if (bins_place(b, j.parts, b->part_cnt, b->part_box) > SC_BSCAN_MAX_REGION_REFS) {
        return 0;
    }
    sc_pool_run(b->pool, job_fill, &j, j.parts);
    return 1;
}
#endif

/* Returns 0 when the path's limits are exceeded (the caller then walks this frame). */
static int build_regions(sc_bscan *b, const sc_mesh *m)
{
    const uint32_t regions = b->def.regions_n;
    uint32_t np = 0;
    if (b->mesh_grid) {
#if SC_BSCAN_RANGES > 1
        if (sc_pool_workers(b->pool) > 1u && m->nz > 2u) {
            const int rc = regions_pool(b, m);
            if (rc >= 0) {
                return rc;
            }
            /* a part over its share: the whole pass on the caller decides */
        }
#endif
        if (!cut_layers(b, m, 1u, m->nz, &np, SC_BSCAN_MAX_PLANE_TETS)) {
            return 0;
        }
    } else {
        for (uint32_t t = 0; t < m->tet_count; t++) {
            if (!add_plane_tet(b, m, t, &np, SC_BSCAN_MAX_PLANE_TETS)) {
                return 0;
            }
        }
    }
    b->ptet_count = np;
    uint32_t cnt[1][SC_BSCAN_MAX_REGIONS] = {{0}};
    float box[1][SC_BSCAN_MAX_REGIONS][4];
    boxes_empty(box[0], regions);
    bin_count(b, 0u, np, cnt[0], box[0]);
    if (bins_place(b, 1u, cnt, box) > SC_BSCAN_MAX_REGION_REFS) {
        return 0;
    }
    bin_fill(b, 0u, np, cnt[0]);
    return 1;
}

/* The first tet of region r holding (x, z), a positively oriented one before an inverted one
 * (a fold's turned layer counts only where nothing else covers the point). */
static int32_t locate_region(line_w *w, const sc_mesh *m, uint32_t r, float x, float z)
{
    const sc_bscan *b = w->b;
    const float *bx = b->region_box[r];
    if (x < bx[0] || x > bx[1] || z < bx[2] || z > bx[3]) {
        return -1;
    }
    int32_t inverted = -1;
    for (uint32_t i = b->region_start[r]; i < b->region_start[r + 1u]; i++) {
        const uint32_t pi = b->region_refs[i];
        const sc_bscan_ptet *p = &b->ptets[pi];
        if (x < p->xmin || x > p->xmax || z < p->zmin || z > p->zmax) {
            continue;
        }
        const sc_bscan_tcache *tc = tet_cached(w, m, p->tet); /* not flat: add_plane_tet */
        int in = 1;
        for (uint32_t v = 0; v < 4u && in; v++) {
            in = tc->lam[0][v] + tc->lam[1][v] * x + tc->lam[2][v] * z >= -SC_BSCAN_LAMBDA_EPS;
        }
        if (in) {
            if (p->orient > 0) {
                return (int32_t)pi;
            }
            if (inverted < 0) {
                inverted = (int32_t)pi;
            }
        }
    }
    return inverted;
}

/* The tet of region r that holds (x, z) deepest (largest smallest barycentric coordinate), a
 * positively oriented one before an inverted one: the oracle's rule, for the walker's
 * relocation inside folds. */
static int32_t locate_deepest(line_w *w, const sc_mesh *m, uint32_t r, float x, float z)
{
    const sc_bscan *b = w->b;
    const float *bx = b->region_box[r];
    if (x < bx[0] || x > bx[1] || z < bx[2] || z > bx[3]) {
        return -1;
    }
    int32_t best = -1;
    int32_t best_orient = -2;
    float best_min = -SC_BSCAN_LAMBDA_EPS;
    for (uint32_t i = b->region_start[r]; i < b->region_start[r + 1u]; i++) {
        const uint32_t pi = b->region_refs[i];
        const sc_bscan_ptet *p = &b->ptets[pi];
        if (x < p->xmin || x > p->xmax || z < p->zmin || z > p->zmax) {
            continue;
        }
        const sc_bscan_tcache *tc = tet_cached(w, m, p->tet); /* not flat: add_plane_tet */
        float lmin = tc->lam[0][0] + tc->lam[1][0] * x + tc->lam[2][0] * z;
        for (uint32_t v = 1; v < 4u; v++) {
            const float l = tc->lam[0][v] + tc->lam[1][v] * x + tc->lam[2][v] * z;
            lmin = l < lmin ? l : lmin;
        }
        if (!(lmin >= -SC_BSCAN_LAMBDA_EPS)) {
            continue;
        }
        if (p->orient > best_orient || (p->orient == best_orient && lmin > best_min)) {
            best = (int32_t)pi;
            best_orient = p->orient;
            best_min = lmin;
        }
    }
    return best;
}

/* Rest positions of samples a..z (all in ptet ta), interpolated linearly between the ends. */
static void fill_run(line_w *w, const sc_mesh *m, const frame_ctx *c, uint32_t ta, uint32_t a,
                     uint32_t z)
{
    const sc_bscan_tcache *tc = tet_cached(w, m, w->b->ptets[ta].tet);
    float ra[3], rz[3], va[3], vz[3];
    const float xa = c->ox + (float)a * c->dx, za = c->oz + (float)a * c->dz;
    const float xz = c->ox + (float)z * c->dx, zz = c->oz + (float)z * c->dz;
    for (uint32_t d = 0; d < 3u; d++) {
        ra[d] = tc->rest[0][d] + tc->rest[1][d] * xa + tc->rest[2][d] * za;
        rz[d] = tc->rest[0][d] + tc->rest[1][d] * xz + tc->rest[2][d] * zz;
    }
    to_vox(c, ra, va);
    to_vox(c, rz, vz);
    /* linear interpolation between the ends: position(k) = va + (k - a) (vz - va) / (z - a) */
    const float inv = z > a ? 1.0f / (float)(z - a) : 0.0f;
    float v0[3], vd[3];
    for (uint32_t d = 0; d < 3u; d++) {
        vd[d] = (vz[d] - va[d]) * inv;
        v0[d] = va[d] - (float)a * vd[d];
    }
    emit_run(w, a, z + 1u, v0, vd);
}

static void map_line_regions(line_w *w, const sc_mesh *m, uint32_t l, const frame_ctx *c)
{
    sc_bscan *const b = w->b;
    const uint32_t r = region_of_line(l, b->def.scan.lines_n, b->def.regions_n);
    const float *bx = b->region_box[r];
    struct {
        uint32_t a, z;
        int32_t ta, tz;
    } st[64];
    uint32_t sp = 0;
    const uint32_t last = c->n - 1u;
    st[sp].a = 0u;
    st[sp].z = last;
    st[sp].ta = locate_region(w, m, r, c->ox, c->oz);
    st[sp].tz = locate_region(w, m, r, c->ox + (float)last * c->dx, c->oz + (float)last * c->dz);
    sp++;
    while (sp > 0u) {
        sp--;
        const uint32_t a = st[sp].a, z = st[sp].z;
        const int32_t ta = st[sp].ta, tz = st[sp].tz;
        if (ta >= 0 && ta == tz) {
            fill_run(w, m, c, (uint32_t)ta, a, z);
            continue;
        }
        if (z <= a + 1u) {
            if (ta >= 0) {
                fill_run(w, m, c, (uint32_t)ta, a, a);
            }
            if (tz >= 0 && z != a) {
                fill_run(w, m, c, (uint32_t)tz, z, z);
            }
            continue;
        }
        if (ta < 0 && tz < 0) {
            /* both ends outside: nothing between them can be inside if the segment misses the
             * box of all the region's tets (the line is straight) */
            const float x0 = c->ox + (float)a * c->dx, z0 = c->oz + (float)a * c->dz;
            const float x1 = c->ox + (float)z * c->dx, z1 = c->oz + (float)z * c->dz;
            if (fmaxf(x0, x1) < bx[0] || fminf(x0, x1) > bx[1] || fmaxf(z0, z1) < bx[2] ||
                fminf(z0, z1) > bx[3]) {
                continue;
            }
        }
        const uint32_t mid = a + (z - a + 1u) / 2u;
        const int32_t tm1 = locate_region(w, m, r, c->ox + (float)(mid - 1u) * c->dx,
                                          c->oz + (float)(mid - 1u) * c->dz);
        const int32_t tm =
            locate_region(w, m, r, c->ox + (float)mid * c->dx, c->oz + (float)mid * c->dz);
        SC_ASSERT(sp + 2u <= SC_COUNT_OF(st));
        st[sp].a = mid;
        st[sp].z = z;
        st[sp].ta = tm;
        st[sp].tz = tz;
        sp++;
        st[sp].a = a;
        st[sp].z = mid - 1u;
        st[sp].ta = ta;
        st[sp].tz = tm1;
        sp++;
    }
}

/* ---- oracle ------------------------------------------------------------------------------ */

/* Per pixel, in the volume frame with the deformed nodes as given: every tet is tried; the one
 * whose smallest barycentric coordinate is largest wins. Independent of the image-frame
 * node copy and of the walker. O(samples * tets). */
static void map_line_oracle(line_w *w, const sc_mesh *m, const sc_nodes *nd, uint32_t l,
                            const frame_ctx *c)
{
    sc_bscan *const b = w->b;
    float img[3], wp[3];
    for (uint32_t k = 0; k < c->n; k++) {
        sc_scan_geom_pixel(&b->geom, l, k, img);
        sc_xform_apply(&c->img2vol, img, wp);
        int32_t best = -1;
        int best_pos = 0; /* a positively oriented tet before an inverted one (sc_bscan.h) */
        float best_min = -SC_BSCAN_LAMBDA_EPS, best_l[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        for (uint32_t t = 0; t < m->tet_count; t++) {
            const uint32_t *tv = m->tet[t];
            float p[4][3];
            int out = 0;
            for (uint32_t v = 0; v < 4u; v++) {
                p[v][0] = nd->x[tv[v]];
                p[v][1] = nd->y[tv[v]];
                p[v][2] = nd->z[tv[v]];
            }
            for (uint32_t d = 0; d < 3u && !out; d++) {
                const float lo = fminf(fminf(p[0][d], p[1][d]), fminf(p[2][d], p[3][d]));
                const float hi = fmaxf(fmaxf(p[0][d], p[1][d]), fmaxf(p[2][d], p[3][d]));
                out = wp[d] < lo - 1e-3f || wp[d] > hi + 1e-3f;
            }
            if (out) {
                continue;
            }
            /* Cramer's rule on [p1-p0 p2-p0 p3-p0] lambda = w - p0 */
            float e[3][3], r[3];
            for (uint32_t d = 0; d < 3u; d++) {
                e[0][d] = p[1][d] - p[0][d];
                e[1][d] = p[2][d] - p[0][d];
                e[2][d] = p[3][d] - p[0][d];
                r[d] = wp[d] - p[0][d];
            }
#define SC_DET3_(a, bb, cc)                                                                        \
    ((a)[0] * ((bb)[1] * (cc)[2] - (bb)[2] * (cc)[1]) -                                            \
     (a)[1] * ((bb)[0] * (cc)[2] - (bb)[2] * (cc)[0]) +                                            \
     (a)[2] * ((bb)[0] * (cc)[1] - (bb)[1] * (cc)[0]))
            const float det = SC_DET3_(e[0], e[1], e[2]);
            if (!(fabsf(det) > 1e-12f)) {
                continue;
            }
            float lam[4];
            lam[1] = SC_DET3_(r, e[1], e[2]) / det;
            lam[2] = SC_DET3_(e[0], r, e[2]) / det;
            lam[3] = SC_DET3_(e[0], e[1], r) / det;
#undef SC_DET3_
            lam[0] = 1.0f - lam[1] - lam[2] - lam[3];
            const float lmin = fminf(fminf(lam[0], lam[1]), fminf(lam[2], lam[3]));
            const int pos = det > 0.0f;
            if (!(lmin >= -SC_BSCAN_LAMBDA_EPS)) {
                continue;
            }
            if ((pos && !best_pos) || (pos == best_pos && (best < 0 || lmin > best_min))) {
                best_pos = pos;
                best_min = lmin;
                best = (int32_t)t;
                for (uint32_t v = 0; v < 4u; v++) {
                    best_l[v] = lam[v];
                }
            }
        }
        if (best >= 0) {
            const uint32_t *tv = m->tet[best];
            float rp[3] = {0.0f, 0.0f, 0.0f}, v[3];
            for (uint32_t i = 0; i < 4u; i++) {
                rp[0] += best_l[i] * m->rest_x[tv[i]];
                rp[1] += best_l[i] * m->rest_y[tv[i]];
                rp[2] += best_l[i] * m->rest_z[tv[i]];
            }
            to_vox(c, rp, v);
            const float zero[3] = {0.0f, 0.0f, 0.0f};
            emit_run(w, k, k + 1u, v, zero);
        }
    }
}

/* ---- sampling, display processing, label areas -------------------------------------------- */


/* Samples of the rest reference above the face are taken every SC_BSCAN_MARGIN_STEP. */
#define SC_BSCAN_MARGIN_STEP 4u
_Static_assert(SC_BSCAN_MARGIN_STEP == 4u, "the margin block sums in sample_line assume 4");
_Static_assert(SC_LABEL_OUTSIDE < SC_LABEL_COUNT, "the margin counts the blocks outside too");
/* Blocks of the margin labelled per call of the margin kernel (a buffer on the stack). */
#define SC_BSCAN_MARGIN_CHUNK 64u

/* Nearest label at voxel-index position f, or SC_LABEL_OUTSIDE outside the grid. */
static uint8_t label_at(const sc_volume *v, float fx, float fy, float fz)
{
    const float hx = (float)v->dim[0] - 0.5f, hy = (float)v->dim[1] - 0.5f,
                hz = (float)v->dim[2] - 0.5f;
    if (!(fx >= -0.5f && fx < hx && fy >= -0.5f && fy < hy && fz >= -0.5f && fz < hz)) {
        return (uint8_t)SC_LABEL_OUTSIDE;
    }
    const uint32_t i = (uint32_t)(fx + 0.5f), j = (uint32_t)(fy + 0.5f), k = (uint32_t)(fz + 0.5f);
    return v->labels[(size_t)i + (size_t)v->dim[0] * ((size_t)j + (size_t)v->dim[1] * k)];
}

/* Add the runs of equal labels in lab[0..n) to the counts (labels come in long runs; this
 * keeps the per-pixel loop free of a read-modify-write chain). */
static void count_labels(const uint8_t *lab, uint32_t n, uint32_t *cnt, uint32_t *ksum)
{
    uint32_t k0 = 0;
    while (k0 < n) {
        const uint8_t l = lab[k0];
        uint32_t k1 = k0 + 1u;
        const uint64_t pat = (uint64_t)l * UINT64_C(0x0101010101010101);
        while (k1 + 8u <= n) { /* 8 labels at a time */
            uint64_t w;
            memcpy(&w, lab + k1, sizeof w);
            if (w != pat) {
                break;
            }
            k1 += 8u;
        }
        while (k1 < n && lab[k1] == l) {
            k1++;
        }
        if (l < SC_LABEL_COUNT) {
            cnt[l] += k1 - k0;
            ksum[l] += (k0 + k1 - 1u) * (k1 - k0) / 2u;
        }
        k0 = k1;
    }
}

typedef struct vol_ctx {
    const uint8_t *vox, *lab;
    float hi[3];            /* dim - 1/2: the volume's extent in voxel units is [-1/2, hi) */
    int64_t xmax[3];        /* largest 32.32 position kept: just below the last voxel centre */
    uint32_t sy32, sz32;    /* strides of y and z (a volume has < 2^32 voxels) */
    size_t stride[3];       /* 1, dim0, dim0 * dim1 */
    int64_t la;             /* display gain lut_a in 16.16 */
    float sp_mm[3];         /* voxel spacing */
    float slab[3];          /* voxels of the slab the continuation beyond a face repeats */
    float beyond_gl_per_mm; /* darkening beyond the volume, grey levels per mm */
    sc_bscan_span_fn span; /* the selected variant's sampler of spans clear of the border */
    sc_bscan_line_fn line; /* the selected variant's sampler of a whole line's positions */
    sc_bscan_words_fn words; /* the selected variant's position words of a clear span */
    sc_acoustics_run_fn acou_run; /* the selected variant's acoustics run kernel */
    sc_bscan_nearest_fn nearest;  /* the selected variant's rest labels of a clear mesh run */
    sc_bscan_margin_fn margin;    /* the selected variant's rest reference above the face */
} vol_ctx;

_Static_assert(SC_MAX_VOLUME_DIM < (1u << (32 - SC_W_BITS)), "position words fit 32 bits");

/* Positions are 32.32 fixed point (int64): stepping along a span adds exactly, the step's
 * rounding drifts by less than 1e-7 voxel over a line. */
#define SC_FX_ONE 4294967296.0f

/* v * 2^32 is exact in float (a power of two) and |v| < 2^31 here: the conversion keeps
 * every bit of v (truncation only below 2^-32). */
static int64_t to_fx32(float v)
{
    return (int64_t)(v * SC_FX_ONE);
}

/* One sample: sc_bscan_sample_fx (sc_bscan_kern.h, shared with the span kernels). */
#define sample_fx sc_bscan_sample_fx

static int64_t clamp_fx(int64_t x, int64_t hi)
{
    return x < 0 ? 0 : (x > hi ? hi : x);
}

static int in_volume(const vol_ctx *vc, const float p[3])
{
    return p[0] >= -0.5f && p[0] < vc->hi[0] && p[1] >= -0.5f && p[1] < vc->hi[1] &&
           p[2] >= -0.5f && p[2] < vc->hi[2];
}

/* Voxel coordinate p folded back into the grid: beyond a face it goes back and forth across
 * the slab of `slab` voxels next to that face (mirrored at the face and at the slab's inner
 * side), so the tissue along the face continues and nothing farther inside (a vessel, a bone's
 * cortex) is mirrored out; with mirror 0 only clamped (above the skin: the top face, air, is not
 * folded into tissue). Clamped to the voxel centres. Returns how far outside p was, in voxels
 * (0 inside). */
static float fold_axis(float p, float dim, float slab, int mirror, float *out)
{
    const float lo = -0.5f, hi = dim - 0.5f;
    float q = p;
    float outside = 0.0f;
    if (p < lo || p >= hi) {
        outside = p < lo ? lo - p : p - hi;
        /* outside mod 2 slab (outside >= 0), without the libm call */
        const float period = 2.0f * slab;
        float q_n = outside / period;
        q_n = q_n < 1e7f ? q_n : 1e7f; /* far outside: any fold is as good */
        float m = outside - period * (float)(int32_t)q_n;
        m = m < slab ? m : 2.0f * slab - m;
        q = p < lo ? (mirror ? lo + m : 0.0f) : hi - m;
    }
    *out = q < 0.0f ? 0.0f : (q > dim - 1.0f ? dim - 1.0f : q);
    return outside;
}

/* A sample beyond the case volume: the tissue continues as the slab along the face it left by,
 * mirrored back and forth (fold_axis), darkened by vc->beyond_gl_per_mm per mm outside (a
 * real probe shows tissue there, not a black "no data" band). Above the top face (z is depth,
 * sc_volume.h) the top voxels are repeated, not mirrored: the gel or air there stays dark. Its
 * label is SC_LABEL_OUTSIDE: the compression measure counts only the case's own tissue. */
static void beyond_sample(const vol_ctx *vc, const vol_regs vr, const int64_t *restrict lut,
                          uint32_t k, const float p[3], uint8_t *restrict out,
                          uint8_t *restrict lab)
{
    float q[3], d2_mm2 = 0.0f;
    for (uint32_t d = 0; d < 3u; d++) {
        const float o =
            fold_axis(p[d], vc->hi[d] + 0.5f, vc->slab[d], d != 2u, &q[d]) * vc->sp_mm[d];
        d2_mm2 += o * o;
    }
    /* the voxel straight across the face first: bone there (and its shadow) continues as
     * itself, and so does a bone the slab would fold into a zigzag */
    const int64_t sx = clamp_fx(to_fx32(p[0]), vc->xmax[0]),
                  sy = clamp_fx(to_fx32(p[1]), vc->xmax[1]),
                  sz = clamp_fx(to_fx32(p[2]), vc->xmax[2]);
    sample_fx(vr, lut, k, sx, sy, sz, out, lab);
    if (lab[k] != (uint8_t)SC_LABEL_BONE) {
        sample_fx(vr, lut, k, clamp_fx(to_fx32(q[0]), vc->xmax[0]),
                  clamp_fx(to_fx32(q[1]), vc->xmax[1]), clamp_fx(to_fx32(q[2]), vc->xmax[2]), out,
                  lab);
        if (lab[k] == (uint8_t)SC_LABEL_BONE) {
            sample_fx(vr, lut, k, sx, sy, sz, out, lab);
        }
    }
    const float v = (float)out[k] - vc->beyond_gl_per_mm * sqrtf(d2_mm2);
    out[k] = (uint8_t)(v > 0.0f ? v + 0.5f : 0.0f);
    lab[k] = (uint8_t)SC_LABEL_OUTSIDE;
}

/* Samples [k0, k1) at voxel positions a + k b, all inside the volume box (the ends are, and the
 * box is convex). */
/* Steps j of [0, n) whose position x + j d lies in [0, xm] (an interval: the position is
 * monotonic in j): [*lo, *hi), empty as lo >= hi. Exact integer arithmetic. */
static void clear_steps(int64_t x, int64_t d, int64_t xm, int64_t n, int64_t *lo, int64_t *hi)
{
    int64_t a = 0, z = n;
    if (d == 0) {
        if (x < 0 || x > xm) {
            z = 0;
        }
    } else if (d > 0) {
        if (x < 0) {
            a = (-x + d - 1) / d; /* ceil */
        }
        z = x > xm ? 0 : (xm - x) / d + 1;
    } else {
        const int64_t e = -d;
        z = x < 0 ? 0 : x / e + 1;
        if (x > xm) {
            a = (x - xm + e - 1) / e;
        }
    }
    *lo = a > *lo ? a : *lo;
    *hi = z < *hi ? z : *hi;
}

/* What sample_span and sample_span_inside do: everything; only the position words of the part
 * clear of the border (for the line sampler, the rest of the words 0); or everything but that
 * part (after the line sampler). The same intervals are computed in each mode. */
typedef enum span_mode { SPAN_ALL = 0, SPAN_WORDS = 1, SPAN_REST = 2 } span_mode;


/* Samples [k0, k1) at voxel positions a + k b, all inside the volume box (the ends are, and the
 * box is convex). The part clear of the half-voxel border (no clamping: an interval) goes to the
 * selected span kernel, the ends clamped sample by sample: the same values either way. */
static void sample_span_inside(line_w *w, const vol_ctx *vc, uint32_t k0, uint32_t k1,
                               const float a[3], const float bb[3], span_mode mode)
{
    sc_bscan *const b = w->b;
    const vol_regs vr = {vc->vox, vc->lab, vc->stride[1], vc->stride[2], vc->la};
    const int64_t *restrict lut = b->lut_b_fx;
    const int64_t xm0 = vc->xmax[0], xm1 = vc->xmax[1], xm2 = vc->xmax[2];
    uint8_t *restrict out = w->out;
    uint8_t *restrict lab = w->label;
    int64_t X = to_fx32(a[0] + (float)k0 * bb[0]), Y = to_fx32(a[1] + (float)k0 * bb[1]),
            Z = to_fx32(a[2] + (float)k0 * bb[2]);
    const int64_t DX = to_fx32(bb[0]), DY = to_fx32(bb[1]), DZ = to_fx32(bb[2]);
    const int64_t n = (int64_t)(k1 - k0);
    int64_t jlo = 0, jhi = n;
    clear_steps(X, DX, xm0, n, &jlo, &jhi);
    clear_steps(Y, DY, xm1, n, &jlo, &jhi);
    clear_steps(Z, DZ, xm2, n, &jlo, &jhi);
    if (jlo >= jhi) {
        jlo = jhi = n; /* nowhere clear: all clamped */
    }
    for (int64_t j = 0; j < n; j++) {
        if (j == jlo) {
            /* clear of the half-voxel border: no clamping */
            if (mode == SPAN_ALL) {
                vc->span(vr, lut, k0 + (uint32_t)jlo, k0 + (uint32_t)jhi, X, Y, Z, DX, DY, DZ,
                         out, lab);
            } else if (mode == SPAN_WORDS) {
                /* the selected variant writes up to 7 words past the clear part: the span's
                 * clamped samples after it need theirs 0 again (the next span writes its own) */
                const uint32_t w1 = k0 + (uint32_t)jhi;
                vc->words(w->pos_h[0], w->pos_h[1], w->pos_h[2], k0 + (uint32_t)jlo, w1, X, Y, Z,
                          DX, DY, DZ);
                for (uint32_t k = w1; k < k1 && k < w1 + 7u; k++) {
                    w->pos_h[0][k] = 0u;
                    w->pos_h[1][k] = 0u;
                    w->pos_h[2][k] = 0u;
                }
            }
            const int64_t m = jhi - jlo;
            X += m * DX;
            Y += m * DY;
            Z += m * DZ;
            j = jhi - 1;
            continue;
        }
        if (mode != SPAN_WORDS) {
            sample_fx(vr, lut, k0 + (uint32_t)j, clamp_fx(X, xm0), clamp_fx(Y, xm1),
                      clamp_fx(Z, xm2), out, lab);
        }
        X += DX;
        Y += DY;
        Z += DZ;
    }
}

static int in_volume_k(const vol_ctx *vc, const float a[3], const float bb[3], uint32_t k)
{
    const float p[3] = {a[0] + (float)k * bb[0], a[1] + (float)k * bb[1], a[2] + (float)k * bb[2]};
    return in_volume(vc, p);
}


/* Samples [k0, k1) at voxel positions a + k b: the part inside the volume box (an interval: the
 * line is straight, the box convex; its ends found from the slab intersection and confirmed by
 * the per-sample test) in fixed point, the parts beyond it continued (beyond_sample). */
static int sample_span(line_w *w, const vol_ctx *vc, uint32_t k0, uint32_t k1, const float a[3],
                       const float bb[3], span_mode mode)
{
    sc_bscan *const b = w->b;
    {
        /* the common case first (a mesh run is one tet's crossing, a few samples): both ends
         * clear of the half-voxel border, so every sample is, and the per-sample box test below
         * would find the whole span inside (the fixed-point positions differ from the float ones
         * by < 1e-4 voxel, the box is wider by half a voxel): straight to the span kernel, with
         * the positions sample_span_inside would step */
        const int64_t X = to_fx32(a[0] + (float)k0 * bb[0]), Y = to_fx32(a[1] + (float)k0 * bb[1]),
                      Z = to_fx32(a[2] + (float)k0 * bb[2]);
        const int64_t DX = to_fx32(bb[0]), DY = to_fx32(bb[1]), DZ = to_fx32(bb[2]);
        const int64_t j1 = (int64_t)(k1 - 1u - k0);
        const int64_t xe = X + j1 * DX, ye = Y + j1 * DY, ze = Z + j1 * DZ;
        if (k1 > k0 && X >= 0 && xe >= 0 && Y >= 0 && ye >= 0 && Z >= 0 && ze >= 0 &&
            X <= vc->xmax[0] && xe <= vc->xmax[0] && Y <= vc->xmax[1] && ye <= vc->xmax[1] &&
            Z <= vc->xmax[2] && ze <= vc->xmax[2]) {
            const vol_regs vr = {vc->vox, vc->lab, vc->stride[1], vc->stride[2], vc->la};
            if (mode == SPAN_ALL) {
                vc->span(vr, b->lut_b_fx, k0, k1, X, Y, Z, DX, DY, DZ, w->out,
                         w->label);
            } else if (mode == SPAN_WORDS) {
                /* (may write up to 7 words past k1: the next span writes its own after) */
                vc->words(w->pos_h[0], w->pos_h[1], w->pos_h[2], k0, k1, X, Y, Z, DX, DY, DZ);
            }
            return 1;
        }
    }
    if (mode == SPAN_WORDS) {
        /* the line sampler reads every word: the samples of this span that sample_span_inside
         * does not give words (clamped ends, beyond the volume) read voxel 0 until SPAN_REST
         * redoes them (a clear span above writes all of its own words) */
        for (uint32_t k = k0; k < k1; k++) {
            w->pos_h[0][k] = 0u;
            w->pos_h[1][k] = 0u;
            w->pos_h[2][k] = 0u;
        }
    }
    /* the line parameter range inside the box, per axis: -1/2 <= a + k b < hi */
    float lo = (float)k0, hi = (float)k1;
    for (uint32_t d = 0; d < 3u && lo < hi; d++) {
        if (bb[d] > 0.0f || bb[d] < 0.0f) {
            const float t0 = (-0.5f - a[d]) / bb[d], t1 = (vc->hi[d] - a[d]) / bb[d];
            const float tl = t0 < t1 ? t0 : t1, th = t0 < t1 ? t1 : t0; /* no libm calls */
            lo = tl > lo ? tl : lo;
            hi = th < hi ? th : hi;
        } else if (!(a[d] >= -0.5f && a[d] < vc->hi[d])) {
            hi = lo; /* parallel to the faces of this axis and outside them */
        }
    }
    uint32_t ka = k1, kb = k1;
    if (lo < hi) {
        ka = first_k(lo, k1);
        ka = ka < k0 ? k0 : ka;
        kb = first_k(hi, k1);
        kb = kb < ka ? ka : kb;
        /* the ends as the per-sample test sees them (a rounding either way) */
        while (ka > k0 && in_volume_k(vc, a, bb, ka - 1u)) {
            ka--;
        }
        while (ka < kb && !in_volume_k(vc, a, bb, ka)) {
            ka++;
        }
        while (kb < k1 && kb > ka && in_volume_k(vc, a, bb, kb)) {
            kb++;
        }
        while (kb > ka && !in_volume_k(vc, a, bb, kb - 1u)) {
            kb--;
        }
        if (ka == kb) {
            ka = kb = k1;
        }
    }
    const vol_regs vr = {vc->vox, vc->lab, vc->stride[1], vc->stride[2], vc->la};
    for (uint32_t k = k0; k < k1; k++) {
        if (k == ka) {
            sample_span_inside(w, vc, ka, kb, a, bb, mode);
            k = kb - 1u;
            continue;
        }
        const float p[3] = {a[0] + (float)k * bb[0], a[1] + (float)k * bb[1],
                            a[2] + (float)k * bb[2]};
        if (mode != SPAN_WORDS) {
            beyond_sample(vc, vr, b->lut_b_fx, k, p, w->out, w->label);
        }
    }
    if (mode == SPAN_WORDS) {
        /* the words kernel of sample_span_inside may have written up to 7 words past kb, over
         * this span's samples beyond the volume zeroed above: they read voxel 0 again (else the
         * line sampler gathers from a position off the volume: a fault at a 64x32x32 rock) */
        for (uint32_t k = kb; k < k1 && k < kb + 7u; k++) {
            w->pos_h[0][k] = 0u;
            w->pos_h[1][k] = 0u;
            w->pos_h[2][k] = 0u;
        }
    }
    return 0;
}

/* The labels of the rigid slice (the compression measure's rest reference) at the samples of the
 * mesh runs, in place of their deformed labels. Every loop-invariant in a local: the label
 * stores (uint8_t) may alias anything, so the compiler would reload them after each store. */
static void rest_labels(line_w *w, const vol_ctx *vc, const sc_volume *v, const frame_ctx *c)
{
    uint8_t *restrict out = w->rest;
    const uint8_t *restrict lab = vc->lab;
    const size_t sy = vc->stride[1], sz = vc->stride[2];
    const float f0[3] = {c->f0[0], c->f0[1], c->f0[2]}, fd[3] = {c->fd[0], c->fd[1], c->fd[2]};
    const float hx = vc->hi[0], hy = vc->hi[1], hz = vc->hi[2];
    const int64_t DX = to_fx32(fd[0]), DY = to_fx32(fd[1]), DZ = to_fx32(fd[2]);
    const int64_t lx = (int64_t)v->dim[0] - 1, ly = (int64_t)v->dim[1] - 1,
                  lz = (int64_t)v->dim[2] - 1;
    const uint32_t runs = w->run_count;
    const sc_bscan_run *restrict rs = w->runs;
    for (uint32_t i = 0; i < runs; i++) {
        /* a run is one tet crossed (about 13 samples) but the rest labels do not depend on the
         * tet: consecutive runs that touch are labelled as one, positions stepped from the
         * first one's start (a deliberate change: before, each run's start was rounded on its
         * own; a label can differ only where a position lies within about 1e-4 voxel of a
         * voxel's boundary) */
        const uint32_t k0 = rs[i].k0;
        uint32_t k1 = rs[i].k1;
        while (i + 1u < runs && rs[i + 1u].k0 == k1) {
            k1 = rs[++i].k1;
        }
        float p0[3], p1[3];
        for (uint32_t d = 0; d < 3u; d++) {
            p0[d] = f0[d] + (float)k0 * fd[d];
            p1[d] = f0[d] + (float)(k1 - 1u) * fd[d];
        }
        /* in_volume of both ends */
        if (p0[0] >= -0.5f && p0[0] < hx && p0[1] >= -0.5f && p0[1] < hy && p0[2] >= -0.5f &&
            p0[2] < hz && p1[0] >= -0.5f && p1[0] < hx && p1[1] >= -0.5f && p1[1] < hy &&
            p1[2] >= -0.5f && p1[2] < hz) {
            /* nearest voxel: 16.16 positions offset by a half */
            int64_t X = to_fx32(p0[0] + 0.5f), Y = to_fx32(p0[1] + 0.5f), Z = to_fx32(p0[2] + 0.5f);
            const int64_t m1 = (int64_t)(k1 - 1u - k0);
            const int64_t xe = X + m1 * DX, ye = Y + m1 * DY, ze = Z + m1 * DZ;
            if (X >= 0 && xe >= 0 && Y >= 0 && ye >= 0 && Z >= 0 && ze >= 0 &&
                (X >> 32) <= lx && (xe >> 32) <= lx && (Y >> 32) <= ly && (ye >> 32) <= ly &&
                (Z >> 32) <= lz && (ze >> 32) <= lz) {
                /* both ends clear of the clamps, so every position between them is (they are
                 * linear in kk): the loop below without them, the same labels */
                vc->nearest(lab, sy, sz, out + k0, k1 - k0, X, Y, Z, DX, DY, DZ);
                continue;
            }
            for (uint32_t kk = k0; kk < k1; kk++) {
                int64_t ix = X < 0 ? 0 : X >> 32, iy = Y < 0 ? 0 : Y >> 32,
                        iz = Z < 0 ? 0 : Z >> 32;
                ix = ix > lx ? lx : ix;
                iy = iy > ly ? ly : iy;
                iz = iz > lz ? lz : iz;
                out[kk] = lab[(size_t)ix + sy * (size_t)iy + sz * (size_t)iz];
                X += DX;
                Y += DY;
                Z += DZ;
            }
            continue;
        }
        for (uint32_t kk = k0; kk < k1; kk++) {
            const float t = (float)kk;
            out[kk] = label_at(v, f0[0] + t * fd[0], f0[1] + t * fd[1], f0[2] + t * fd[2]);
        }
    }
}

static int emit_line(sc_bscan *b, const sc_display_dev *disp, uint32_t frame_no, uint32_t l,
                     const uint8_t *out, int rc);

#if SC_BSCAN_PSF
/* The speckle pass's input (sc_psf.h): the line's rest positions, span by span, and its grey. */
static void psf_line_in(line_w *w, const frame_ctx *c)
{
    sc_bscan *const b = w->b;
    uint32_t k = 0;
    for (uint32_t i = 0; i < w->run_count; i++) {
        const sc_bscan_run *r = &w->runs[i];
        if (k < r->k0) {
            sc_psf_span(&b->psf, k, r->k0, c->f0, c->fd);
        }
        sc_psf_span(&b->psf, r->k0, r->k1, r->a, r->b);
        k = r->k1;
    }
    sc_psf_span(&b->psf, k, c->n, c->f0, c->fd);
    sc_psf_line_in(&b->psf, c->line, w->out);
}

/* After line l: hand the hook's drawing over, emit the lines whose neighbours are all in. */
static int psf_emit(sc_bscan *b, const sc_display_dev *disp, uint32_t frame_no, uint32_t l,
                    uint32_t *next_out, int rc)
{
    sc_psf_line_hooked(&b->psf, l, b->line_out);
    int32_t m;
    while ((m = sc_psf_line_ready(&b->psf, l, *next_out)) >= 0) {
        sc_psf_line_out(&b->psf, (uint32_t)m, b->line_out);
        rc = emit_line(b, disp, frame_no, (uint32_t)m, b->line_out, rc);
        (*next_out)++;
    }
    return rc;
}
#endif

/* The whole line: mesh runs at their rest positions, the gaps rigid; then label areas. */
static void sample_line(line_w *w, const vol_ctx *vc, const sc_volume *v, const frame_ctx *c,
                        sc_bscan_area_acc *acc, int margin_known)
{
    sc_bscan *const b = w->b;
    const uint32_t n = c->n;
    /* the position words of every span's part clear of the volume's border (nearly every
     * sample), one call of the line sampler for them all, then the rest of the spans (clamped
     * ends, beyond the volume) sample by sample: the same intervals, positions and bytes as
     * sample_span alone (SPAN_ALL) */
    /* spans in line order: the rigid gap before run i is span 2 i, run i span 2 i + 1, the
     * gap after the last run span 2 run_count; those between first and last need the rest */
    uint32_t k = 0, first = UINT32_MAX, last = 0;
    for (uint32_t i = 0; i < w->run_count; i++) {
        const sc_bscan_run *r = &w->runs[i];
        if (k < r->k0 && !sample_span(w, vc, k, r->k0, c->f0, c->fd, SPAN_WORDS)) {
            first = first < 2u * i ? first : 2u * i;
            last = 2u * i;
        }
        if (!sample_span(w, vc, r->k0, r->k1, r->a, r->b, SPAN_WORDS)) {
            first = first < 2u * i + 1u ? first : 2u * i + 1u;
            last = 2u * i + 1u;
        }
        k = r->k1;
    }
    if (k < n && !sample_span(w, vc, k, n, c->f0, c->fd, SPAN_WORDS)) {
        first = first < 2u * w->run_count ? first : 2u * w->run_count;
        last = 2u * w->run_count;
    }
#ifdef SC_ENABLE_VALIDATE
    /* every word the line sampler gathers at is a position in the volume (or voxel 0) */
    for (uint32_t a = 0; a < 3u; a++) {
        const uint32_t wmax = (uint32_t)((uint64_t)(vc->xmax[a] + SC_W_HALF) >> SC_POS_SHIFT);
        for (uint32_t kk = 0; kk < n; kk++) {
            SC_VALIDATE(w->pos_h[a][kk] <= wmax);
        }
    }
#endif
    {
        const vol_regs vr = {vc->vox, vc->lab, vc->stride[1], vc->stride[2], vc->la};
        vc->line(vr, b->lut_b_fx, n, w->pos_h[0], w->pos_h[1], w->pos_h[2], w->out,
                 w->label);
    }
    if (first != UINT32_MAX) {
        const uint32_t i0 = first / 2u;
        k = i0 > 0u ? w->runs[i0 - 1u].k1 : 0u;
        for (uint32_t i = i0; i < w->run_count && 2u * i <= last; i++) {
            const sc_bscan_run *r = &w->runs[i];
            if (k < r->k0 && 2u * i >= first) {
                (void)sample_span(w, vc, k, r->k0, c->f0, c->fd, SPAN_REST);
            }
            if (2u * i + 1u >= first && 2u * i + 1u <= last) {
                (void)sample_span(w, vc, r->k0, r->k1, r->a, r->b, SPAN_REST);
            }
            k = r->k1;
        }
        if (k < n && last == 2u * w->run_count) {
            (void)sample_span(w, vc, k, n, c->f0, c->fd, SPAN_REST);
        }
    }
    if (b->def.acoustics != 0u) {
        /* along the beam as it runs now: the labels are this frame's (deformed) ones */
        sc_acoustics_line_k(&b->acou, w->label, w->out, n, vc->acou_run);
    }
#if SC_BSCAN_PSF
    if (b->def.psf != 0u) {
        SC_ASSERT(w->serial); /* the pool path is not taken with it */
        psf_line_in(w, c);
    }
#endif
    if (b->line_hook != NULL && w->serial) { /* the pool path calls it as the line leaves */
        /* the labels are still this frame's (deformed) ones here */
        const sc_bscan_line_view lv = {
            .line = c->line, .lines_n = b->def.scan.lines_n, .samples_n = n,
            .labels = w->label, .runs = w->runs, .run_count = w->run_count,
            .f0 = {c->f0[0], c->f0[1], c->f0[2]}, .fd = {c->fd[0], c->fd[1], c->fd[2]},
            .org_x = c->ox, .org_z = c->oz, .dir_x = c->dx, .dir_z = c->dz, .out = w->out,
            .img2vol = &c->img2vol};
        b->line_hook(b->line_hook_ctx, &lv);
    }
    if (vc->lab == NULL) {
        return;
    }
    count_labels(w->label, n, acc->now_n, acc->now_k);
    /* rest areas: the rigid slice's labels; outside the mesh identical to the above */
    if (w->rest != w->label) {
        memcpy(w->rest, w->label, n); /* the deformed labels stay for the hook (pool path) */
    }
    rest_labels(w, vc, v, c);
    count_labels(w->rest, n, acc->rest_n, acc->rest_k);
    /* the rest reference continues above the face by the margin: tissue the probe has pushed
     * into the image was there at rest (every 4th sample, each counting for 4) */
    /* blocks of 4 samples above the face, -(4i + 1) .. -(4i + 4), each sampled at -(4i + 2);
     * the counts of a run of one label summed in registers and added at its end (labels come
     * in runs: the counter in memory, read and written back per block, was a chain through the
     * store forwarding; integers: the same sums) */
    /* the blocks' labels come from the selected variant (the same positions, tests and
     * rounding as label_at), a chunk at a time */
    if (margin_known) {
        return; /* the same pose and volume as the last frame: its counts (sc_bscan_frame) */
    }
    uint32_t run_label = SC_LABEL_COUNT, run_n = 0;
    int32_t run_k = 0;
    const uint32_t blocks = c->margin_n / SC_BSCAN_MARGIN_STEP;
    /* the blocks far outside the volume (above the skin, most of them under a pressed face)
     * are SC_LABEL_OUTSIDE: their counts in closed form (the sums are the same grouped any
     * way), the blocks near or inside through the kernel */
    uint32_t near_lo = 0, near_hi = 0;
    sc_bscan_margin_near(v->dim, c->f0, c->fd, blocks, &near_lo, &near_hi);
    {
        /* blocks [0, near_lo) and [near_hi, blocks): n 4 each, k -(16 i + 10) each */
        const uint32_t far_n = near_lo + (blocks - near_hi);
        const uint32_t far_i = near_lo * (near_lo - 1u) / 2u + /* (0 for none: unsigned) */
                               (blocks - near_hi) * (near_hi + blocks - 1u) / 2u;
        acc->margin_n[SC_LABEL_OUTSIDE] += SC_BSCAN_MARGIN_STEP * far_n;
        acc->margin_k[SC_LABEL_OUTSIDE] -= (int32_t)(16u * far_i + 10u * far_n);
    }
    uint8_t mlab[SC_BSCAN_MARGIN_CHUNK];
    for (uint32_t b0 = near_lo; b0 < near_hi; b0 += SC_BSCAN_MARGIN_CHUNK) {
        const uint32_t nb =
            near_hi - b0 < SC_BSCAN_MARGIN_CHUNK ? near_hi - b0 : SC_BSCAN_MARGIN_CHUNK;
        vc->margin(vc->lab, v->dim, c->f0, c->fd, b0 * SC_BSCAN_MARGIN_STEP, nb, mlab);
        for (uint32_t i = 0; i < nb; i++) {
            const uint32_t j0 = (b0 + i) * SC_BSCAN_MARGIN_STEP;
            const uint8_t label = mlab[i];
            if (label != run_label) {
                if (run_label < SC_LABEL_COUNT) {
                    acc->margin_n[run_label] += run_n;
                    acc->margin_k[run_label] += run_k;
                }
                run_label = label;
                run_n = 0u;
                run_k = 0;
            }
            run_n += SC_BSCAN_MARGIN_STEP;
            run_k -= (int32_t)(4u * j0 + 10u); /* sum of the block's indices */
        }
    }
    if (run_label < SC_LABEL_COUNT) {
        acc->margin_n[run_label] += run_n;
        acc->margin_k[run_label] += run_k;
    }
}

/* ---- lines: one after the other, or in ranges on the worker pool ------------------------ */

typedef struct frame_args {
    sc_bscan *b;
    const sc_mesh *mesh;
    const sc_nodes *nodes;
    const sc_volume *volume;
    const vol_ctx *vc;
    frame_ctx c; /* the frame's part */
    uint32_t mapper;
    int margin_known;
    const sc_display_dev *display;
    uint32_t frame_no;
} frame_args;

/* Line l's origin and direction, in the image frame and in voxel units, into c. */
static void line_setup(const sc_bscan *b, frame_ctx *c, uint32_t l)
{
    c->line = l;
    c->ox = b->geom.start_x_mm[l];
    c->oz = b->geom.start_z_mm[l];
    c->dx = b->geom.step_x_mm[l];
    c->dz = b->geom.step_z_mm[l];
    const float o_img[3] = {c->ox, 0.0f, c->oz}, d_img[3] = {c->dx, 0.0f, c->dz};
    float w0[3], wd[3];
    sc_xform_apply(&c->img2vol, o_img, w0);
    sc_xform_rotate(&c->img2vol, d_img, wd);
    to_vox(c, w0, c->f0);
    for (uint32_t d = 0; d < 3u; d++) {
        c->fd[d] = wd[d] * c->inv_sp[d];
    }
}

/* The mesh runs of line l (none without a mesh). */
static void map_line(line_w *w, const frame_args *fa, uint32_t l, const frame_ctx *c)
{
    w->run_count = 0u;
    if (fa->mesh == NULL) {
        return;
    }
    switch (fa->mapper) {
    case SC_BSCAN_MAP_WALK:
        map_line_walk(w, fa->mesh, l, c);
        break;
    case SC_BSCAN_MAP_REGIONS:
        map_line_regions(w, fa->mesh, l, c);
        break;
    case SC_BSCAN_MAP_ORACLE:
        map_line_oracle(w, fa->mesh, fa->nodes, l, c);
        break;
    default:
        SC_ASSERT(0);
        break;
    }
    for (uint32_t i = 0; i < w->run_count; i++) {
        w->cnt->pixels_in_mesh += (uint32_t)w->runs[i].k1 - w->runs[i].k0;
    }
}

/* The sc_bscan's own scratch, for lines run on the caller alone. */
static line_w serial_w(sc_bscan *b, sc_bscan_counts *cnt, uint32_t *regions_need)
{
    const line_w w = {.b = b,
                      .runs = b->runs,
                      .label = b->line_label,
                      .rest = b->line_label,
                      .out = b->line_out,
                      .pos_h = b->pos_h,
                      .events = b->events,
                      .active = b->active,
                      .active_cap = SC_BSCAN_MAX_HULL_FACES,
                      .tcache = b->tcache,
                      .tmask = SC_BSCAN_TET_CACHE - 1u,
                      .cnt = cnt,
                      .regions_need = regions_need,
                      .serial = 1};
    return w;
}

/* Lines [l0, l1) on the caller, each leaving as soon as it is computed. */
static int lines_serial(line_w *w, const frame_args *fa, uint32_t l0, uint32_t l1,
                        sc_bscan_area_acc *acc, int rc, uint32_t *psf_next)
{
    sc_bscan *b = fa->b;
    frame_ctx c = fa->c;
    (void)psf_next;
    if (fa->mesh != NULL && fa->mapper == SC_BSCAN_MAP_WALK) {
        (void)active_at(w, l0); /* every segment fits the sc_bscan's own list */
    }
    for (uint32_t l = l0; l < l1; l++) {
        line_setup(b, &c, l);
        map_line(w, fa, l, &c);
        SC_ASSERT(!w->stop);
        sample_line(w, fa->vc, fa->volume, &c, acc, fa->margin_known);
#if SC_BSCAN_PSF
        if (b->def.psf != 0u) {
            rc = psf_emit(b, fa->display, fa->frame_no, l, psf_next, rc);
            continue;
        }
#endif
        rc = emit_line(b, fa->display, fa->frame_no, l, w->out, rc);
    }
    return rc;
}

#if SC_BSCAN_RANGES > 1
/* The walker's tet cache slice of a range: SC_BSCAN_TET_CACHE / SC_BSCAN_RANGES entries,
 * rounded down to a power of two (a hit or a miss gives the same values). */
static uint32_t range_tcache_n(void)
{
    uint32_t n = 1u;
    while (n * 2u <= SC_BSCAN_TET_CACHE / SC_BSCAN_RANGES) {
        n *= 2u;
    }
    return n;
}

/* One range of lines on a worker: mapped and sampled into its own scratch, the displayed
 * samples and labels into the frame's rows, the runs kept while a line hook needs them. A line
 * that needs what only the caller may do (the region bins not built, the range's active list
 * or runs full) stops the range there: done_to says how far it got, its counters are those of
 * the lines before it. */
static void range_job(void *arg, uint32_t r)
{
    const frame_args *fa = arg;
    sc_bscan *b = fa->b;
    sc_bscan_range *rg = &b->range[r];
    const uint32_t n = fa->c.n, tn = range_tcache_n();
    memset(&rg->counts, 0, sizeof rg->counts);
    memset(&rg->acc, 0, sizeof rg->acc);
    rg->regions_need = 0u;
    rg->run_used = 0u;
    rg->done_to = rg->l0;
    rg->stopped = 0u;
    line_w w = {.b = b,
                .rest = rg->rest_label,
                .pos_h = rg->pos_h,
                .events = rg->events,
                .active = rg->active,
                .active_cap = SC_BSCAN_RANGE_ACTIVE,
                .tcache = &b->tcache[r * tn],
                .tmask = tn - 1u,
                .cnt = &rg->counts,
                .regions_need = &rg->regions_need,
                .serial = 0};
    if (fa->mesh != NULL && fa->mapper == SC_BSCAN_MAP_WALK && !active_at(&w, rg->l0)) {
        rg->stopped = 1u;
        return;
    }
    frame_ctx c = fa->c;
    for (uint32_t l = rg->l0; l < rg->l1; l++) {
        if (b->line_hook == NULL) {
            rg->run_used = 0u; /* nobody reads a line's runs after it */
        }
        if (rg->run_used + n > SC_BSCAN_RANGE_RUNS) {
            rg->stopped = 1u;
            return;
        }
        w.runs = &rg->runs[rg->run_used];
        w.out = &b->frame_out[(size_t)l * n];
        w.label = &b->frame_label[(size_t)l * n];
        const sc_bscan_counts before = rg->counts;
        line_setup(b, &c, l);
        map_line(&w, fa, l, &c);
        if (w.stop) {
            rg->counts = before;
            rg->stopped = 1u;
            return;
        }
        sample_line(&w, fa->vc, fa->volume, &c, &rg->acc, fa->margin_known);
        b->line_run0[l] = (uint16_t)rg->run_used;
        b->line_runs[l] = (uint16_t)w.run_count;
        rg->run_used += w.run_count;
        rg->done_to = l + 1u;
    }
}

/* A stored line leaves: the hook (in line order, as on the serial path) and the display. */
static int emit_stored(const frame_args *fa, const sc_bscan_range *rg, uint32_t l, int rc)
{
    sc_bscan *b = fa->b;
    const uint32_t n = fa->c.n;
    uint8_t *out = &b->frame_out[(size_t)l * n];
    if (b->line_hook != NULL) {
        frame_ctx c = fa->c;
        line_setup(b, &c, l);
        const sc_bscan_line_view lv = {
            .line = l, .lines_n = b->def.scan.lines_n, .samples_n = n,
            .labels = &b->frame_label[(size_t)l * n], .runs = &rg->runs[b->line_run0[l]],
            .run_count = b->line_runs[l],
            .f0 = {c.f0[0], c.f0[1], c.f0[2]}, .fd = {c.fd[0], c.fd[1], c.fd[2]},
            .org_x = c.ox, .org_z = c.oz, .dir_x = c.dx, .dir_z = c.dz, .out = out,
            .img2vol = &fa->c.img2vol};
        b->line_hook(b->line_hook_ctx, &lv);
    }
    return emit_line(b, fa->display, fa->frame_no, l, out, rc);
}

static void counts_add(sc_bscan_counts *t, const sc_bscan_counts *a)
{
    t->pixels_in_mesh += a->pixels_in_mesh;
    t->walk_steps += a->walk_steps;
    t->walk_aborts += a->walk_aborts;
    t->event_overflows += a->event_overflows;
    t->line_fallbacks += a->line_fallbacks;
    t->walk_relocations += a->walk_relocations;
    t->region_overflows += a->region_overflows;
}

static void acc_add(sc_bscan_area_acc *t, const sc_bscan_area_acc *a)
{
    for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
        t->now_n[i] += a->now_n[i];
        t->now_k[i] += a->now_k[i];
        t->rest_n[i] += a->rest_n[i];
        t->rest_k[i] += a->rest_k[i];
        t->margin_n[i] += a->margin_n[i];
        t->margin_k[i] += a->margin_k[i];
    }
}

/* The frame's lines on the pool: ranges fixed by the line count, run at the same time; then,
 * in range order, each range's lines leave (hook, display) and a range that stopped is finished
 * by the caller, line by line as on the serial path; the counters and label counts added in
 * range order (integers). Lines leave once every range is done: the display sees them in order,
 * later than on the serial path by up to the frame's sampling time. */
static int lines_pool(const frame_args *fa, sc_bscan_area_acc *acc, sc_bscan_counts *cnt,
                      uint32_t *regions_need, int rc)
{
    sc_bscan *b = fa->b;
    const uint32_t lines = b->def.scan.lines_n;
    const uint32_t nr = lines < SC_BSCAN_RANGES ? lines : SC_BSCAN_RANGES;
    for (uint32_t r = 0; r < nr; r++) {
        b->range[r].l0 = (uint32_t)(((uint64_t)r * lines) / nr);
        b->range[r].l1 = (uint32_t)(((uint64_t)(r + 1u) * lines) / nr);
    }
    if (fa->mesh != NULL && fa->mapper == SC_BSCAN_MAP_WALK && b->regions_last != 0u &&
        b->regions_state == 0u) {
        /* the last frame's walker located across folds: this one likely does too, and a range
         * cannot build the bins (the same bins whenever they are built) */
        b->regions_state = build_regions(b, fa->mesh) ? 1u : 2u;
    }
    sc_pool_run(b->pool, range_job, (void *)(uintptr_t)fa, nr);
    for (uint32_t r = 0; r < nr; r++) {
        sc_bscan_range *rg = &b->range[r];
        for (uint32_t l = rg->l0; l < rg->done_to; l++) {
            rc = emit_stored(fa, rg, l, rc);
        }
        if (rg->done_to < rg->l1) {
            line_w w = serial_w(b, &rg->counts, &rg->regions_need);
            rc = lines_serial(&w, fa, rg->done_to, rg->l1, &rg->acc, rc, NULL);
        }
        counts_add(cnt, &rg->counts);
        acc_add(acc, &rg->acc);
        *regions_need |= rg->regions_need;
    }
    return rc;
}
#endif

/* ---- frame ------------------------------------------------------------------------------- */

static int volume_ok(const sc_volume *v)
{
    if (v->voxels == NULL) {
        return 0;
    }
    for (uint32_t d = 0; d < 3u; d++) {
        if (v->dim[d] < 2u || v->dim[d] > SC_MAX_VOLUME_DIM || !isfinite(v->spacing_mm[d]) ||
            !(v->spacing_mm[d] > 0.0f) || !isfinite(v->origin_mm[d])) {
            return 0;
        }
    }
    return 1;
}

static int emit_line(sc_bscan *b, const sc_display_dev *disp, uint32_t frame_no, uint32_t l,
                     const uint8_t *out, int rc)
{
    const int r =
        sc_display_line(disp, frame_no, (uint16_t)l, out, (uint16_t)b->def.scan.samples_n);
    if (r != SC_OK) {
        b->status.display_errors++;
        return rc != SC_OK ? rc : r;
    }
    return rc;
}

/* The frame's closing record carries this frame's compression measure (status areas). */
static int close_frame(sc_bscan *b, const sc_display_dev *disp, uint32_t frame_no, int rc)
{
    sc_bscan_status *st = &b->status;
    const sc_display_end_info end = {
        .frame_no = frame_no,
        .vein_area_ratio = st->areas_valid ? st->area_ratio[SC_LABEL_VEIN] : -1.0f,
        .artery_area_ratio = st->areas_valid ? st->area_ratio[SC_LABEL_ARTERY] : -1.0f,
    };
    const int re = sc_display_frame_end(disp, &end);
    if (re != SC_OK) {
        st->display_errors++;
        return rc != SC_OK ? rc : re;
    }
    return rc;
}

/* The nodes in the image frame (qx, qy, qz), on the pool in spans of SC_BSCAN_XFORM_SPAN nodes
 * (each node its own: any split gives the same bits; 65,536 nodes at 64x32x32) */
#define SC_BSCAN_XFORM_SPAN 4096u
typedef struct xform_args {
    sc_bscan *b;
    const sc_nodes *n;
    uint32_t count;
    const sc_xform *vol2img;
} xform_args;

static void xform_job(void *arg, uint32_t s)
{
    const xform_args *a = (const xform_args *)arg;
    sc_bscan *b = a->b;
    /* the transform and the arrays in locals, the arrays restrict: the stores cannot change
     * what the loop reads, so it runs in vectors (the same operations, lane by lane) */
    const float *r = a->vol2img->r, *t = a->vol2img->t_mm;
    const float r0 = r[0], r1 = r[1], r2 = r[2], r3 = r[3], r4 = r[4], r5 = r[5], r6 = r[6],
                r7 = r[7], r8 = r[8], t0 = t[0], t1 = t[1], t2 = t[2];
    const float *restrict nx = a->n->x, *restrict ny = a->n->y, *restrict nz = a->n->z;
    float *restrict qx = b->qx, *restrict qy = b->qy, *restrict qz = b->qz;
    const uint32_t i0 = s * SC_BSCAN_XFORM_SPAN;
    const uint32_t i1 = i0 + SC_BSCAN_XFORM_SPAN < a->count ? i0 + SC_BSCAN_XFORM_SPAN : a->count;
    for (uint32_t i = i0; i < i1; i++) {
        const float x = nx[i], y = ny[i], z = nz[i];
        qx[i] = r0 * x + r1 * y + r2 * z + t0;
        qy[i] = r3 * x + r4 * y + r5 * z + t1;
        qz[i] = r6 * x + r7 * y + r8 * z + t2;
    }
}

int sc_bscan_frame(sc_bscan *b, const sc_mesh *mesh, const sc_nodes *nodes, const sc_volume *volume,
                   const sc_xform *probe_to_volume, int contact, const sc_display_dev *display,
                   uint32_t frame_no)
{
    if (b == NULL || volume == NULL || probe_to_volume == NULL || display == NULL ||
        !volume_ok(volume)) {
        return SC_ERR_INVALID_ARG;
    }
    if ((mesh == NULL) != (nodes == NULL) ||
        (mesh != NULL && (mesh->tet_count != b->mesh_tets || b->mesh_tets == 0u))) {
        return SC_ERR_INVALID_ARG;
    }
    if (!sc_xform_is_rigid(probe_to_volume, 1e-3f)) {
        return SC_ERR_CASE_TRANSFORM;
    }
    const sc_scan_def *sd = &b->def.scan;
    const uint32_t lines = sd->lines_n, n = sd->samples_n;
    sc_bscan_status *st = &b->status;
    st->frame_no = frame_no;
    st->contact = (uint8_t)(contact != 0);
    st->pixels_in_mesh = 0u;
    st->plane_hull_segments = 0u;
    st->plane_tets = 0u;
    st->walk_steps = 0u;

    sc_display_frame_info info = {
        .frame_no = frame_no,
        .lines = (uint16_t)lines,
        .samples = (uint16_t)n,
        .geometry_id = (uint16_t)sd->kind,
        .flags = (uint16_t)(contact ? SC_DISPLAY_FLAG_CONTACT : 0u),
        .depth_mm = sd->depth_mm,
        .width_mm = sd->kind == SC_SCAN_GEOM_LINEAR ? sd->width_mm : sd->sector_deg,
        /* the sinks draw the fan from the probe face's arc, radius_mm in front of the apex */
        .radius_mm = sd->kind == SC_SCAN_GEOM_LINEAR ? 0.0f : sd->radius_mm,
        .gain_db = b->def.gain_db,
        .dynamic_range_db = b->def.dynamic_range_db,
        .focus_mm = b->def.focus_mm,
        .frequency_mhz = b->def.acoustic.frequency_mhz,
    };
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        info.tgc_db[i] = b->def.tgc_db[i];
    }
    int rc = sc_display_frame_begin(display, &info);
    if (rc != SC_OK) {
        st->display_errors++;
    }

    if (!contact) {
        memset(b->line_out, 0, n);
        for (uint32_t l = 0; l < lines; l++) {
            rc = emit_line(b, display, frame_no, l, b->line_out, rc);
        }
        st->areas_valid = 0u;
        for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
            st->area_now_mm2[i] = 0.0f;
            st->area_rest_mm2[i] = 0.0f;
            st->area_ratio[i] = -1.0f;
        }
        return close_frame(b, display, frame_no, rc);
    }

    frame_ctx c;
    c.img2vol = sc_xform_compose(probe_to_volume, &sd->image_to_probe);
    c.n = n;
    {
        /* above the face, not beyond the apex (curvilinear) */
        float m = b->def.rest_margin_mm / b->geom.sample_mm;
        if (m > -b->geom.s_min) {
            m = -b->geom.s_min;
        }
        c.margin_n = (uint32_t)m;
    }
    for (uint32_t d = 0; d < 3u; d++) {
        c.vo[d] = volume->origin_mm[d];
        c.inv_sp[d] = 1.0f / volume->spacing_mm[d];
    }

    uint32_t mapper = b->def.mapper;
    b->regions_state = 0u;
    if (mesh != NULL) {
        const sc_xform vol2img = sc_xform_inverse(&c.img2vol);
        const xform_args xa = {b, nodes, mesh->node_count, &vol2img};
        sc_pool_run(b->pool, xform_job, (void *)(uintptr_t)&xa,
                    (mesh->node_count + SC_BSCAN_XFORM_SPAN - 1u) / SC_BSCAN_XFORM_SPAN);
        if (++b->epoch == 0u) { /* wrapped: forget every entry */
            for (uint32_t i = 0; i < SC_BSCAN_TET_CACHE; i++) {
                b->tcache[i].epoch = 0u;
            }
            b->epoch = 1u;
        }
        if (mapper == SC_BSCAN_MAP_REGIONS) {
            if (build_regions(b, mesh)) {
                b->regions_state = 1u;
                st->plane_tets = b->ptet_count;
            } else {
                st->region_overflows++;
                mapper = SC_BSCAN_MAP_WALK;
            }
        }
        if (mapper == SC_BSCAN_MAP_WALK) {
            build_segments(b, mesh);
            st->plane_hull_segments = b->seg_count;
        }
    }

    vol_ctx vc;
    vc.vox = volume->voxels;
    vc.lab = volume->labels;
    vc.la = (int64_t)(b->lut_a * 65536.0f + 0.5f);
    for (uint32_t d = 0; d < 3u; d++) {
        const uint32_t dim = volume->dim[d];
        vc.hi[d] = (float)dim - 0.5f;
        /* below the last voxel centre by the weight rounding, so x + 1 stays in the grid */
        vc.xmax[d] = dim > 1u ? ((int64_t)(dim - 1u) << 32) - 1 - SC_W_HALF : 0;
        vc.stride[d] =
            d == 0u ? 1u : (d == 1u ? volume->dim[0] : (size_t)volume->dim[0] * volume->dim[1]);
    }
    for (uint32_t d = 0; d < 3u; d++) {
        vc.sp_mm[d] = volume->spacing_mm[d];
        const float slab = SC_BSCAN_BEYOND_SLAB_MM / volume->spacing_mm[d];
        const float most = (float)volume->dim[d] - 1.0f;
        vc.slab[d] = slab < 1.0f ? 1.0f : (slab > most ? most : slab);
    }
    vc.beyond_gl_per_mm = 255.0f * SC_BSCAN_BEYOND_DB_PER_MM / b->def.dynamic_range_db;
    vc.span = sc_bscan_span_selected();
    vc.line = sc_bscan_line_selected();
    vc.words = sc_bscan_words_selected();
    vc.acou_run = sc_acoustics_run_selected();
    vc.nearest = sc_bscan_nearest_selected();
    vc.margin = sc_bscan_margin_selected();
    vc.sy32 = volume->dim[0];
    vc.sz32 = volume->dim[0] * volume->dim[1];
    sc_bscan_area_acc acc;
    memset(&acc, 0, sizeof acc);
    sc_bscan_margin_memo *mm = &b->margin_memo;
    const int margin_known =
        mm->valid != 0u && volume->labels != NULL && mm->labels == volume->labels &&
        mm->margin_n == c.margin_n && memcmp(&mm->pose, probe_to_volume, sizeof mm->pose) == 0 &&
        memcmp(mm->dim, volume->dim, sizeof mm->dim) == 0 &&
        memcmp(mm->origin_mm, volume->origin_mm, sizeof mm->origin_mm) == 0 &&
        memcmp(mm->spacing_mm, volume->spacing_mm, sizeof mm->spacing_mm) == 0;
    const frame_args fa = {.b = b,
                           .mesh = mesh,
                           .nodes = nodes,
                           .volume = volume,
                           .vc = &vc,
                           .c = c,
                           .mapper = mapper,
                           .margin_known = margin_known,
                           .display = display,
                           .frame_no = frame_no};
    sc_bscan_counts cnt;
    memset(&cnt, 0, sizeof cnt);
    uint32_t regions_need = 0u;
#if SC_BSCAN_RANGES > 1
    if (b->pool != NULL && sc_pool_workers(b->pool) > 1u && b->def.psf == 0u) {
        rc = lines_pool(&fa, &acc, &cnt, &regions_need, rc);
    } else
#endif
    {
        uint32_t psf_next = 0;
#if SC_BSCAN_PSF
        if (b->def.psf != 0u) {
            sc_psf_frame_begin(&b->psf, volume->spacing_mm);
        }
#endif
        line_w w = serial_w(b, &cnt, &regions_need);
        rc = lines_serial(&w, &fa, 0u, lines, &acc, rc, &psf_next);
    }
    b->regions_last = regions_need;
    st->pixels_in_mesh = cnt.pixels_in_mesh;
    st->walk_steps = cnt.walk_steps;
    st->walk_aborts += cnt.walk_aborts;
    st->event_overflows += cnt.event_overflows;
    st->line_fallbacks += cnt.line_fallbacks;
    st->walk_relocations += cnt.walk_relocations;
    st->region_overflows += cnt.region_overflows;
    if (volume->labels != NULL) {
        if (margin_known) {
            memcpy(acc.margin_n, mm->n, sizeof acc.margin_n);
            memcpy(acc.margin_k, mm->k, sizeof acc.margin_k);
        } else {
            mm->valid = 1u;
            mm->pose = *probe_to_volume;
            mm->labels = volume->labels;
            memcpy(mm->dim, volume->dim, sizeof mm->dim);
            memcpy(mm->origin_mm, volume->origin_mm, sizeof mm->origin_mm);
            memcpy(mm->spacing_mm, volume->spacing_mm, sizeof mm->spacing_mm);
            mm->margin_n = c.margin_n;
            memcpy(mm->n, acc.margin_n, sizeof mm->n);
            memcpy(mm->k, acc.margin_k, sizeof mm->k);
        }
    }
    /* areas: sum over pixels of the pixel area, from counts (exact integers) */
    const float a0 = b->geom.sample_area_mm2[0];
    const float a1 = n > 1u ? b->geom.sample_area_mm2[1] - a0 : 0.0f; /* per sample index */
    st->areas_valid = (uint8_t)(volume->labels != NULL);
    st->image_area_mm2 = 0.0f;
    for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
        st->area_now_mm2[i] = a0 * (float)acc.now_n[i] + a1 * (float)acc.now_k[i];
        st->area_rest_mm2[i] = a0 * (float)(acc.rest_n[i] + acc.margin_n[i]) +
                               a1 * ((float)acc.rest_k[i] + (float)acc.margin_k[i]);
        st->area_ratio[i] =
            st->area_rest_mm2[i] > 0.0f ? st->area_now_mm2[i] / st->area_rest_mm2[i] : -1.0f;
        st->image_area_mm2 += st->area_now_mm2[i];
    }
    return close_frame(b, display, frame_no, rc);
}
