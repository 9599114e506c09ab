/* sc_casesurf.c: SURF section builder, see sc_casesurf.h. */
#include "sc_casesurf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_isosurface.h"
#include "sc_labels.h"
#include "sc_mesh.h"

#define TARGET_SPACING_MM 1.0f

typedef struct vbuf {
    uint32_t *tet;
    float *w;      /* 3 per vertex */
    uint32_t *tri; /* 3 per triangle */
    uint32_t nv, nt;
    sc_case_surface s[SC_CASE_SURF_MAX_SURFACES];
    uint32_t ns;
} vbuf;

/* barycentric weights of p in tet t of the rest mesh */
static void bary(const sc_mesh *m, uint32_t t, const float p[3], float w[4])
{
    const uint32_t *n = m->tet[t];
    double a[3][3], r[3];
    for (int d = 0; d < 3; d++) {
        const float *c = d == 0 ? m->rest_x : (d == 1 ? m->rest_y : m->rest_z);
        for (int k = 0; k < 3; k++) {
            a[d][k] = (double)c[n[k]] - (double)c[n[3]];
        }
        r[d] = (double)p[d] - (double)c[n[3]];
    }
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    double x[3];
    for (int k = 0; k < 3; k++) { /* Cramer's rule */
        double b[3][3];
        memcpy(b, a, sizeof b);
        for (int d = 0; d < 3; d++) {
            b[d][k] = r[d];
        }
        x[k] = (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])) /
               det;
    }
    w[0] = (float)x[0];
    w[1] = (float)x[1];
    w[2] = (float)x[2];
    w[3] = (float)(1.0 - x[0] - x[1] - x[2]);
}

/* embed p (clamped into the box) in the best tet of its cell */
static void locate(const sc_mesh *m, const float p_in[3], uint32_t *tet, float w[4])
{
    const uint32_t cnt[3] = {m->nx, m->ny, m->nz};
    float p[3];
    uint32_t cell[3];
    for (int d = 0; d < 3; d++) {
        const float hi = m->origin_mm[d] + m->cell_mm[d] * (float)(cnt[d] - 1u);
        p[d] = fminf(fmaxf(p_in[d], m->origin_mm[d]), hi);
        float f = floorf((p[d] - m->origin_mm[d]) / m->cell_mm[d]);
        f = fminf(fmaxf(f, 0.0f), (float)(cnt[d] - 2u));
        cell[d] = (uint32_t)f;
    }
    const uint32_t c = cell[0] + (m->nx - 1u) * (cell[1] + (m->ny - 1u) * cell[2]);
    float best = -1e30f;
    for (uint32_t q = 0; q < 5u; q++) {
        float ww[4];
        bary(m, 5u * c + q, p, ww);
        const float mn = fminf(fminf(ww[0], ww[1]), fminf(ww[2], ww[3]));
        if (mn > best) {
            best = mn;
            *tet = 5u * c + q;
            memcpy(w, ww, sizeof ww);
        }
    }
}

static int grow(vbuf *b, uint32_t nv, uint32_t nt)
{
    uint32_t *tet = realloc(b->tet, (size_t)(b->nv + nv) * sizeof *tet);
    if (tet) {
        b->tet = tet;
    }
    float *w = realloc(b->w, (size_t)(b->nv + nv) * 3u * sizeof *w);
    if (w) {
        b->w = w;
    }
    uint32_t *tri = realloc(b->tri, (size_t)(b->nt + nt) * 3u * sizeof *tri + 1u);
    if (tri) {
        b->tri = tri;
    }
    return (tet && w && tri) ? SC_OK : SC_ERR_NO_SPACE;
}

static void add_vertex(vbuf *b, const sc_mesh *m, const float p[3])
{
    uint32_t t = 0;
    float w[4];
    locate(m, p, &t, w);
    b->tet[b->nv] = t;
    b->w[3u * b->nv] = w[0];
    b->w[3u * b->nv + 1u] = w[1];
    b->w[3u * b->nv + 2u] = w[2];
    b->nv++;
}

