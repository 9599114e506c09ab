/* sc_mesh.c: regular 5-tet mesh of a box, see sc_mesh.h.
 *
 * Cube corners are numbered c = dx + 2 dy + 4 dz (dx, dy, dz in {0, 1}). In a cube whose
 * lower corner (i, j, k) has i + j + k even, the four "corner" tets sit at the corners with an
 * even number of set bits (0, 3, 5, 6) and the central tet joins the others (1, 2, 4, 7); in an
 * odd cube the roles swap. Every face diagonal then joins two grid nodes whose i + j + k is
 * odd, in both cubes that share the face, so the faces conform.
 */
#include "sc_mesh.h"

#include <math.h>
#include <stddef.h>

#include "sc_assert.h"
#include "sc_err.h"


static float det3(const float a[3], const float b[3], const float c[3])
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

static void corner_pos(uint32_t c, float p[3])
{
    p[0] = (float)(c & 1u);
    p[1] = (float)((c >> 1) & 1u);
    p[2] = (float)((c >> 2) & 1u);
}

static void orient_template(uint8_t t[4])
{
    float p[4][3];
    for (uint32_t v = 0; v < 4u; v++) {
        corner_pos(t[v], p[v]);
    }
    float e1[3], e2[3], e3[3];
    for (uint32_t d = 0; d < 3u; d++) {
        e1[d] = p[1][d] - p[0][d];
        e2[d] = p[2][d] - p[0][d];
        e3[d] = p[3][d] - p[0][d];
    }
    if (det3(e1, e2, e3) < 0.0f) {
        uint8_t s = t[2];
        t[2] = t[3];
        t[3] = s;
    }
}

/* Five tets of a cube as local corner numbers, for the even (0) and odd (1) parity, each
 * ordered so that the tet is positively oriented in the unit cube (checked again on the
 * global coordinates in sc_mesh_build). */
static void build_templates(uint8_t tmpl[2][5][4])
{
    static const uint8_t corners[2][4] = {{0u, 3u, 5u, 6u}, {1u, 2u, 4u, 7u}};
    for (uint32_t par = 0; par < 2u; par++) {
        for (uint32_t t = 0; t < 4u; t++) {
            uint8_t c = corners[par][t];
            uint8_t *q = tmpl[par][t];
            q[0] = c;
            q[1] = (uint8_t)(c ^ 1u);
            q[2] = (uint8_t)(c ^ 2u);
            q[3] = (uint8_t)(c ^ 4u);
            orient_template(q);
        }
        /* central tet: the corners of the other parity */
        uint8_t *q = tmpl[par][4];
        for (uint32_t v = 0; v < 4u; v++) {
            q[v] = corners[1u - par][v];
        }
        orient_template(q);
    }
}

sc_mesh_def sc_mesh_default_def(void)
{
    sc_mesh_def d;
    d.nx = SC_MAX_MESH_NX;
    d.ny = SC_MAX_MESH_NY;
    d.nz = SC_MAX_MESH_NZ;
    d.origin_mm[0] = 0.0f;
    d.origin_mm[1] = 0.0f;
    d.origin_mm[2] = 0.0f;
    d.size_mm[0] = 40.0f;
    d.size_mm[1] = 20.0f;
    d.size_mm[2] = 30.0f;
    return d;
}

static uint32_t node_of(const sc_mesh *m, uint32_t i, uint32_t j, uint32_t k)
{
    return i + m->nx * (j + m->ny * k);
}

/* Grid coordinates of a node. */
static void node_ijk(const sc_mesh *m, uint32_t n, uint32_t ijk[3])
{
    ijk[0] = n % m->nx;
    ijk[1] = (n / m->nx) % m->ny;
    ijk[2] = n / (m->nx * m->ny);
}

static int tet_has_nodes(const uint32_t tet[4], const uint32_t f[3])
{
    int hits = 0;
    for (uint32_t a = 0; a < 3u; a++) {
        for (uint32_t v = 0; v < 4u; v++) {
            if (tet[v] == f[a]) {
                hits++;
                break;
            }
        }
    }
    return hits == 3;
}

/* Neighbour across the face of tet t opposite vertex v: the face lies either inside the cube
 * (neighbour among the same cube's five) or on one cube face (neighbour among the five of the
 * adjacent cube, or none on the hull). O(1). */
static int32_t find_nbr(const sc_mesh *m, uint32_t t, uint32_t v)
{
    const uint32_t cx = m->nx - 1u, cy = m->ny - 1u, cz = m->nz - 1u;
    const uint32_t cube = t / 5u;
    uint32_t cc[3] = {cube % cx, (cube / cx) % cy, cube / (cx * cy)};
    uint32_t f[3];
    uint32_t fi = 0;
    for (uint32_t w = 0; w < 4u; w++) {
        if (w != v) {
            f[fi++] = m->tet[t][w];
        }
    }
    uint32_t g[3][3];
    for (uint32_t a = 0; a < 3u; a++) {
        node_ijk(m, f[a], g[a]);
    }
    int32_t ncube[3] = {(int32_t)cc[0], (int32_t)cc[1], (int32_t)cc[2]};
    const uint32_t lim[3] = {cx, cy, cz};
    for (uint32_t ax = 0; ax < 3u; ax++) {
        if (g[0][ax] == g[1][ax] && g[1][ax] == g[2][ax]) {
            /* on the cube face orthogonal to ax */
            if (g[0][ax] == cc[ax]) {
                if (cc[ax] == 0u) {
                    return -1;
                }
                ncube[ax] -= 1;
            } else {
                if (cc[ax] + 1u >= lim[ax]) {
                    return -1;
                }
                ncube[ax] += 1;
            }
            break;
        }
    }
    const uint32_t nc =
        (uint32_t)ncube[0] + cx * ((uint32_t)ncube[1] + cy * (uint32_t)ncube[2]);
    for (uint32_t u = nc * 5u; u < nc * 5u + 5u; u++) {
        if (u != t && tet_has_nodes(m->tet[u], f)) {
            return (int32_t)u;
        }
    }
    return -2; /* not conforming: a bug, reported by the caller */
}

