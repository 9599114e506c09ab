/* sc_isosurface.c: marching cubes by face walking + Gaussian-weighted Taubin smoothing. */
#include "sc_isosurface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"

/* Cube corner c has offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). */
typedef struct cube_tables {
    int edge_of[8][8]; /* cube edge id of a corner pair, -1 if not an edge */
    int edge_a[12];    /* corner with the smaller offset */
    int edge_axis[12]; /* axis of the edge */
    int face[6][4];    /* corners, counter-clockwise seen from outside */
} cube_tables;

static void tables_init(cube_tables *t)
{
    memset(t->edge_of, -1, sizeof t->edge_of);
    int e = 0;
    for (int c = 0; c < 8; c++) {
        for (int a = 0; a < 3; a++) {
            if (!(c & (1 << a))) {
                int d = c | (1 << a);
                t->edge_of[c][d] = t->edge_of[d][c] = e;
                t->edge_a[e] = c;
                t->edge_axis[e] = a;
                e++;
            }
        }
    }
    /* faces: fixed axis a at side s; the other axes u, v; cycle (0,0),(1,0),(1,1),(0,1) */
    int f = 0;
    for (int a = 0; a < 3; a++) {
        int u = (a + 1) % 3, v = (a + 2) % 3;
        for (int s = 0; s < 2; s++) {
            const int cyc[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int m = 0; m < 4; m++) {
                t->face[f][m] = (s << a) | (cyc[m][0] << u) | (cyc[m][1] << v);
            }
            /* (u, v, a) is right-handed: the cycle is counter-clockwise about +a; on the
             * s = 0 side the outward normal is -a, so reverse it there */
            if (s == 0) {
                int tmp = t->face[f][1];
                t->face[f][1] = t->face[f][3];
                t->face[f][3] = tmp;
            }
            f++;
        }
    }
}

sc_iso_opts sc_iso_default_opts(void)
{
    return (sc_iso_opts){.label = 4, .sigma_mm = 1.0f, .iterations = 10u};
}

void sc_iso_mesh_free(sc_iso_mesh *m)
{
    if (m != NULL) {
        free(m->xyz);
        free(m->tri);
        m->xyz = NULL;
        m->tri = NULL;
    }
}

typedef struct growbuf {
    void *p;
    size_t n, cap, elem;
} growbuf;