static int add_skin(vbuf *b, const sc_mesh *m)
{
    const uint32_t nv = m->nx * m->ny, nt = 2u * (m->nx - 1u) * (m->ny - 1u);
    if (grow(b, nv, nt) != SC_OK) {
        return SC_ERR_NO_SPACE;
    }
    const uint32_t v0 = b->nv;
    for (uint32_t j = 0; j < m->ny; j++) {
        for (uint32_t i = 0; i < m->nx; i++) {
            const uint32_t n = i + m->nx * j; /* k = 0: the skin side */
            const float p[3] = {m->rest_x[n], m->rest_y[n], m->rest_z[n]};
            add_vertex(b, m, p);
        }
    }
    for (uint32_t j = 0; j + 1u < m->ny; j++) {
        for (uint32_t i = 0; i + 1u < m->nx; i++) {
            const uint32_t a = v0 + i + m->nx * j, c = a + m->nx;
            const uint32_t t[6] = {a, a + 1u, c, a + 1u, c + 1u, c};
            memcpy(b->tri + 3u * b->nt, t, sizeof t);
            b->nt += 2u;
        }
    }
    b->s[b->ns++] = (sc_case_surface){.label = 0u, .kind = SC_CASE_SURF_SKIN,
                                      .first_vertex = v0, .vertex_count = nv,
                                      .triangle_count = nt};
    return SC_OK;
}

/* the labels inside the mesh box resampled by factor f, with a border of label 0 */
static uint8_t *resample(const sc_volume *v, const sc_mesh_def *md, uint32_t f, sc_volume *out)
{
    uint32_t lo[3], dim[3];
    for (int a = 0; a < 3; a++) {
        float l = (md->origin_mm[a] - v->origin_mm[a]) / v->spacing_mm[a];
        float h = (md->origin_mm[a] + md->size_mm[a] - v->origin_mm[a]) / v->spacing_mm[a];
        l = fmaxf(0.0f, floorf(l));
        h = fminf((float)(v->dim[a] - 1u), ceilf(h));
        lo[a] = (uint32_t)l;
        dim[a] = ((uint32_t)h - lo[a]) / f + 1u + 2u;
    }
    uint8_t *lab = calloc((size_t)dim[0] * dim[1] * dim[2], 1u);
    if (lab == NULL) {
        return NULL;
    }
    for (uint32_t k = 1; k + 1u < dim[2]; k++) {
        for (uint32_t j = 1; j + 1u < dim[1]; j++) {
            for (uint32_t i = 1; i + 1u < dim[0]; i++) {
                const uint64_t si = lo[0] + (i - 1u) * f, sj = lo[1] + (j - 1u) * f,
                               sk = lo[2] + (k - 1u) * f;
                if (si < v->dim[0] && sj < v->dim[1] && sk < v->dim[2]) {
                    lab[i + (size_t)dim[0] * (j + (size_t)dim[1] * k)] =
                        v->labels[si + v->dim[0] * (sj + (uint64_t)v->dim[1] * sk)];
                }
            }
        }
    }
    *out = *v;
    for (int a = 0; a < 3; a++) {
        out->dim[a] = dim[a];
        out->spacing_mm[a] = v->spacing_mm[a] * (float)f;
        out->origin_mm[a] = v->origin_mm[a] + v->spacing_mm[a] * (float)lo[a] - out->spacing_mm[a];
    }
    out->labels = lab;
    out->voxels = lab;
    return lab;
}