float sc_mesh_tet_volume_mm3(const float *x, const float *y, const float *z, const uint32_t tet[4])
{
    const uint32_t a = tet[0], b = tet[1], c = tet[2], d = tet[3];
    const float e1[3] = {x[b] - x[a], y[b] - y[a], z[b] - z[a]};
    const float e2[3] = {x[c] - x[a], y[c] - y[a], z[c] - z[a]};
    const float e3[3] = {x[d] - x[a], y[d] - y[a], z[d] - z[a]};
    return det3(e1, e2, e3) / 6.0f;
}

int sc_mesh_build(sc_mesh *m, const sc_mesh_def *def)
{
    if (m == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (def->nx < 2u || def->ny < 2u || def->nz < 2u || def->nx > SC_MAX_MESH_NX ||
        def->ny > SC_MAX_MESH_NY || def->nz > SC_MAX_MESH_NZ) {
        return SC_ERR_MESH_DIMS;
    }
    for (uint32_t d = 0; d < 3u; d++) {
        if (!isfinite(def->origin_mm[d]) || !isfinite(def->size_mm[d])) {
            return SC_ERR_NOT_FINITE;
        }
        if (!(def->size_mm[d] > 0.0f)) {
            return SC_ERR_RANGE;
        }
    }
    uint8_t tmpl[2][5][4];
    build_templates(tmpl);
    m->nx = def->nx;
    m->ny = def->ny;
    m->nz = def->nz;
    m->node_count = def->nx * def->ny * def->nz;
    m->tet_count = 5u * (def->nx - 1u) * (def->ny - 1u) * (def->nz - 1u);
    const uint32_t cnt[3] = {def->nx, def->ny, def->nz};
    for (uint32_t d = 0; d < 3u; d++) {
        m->origin_mm[d] = def->origin_mm[d];
        m->cell_mm[d] = def->size_mm[d] / (float)(cnt[d] - 1u);
    }
    for (uint32_t k = 0; k < m->nz; k++) {
        for (uint32_t j = 0; j < m->ny; j++) {
            for (uint32_t i = 0; i < m->nx; i++) {
                const uint32_t n = node_of(m, i, j, k);
                /* the last node lands exactly on the far side of the box */
                m->rest_x[n] = (i + 1u == m->nx) ? def->origin_mm[0] + def->size_mm[0]
                                                 : def->origin_mm[0] + (float)i * m->cell_mm[0];
                m->rest_y[n] = (j + 1u == m->ny) ? def->origin_mm[1] + def->size_mm[1]
                                                 : def->origin_mm[1] + (float)j * m->cell_mm[1];
                m->rest_z[n] = (k + 1u == m->nz) ? def->origin_mm[2] + def->size_mm[2]
                                                 : def->origin_mm[2] + (float)k * m->cell_mm[2];
                m->node_fixed[n] = 0u;
            }
        }
    }
    uint32_t t = 0;
    for (uint32_t k = 0; k + 1u < m->nz; k++) {
        for (uint32_t j = 0; j + 1u < m->ny; j++) {
            for (uint32_t i = 0; i + 1u < m->nx; i++) {
                const uint32_t par = (i + j + k) & 1u;
                for (uint32_t q = 0; q < 5u; q++) {
                    for (uint32_t v = 0; v < 4u; v++) {
                        const uint32_t c = tmpl[par][q][v];
                        m->tet[t][v] = node_of(m, i + (c & 1u), j + ((c >> 1) & 1u),
                                               k + ((c >> 2) & 1u));
                    }
                    m->tet_label[t] = 0u;
                    t++;
                }
            }
        }
    }
    SC_ASSERT(t == m->tet_count);
    for (uint32_t e = 0; e < m->tet_count; e++) {
        if (!(sc_mesh_tet_volume_mm3(m->rest_x, m->rest_y, m->rest_z, m->tet[e]) > 0.0f)) {
            return SC_ERR_MESH_ORIENTATION;
        }
        for (uint32_t v = 0; v < 4u; v++) {
            const int32_t nb = find_nbr(m, e, v);
            if (nb < -1) {
                return SC_ERR_MESH_ORIENTATION; /* non-conforming face: a bug */
            }
            m->tet_nbr[e][v] = nb;
        }
    }
    return SC_OK;
}

void sc_nodes_reset_to_rest(sc_nodes *n, const sc_mesh *m)
{
    SC_ASSERT(n != NULL && m != NULL);
    for (uint32_t i = 0; i < m->node_count; i++) {
        n->x[i] = m->rest_x[i];
        n->y[i] = m->rest_y[i];
        n->z[i] = m->rest_z[i];
        n->vx[i] = 0.0f;
        n->vy[i] = 0.0f;
        n->vz[i] = 0.0f;
        n->fx[i] = 0.0f;
        n->fy[i] = 0.0f;
        n->fz[i] = 0.0f;
    }
}