static int gb_push(growbuf *b, const void *v)
{
    if (b->n == b->cap) {
        size_t nc = b->cap ? b->cap * 2u : 4096u;
        void *np = realloc(b->p, nc * b->elem);
        if (np == NULL) {
            return -1;
        }
        b->p = np;
        b->cap = nc;
    }
    memcpy((char *)b->p + b->n * b->elem, v, b->elem);
    b->n++;
    return 0;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Taubin smoothing with Gaussian weights over the one-ring. */
static int smooth(sc_iso_mesh *m, float sigma, uint32_t iterations)
{
    if (sigma <= 0.0f || iterations == 0u || m->vertex_count == 0u) {
        return SC_OK;
    }
    size_t ne = m->triangle_count * 6u;
    uint64_t *edges = malloc(ne * sizeof *edges);
    size_t *start = calloc(m->vertex_count + 1u, sizeof *start);
    float *tmp = malloc(m->vertex_count * 3u * sizeof(float));
    if (!edges || !start || !tmp) {
        free(edges);
        free(start);
        free(tmp);
        return SC_ERR_NO_SPACE;
    }
    size_t k = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        for (int e = 0; e < 3; e++) {
            uint64_t a = m->tri[t * 3 + (size_t)e], b = m->tri[t * 3 + (size_t)((e + 1) % 3)];
            edges[k++] = (a << 32) | b;
            edges[k++] = (b << 32) | a;
        }
    }
    qsort(edges, ne, sizeof *edges, cmp_u64);
    size_t u = 0;
    for (size_t i = 0; i < ne; i++) {
        if (u == 0u || edges[i] != edges[u - 1u]) {
            edges[u++] = edges[i];
        }
    }
    for (size_t i = 0; i < u; i++) {
        start[(edges[i] >> 32) + 1u]++;
    }
    for (size_t v = 0; v < m->vertex_count; v++) {
        start[v + 1u] += start[v];
    }
    const float inv2s2 = 1.0f / (2.0f * sigma * sigma);
    const float steps[2] = {0.5f, -0.53f}; /* Taubin lambda, mu */
    for (uint32_t it = 0; it < iterations; it++) {
        for (int s = 0; s < 2; s++) {
            for (size_t v = 0; v < m->vertex_count; v++) {
                const float *p = &m->xyz[v * 3u];
                float acc[3] = {0.0f, 0.0f, 0.0f}, wsum = 0.0f;
                for (size_t i = start[v]; i < start[v + 1u]; i++) {
                    const float *q = &m->xyz[(edges[i] & 0xFFFFFFFFu) * 3u];
                    float dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
                    float w = expf(-(dx * dx + dy * dy + dz * dz) * inv2s2);
                    acc[0] += w * dx;
                    acc[1] += w * dy;
                    acc[2] += w * dz;
                    wsum += w;
                }
                for (int a = 0; a < 3; a++) {
                    tmp[v * 3u + (size_t)a] =
                        p[a] + (wsum > 0.0f ? steps[s] * acc[a] / wsum : 0.0f);
                }
            }
            memcpy(m->xyz, tmp, m->vertex_count * 3u * sizeof(float));
        }
    }
    free(edges);
    free(start);
    free(tmp);
    return SC_OK;
}