static int add_vessels(vbuf *b, const sc_case_def *def, const sc_mesh *m, uint32_t f)
{
    static const int vessel_labels[] = {SC_LABEL_VEIN, SC_LABEL_ARTERY, SC_LABEL_THROMBUS};
    sc_volume rv;
    uint8_t *lab = resample(&def->volume, &def->mesh, f, &rv);
    if (lab == NULL) {
        return SC_ERR_NO_SPACE;
    }
    int rc = SC_OK;
    for (size_t li = 0; li < sizeof vessel_labels / sizeof vessel_labels[0] && rc == SC_OK; li++) {
        if (b->ns >= SC_CASE_SURF_MAX_SURFACES) {
            break;
        }
        sc_iso_opts o = sc_iso_default_opts();
        o.label = vessel_labels[li];
        o.sigma_mm = rv.spacing_mm[0];
        sc_iso_mesh im = {0};
        const int erc = sc_iso_extract(&rv, &o, &im);
        if (erc == SC_ERR_NOT_FOUND) {
            continue;
        }
        if (erc != SC_OK) {
            rc = erc;
            break;
        }
        if (b->nv + im.vertex_count > SC_CASE_SURF_MAX_VERTICES ||
            b->nt + im.triangle_count > SC_CASE_SURF_MAX_TRIANGLES) {
            sc_iso_mesh_free(&im);
            rc = SC_ERR_OVERFLOW;
            break;
        }
        rc = grow(b, (uint32_t)im.vertex_count, (uint32_t)im.triangle_count);
        if (rc == SC_OK) {
            const uint32_t v0 = b->nv;
            for (size_t v = 0; v < im.vertex_count; v++) {
                add_vertex(b, m, &im.xyz[3u * v]);
            }
            for (size_t t = 0; t < 3u * im.triangle_count; t++) {
                b->tri[3u * b->nt + t] = v0 + im.tri[t];
            }
            b->nt += (uint32_t)im.triangle_count;
            b->s[b->ns++] = (sc_case_surface){.label = (uint8_t)o.label,
                                              .kind = SC_CASE_SURF_VESSEL,
                                              .first_vertex = v0,
                                              .vertex_count = (uint32_t)im.vertex_count,
                                              .triangle_count = (uint32_t)im.triangle_count};
        }
        sc_iso_mesh_free(&im);
    }
    free(lab);
    return rc;
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void putf(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put32(p, u);
}

static int encode(const vbuf *b, uint8_t **payload, size_t *n)
{
    const uint64_t size = sc_case_surf_payload_size(b->ns, b->nv, b->nt);
    uint8_t *p = calloc((size_t)size, 1u);
    if (p == NULL) {
        return SC_ERR_NO_SPACE;
    }
    put32(p, SC_CASE_SURF_VERSION);
    put32(p + 4, b->ns);
    put32(p + 8, b->nv);
    put32(p + 12, b->nt);
    uint8_t *q = p + SC_CASE_SURF_HEAD_SIZE;
    for (uint32_t i = 0; i < b->ns; i++, q += SC_CASE_SURF_REC_SIZE) {
        q[0] = b->s[i].label;
        q[1] = b->s[i].kind;
        put32(q + 4, b->s[i].first_vertex);
        put32(q + 8, b->s[i].vertex_count);
        put32(q + 12, b->s[i].triangle_count);
    }
    for (uint32_t v = 0; v < b->nv; v++, q += SC_CASE_SURF_VERTEX_SIZE) {
        put32(q, b->tet[v]);
        putf(q + 4, b->w[3u * v]);
        putf(q + 8, b->w[3u * v + 1u]);
        putf(q + 12, b->w[3u * v + 2u]);
    }
    for (uint32_t t = 0; t < 3u * b->nt; t++, q += 4) {
        put32(q, b->tri[t]);
    }
    *payload = p;
    *n = (size_t)size;
    return SC_OK;
}

int sc_casesurf_build(const sc_case_def *def, uint8_t **payload, size_t *n)
{
    if (def == NULL || payload == NULL || n == NULL || def->volume.labels == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    sc_mesh *m = malloc(sizeof *m);
    if (m == NULL) {
        return SC_ERR_NO_SPACE;
    }
    int rc = sc_mesh_build(m, &def->mesh);
    const float sp = fminf(def->volume.spacing_mm[0],
                           fminf(def->volume.spacing_mm[1], def->volume.spacing_mm[2]));
    uint32_t f = (uint32_t)fmaxf(1.0f, ceilf(TARGET_SPACING_MM / sp));
    for (int attempt = 0; rc == SC_OK && attempt < 8; attempt++, f++) {
        vbuf b;
        memset(&b, 0, sizeof b);
        rc = add_skin(&b, m);
        if (rc == SC_OK) {
            rc = add_vessels(&b, def, m, f);
        }
        if (rc == SC_OK) {
            rc = encode(&b, payload, n);
        }
        free(b.tet);
        free(b.w);
        free(b.tri);
        if (rc != SC_ERR_OVERFLOW) {
            break;
        }
        rc = SC_OK; /* too many vertices: coarser */
    }
    free(m);
    return rc;
}