int sc_iso_extract(const sc_volume *vol, const sc_iso_opts *o, sc_iso_mesh *out)
{
    if (vol == NULL || o == NULL || out == NULL || vol->labels == NULL || o->label < 0 ||
        o->label > 255) {
        return SC_ERR_INVALID_ARG;
    }
    memset(out, 0, sizeof *out);
    const uint32_t *dim = vol->dim;
    const uint8_t L = (uint8_t)o->label;
    /* bounding box of the label */
    int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {-1, -1, -1};
    for (uint32_t k = 0; k < dim[2]; k++) {
        for (uint32_t j = 0; j < dim[1]; j++) {
            const uint8_t *row = vol->labels + (size_t)dim[0] * (j + (size_t)dim[1] * k);
            for (uint32_t i = 0; i < dim[0]; i++) {
                if (row[i] == L) {
                    const int64_t c[3] = {i, j, k};
                    for (int a = 0; a < 3; a++) {
                        lo[a] = c[a] < lo[a] ? c[a] : lo[a];
                        hi[a] = c[a] > hi[a] ? c[a] : hi[a];
                    }
                }
            }
        }
    }
    if (hi[0] < 0) {
        return SC_ERR_NOT_FOUND;
    }
    /* work grid: the box plus one layer of outside on every side (closes the surface) */
    int64_t g0[3], gn[3];
    for (int a = 0; a < 3; a++) {
        g0[a] = lo[a] - 1;
        gn[a] = hi[a] - lo[a] + 3;
    }
    const size_t gcount = (size_t)(gn[0] * gn[1] * gn[2]);
    uint8_t *in = malloc(gcount);
    int32_t *vid = malloc(gcount * 3u * sizeof(int32_t));
    if (!in || !vid) {
        free(in);
        free(vid);
        return SC_ERR_NO_SPACE;
    }
    for (int64_t k = 0; k < gn[2]; k++) {
        for (int64_t j = 0; j < gn[1]; j++) {
            for (int64_t i = 0; i < gn[0]; i++) {
                int64_t x = g0[0] + i, y = g0[1] + j, z = g0[2] + k;
                int inside = 0;
                if (x >= 0 && y >= 0 && z >= 0 && x < dim[0] && y < dim[1] && z < dim[2]) {
                    inside =
                        vol->labels[(size_t)x +
                                    (size_t)dim[0] * ((size_t)y + (size_t)dim[1] * (size_t)z)] == L;
                }
                in[(size_t)(i + gn[0] * (j + gn[1] * k))] = (uint8_t)inside;
            }
        }
    }
    memset(vid, -1, gcount * 3u * sizeof(int32_t));
    growbuf verts = {NULL, 0, 0, 3u * sizeof(float)};
    growbuf tris = {NULL, 0, 0, 3u * sizeof(uint32_t)};
    cube_tables t;
    tables_init(&t);
    int rc = SC_OK;
    const int64_t stride[3] = {1, gn[0], gn[0] * gn[1]};
    for (int64_t k = 0; k + 1 < gn[2] && rc == SC_OK; k++) {
        for (int64_t j = 0; j + 1 < gn[1] && rc == SC_OK; j++) {
            for (int64_t i = 0; i + 1 < gn[0] && rc == SC_OK; i++) {
                const int64_t base = i + gn[0] * (j + gn[1] * k);
                int cin[8], n_in = 0;
                for (int c = 0; c < 8; c++) {
                    int64_t off = base + (c & 1) * stride[0] + ((c >> 1) & 1) * stride[1] +
                                  ((c >> 2) & 1) * stride[2];
                    cin[c] = in[off];
                    n_in += cin[c];
                }
                if (n_in == 0 || n_in == 8) {
                    continue;
                }
                /* segments on the faces: exit (inside -> outside along the CCW walk) to the
                 * entry before the same inside corner */
                int next[12];
                memset(next, -1, sizeof next);
                for (int f = 0; f < 6; f++) {
                    const int *q = t.face[f];
                    for (int m = 0; m < 4; m++) {
                        int a = q[m], b = q[(m + 1) % 4];
                        if (cin[a] && !cin[b]) {
                            /* exit on edge (a, b); walk back over the inside corners to the
                             * entry edge (o, first inside corner); b ends the walk */
                            int cur = m;
                            while (cin[q[(cur + 3) % 4]]) {
                                cur = (cur + 3) % 4;
                            }
                            int entry_edge = t.edge_of[q[(cur + 3) % 4]][q[cur]];
                            next[t.edge_of[a][b]] = entry_edge;
                        }
                    }
                }
                /* global vertices of the crossing edges */
                int32_t gv[12];
                for (int e = 0; e < 12; e++) {
                    gv[e] = -1;
                    if (next[e] < 0) {
                        continue;
                    }
                    int ca = t.edge_a[e], ax = t.edge_axis[e];
                    int64_t gi = base + (ca & 1) * stride[0] + ((ca >> 1) & 1) * stride[1] +
                                 ((ca >> 2) & 1) * stride[2];
                    int32_t *slot = &vid[(size_t)gi * 3u + (size_t)ax];
                    if (*slot < 0) {
                        int64_t c[3] = {i + (ca & 1), j + ((ca >> 1) & 1), k + ((ca >> 2) & 1)};
                        float p[3];
                        for (int a2 = 0; a2 < 3; a2++) {
                            float idx = (float)(g0[a2] + c[a2]) + (a2 == ax ? 0.5f : 0.0f);
                            p[a2] = vol->origin_mm[a2] + vol->spacing_mm[a2] * idx;
                        }
                        if (verts.n >= 0x7FFFFFFFu || gb_push(&verts, p) != 0) {
                            rc = SC_ERR_NO_SPACE;
                            break;
                        }
                        *slot = (int32_t)(verts.n - 1u);
                    }
                    gv[e] = *slot;
                }
                /* loops -> triangle fans */
                int used[12] = {0};
                for (int e0 = 0; e0 < 12 && rc == SC_OK; e0++) {
                    if (next[e0] < 0 || used[e0]) {
                        continue;
                    }
                    int loop[12], len = 0, e = e0;
                    while (!used[e] && len < 12) {
                        used[e] = 1;
                        loop[len++] = e;
                        e = next[e];
                        if (e < 0) {
                            break;
                        }
                    }
                    /* the face walk winds the loop clockwise seen from outside the label:
                     * emit reversed. Loops of 4+ vertices get a centre vertex so that the
                     * only edges shared between cubes are the face segments (a fan's
                     * chords could meet another cube's chords on an ambiguous face) */
                    if (len == 3) {
                        uint32_t tri[3] = {(uint32_t)gv[loop[0]], (uint32_t)gv[loop[2]],
                                           (uint32_t)gv[loop[1]]};
                        if (gb_push(&tris, tri) != 0) {
                            rc = SC_ERR_NO_SPACE;
                        }
                        continue;
                    }
                    float cen[3] = {0.0f, 0.0f, 0.0f};
                    for (int m = 0; m < len; m++) {
                        const float *q = (const float *)verts.p + (size_t)gv[loop[m]] * 3u;
                        cen[0] += q[0] / (float)len;
                        cen[1] += q[1] / (float)len;
                        cen[2] += q[2] / (float)len;
                    }
                    if (gb_push(&verts, cen) != 0) {
                        rc = SC_ERR_NO_SPACE;
                        break;
                    }
                    uint32_t cv = (uint32_t)(verts.n - 1u);
                    for (int m = 0; m < len; m++) {
                        uint32_t tri[3] = {cv, (uint32_t)gv[loop[(m + 1) % len]],
                                           (uint32_t)gv[loop[m]]};
                        if (gb_push(&tris, tri) != 0) {
                            rc = SC_ERR_NO_SPACE;
                            break;
                        }
                    }
                }
            }
        }
    }
    free(in);
    free(vid);
    out->xyz = verts.p;
    out->vertex_count = verts.n;
    out->tri = tris.p;
    out->triangle_count = tris.n;
    if (rc == SC_OK) {
        rc = smooth(out, o->sigma_mm, o->iterations);
    }
    if (rc != SC_OK) {
        sc_iso_mesh_free(out);
    }
    return rc;
}

int sc_iso_write_ply(const sc_iso_mesh *m, const char *path)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return SC_ERR_IO;
    }
    fprintf(f,
            "ply\nformat ascii 1.0\ncomment sonocomp label isosurface, mm, volume frame\n"
            "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
            "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
            m->vertex_count, m->triangle_count);
    for (size_t v = 0; v < m->vertex_count; v++) {
        fprintf(f, "%.4f %.4f %.4f\n", (double)m->xyz[v * 3u], (double)m->xyz[v * 3u + 1u],
                (double)m->xyz[v * 3u + 2u]);
    }
    for (size_t t = 0; t < m->triangle_count; t++) {
        fprintf(f, "3 %u %u %u\n", m->tri[t * 3u], m->tri[t * 3u + 1u], m->tri[t * 3u + 2u]);
    }
    return fclose(f) == 0 ? SC_OK : SC_ERR_IO;
}

int sc_iso_write_obj(const sc_iso_mesh *m, const char *path)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return SC_ERR_IO;
    }
    fprintf(f, "# sonocomp label isosurface, mm, volume frame\n");
    for (size_t v = 0; v < m->vertex_count; v++) {
        fprintf(f, "v %.4f %.4f %.4f\n", (double)m->xyz[v * 3u], (double)m->xyz[v * 3u + 1u],
                (double)m->xyz[v * 3u + 2u]);
    }
    for (size_t t = 0; t < m->triangle_count; t++) {
        fprintf(f, "f %u %u %u\n", m->tri[t * 3u] + 1u, m->tri[t * 3u + 1u] + 1u,
                m->tri[t * 3u + 2u] + 1u);
    }
    return fclose(f) == 0 ? SC_OK : SC_ERR_IO;
}
