/* sc_msds_implicit.c: backward Euler for the MSDS in the FEM's pattern; see
 * sc_msds_implicit.h. */
#include "sc_msds_implicit.h"

#include <math.h>
#include <stddef.h>

#include "sc_assert.h"
#include "sc_msds_kern.h"

static const uint8_t k_pa[6] = {0u, 0u, 0u, 1u, 1u, 2u};
static const uint8_t k_pb[6] = {1u, 2u, 3u, 2u, 3u, 3u};

typedef struct implicit_ctx {
    const sc_msds *s;
    const sc_mesh *m;
} implicit_ctx;

/* B += a u u^T + g I (a 3x3 block stored as 3 rows of 4) */
static inline void add_spring_block(float *B, const float u[3], float a, float g, float sign)
{
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t c = 0; c < 3u; c++) {
            B[4u * r + c] += sign * (a * u[r] * u[c] + (r == c ? g : 0.0f));
        }
    }
}

static void assemble_springs(const sc_msds *s, sc_fem *f, float dt, float *r3)
{
    const uint32_t nn = f->node_count;
    const float *x3 = f->x3;
    for (uint32_t i = 0; i < nn; i++) {
        const uint32_t beg = f->row_start[i], end = f->row_start[i + 1u];
        for (uint32_t b = beg + 1u; b < end; b++) {
            const uint32_t j = f->col[b];
            const uint32_t off = j - i;
            uint32_t d = 0;
            while (d < SC_MSDS_FAMILIES && s->off[d] != off) {
                d++;
            }
            if (d == SC_MSDS_FAMILIES) {
                continue; /* not a spring of the grid (cannot happen on sc_mesh_build's mesh) */
            }
            const float k = s->k_n_per_mm[d][i];
            if (!(k > 0.0f)) {
                continue;
            }
            const float l0 = s->l0_mm[d][i];
            const float dx = x3[4u * j] - x3[4u * i], dy = x3[4u * j + 1u] - x3[4u * i + 1u],
                        dz = x3[4u * j + 2u] - x3[4u * i + 2u];
            /* the explicit kernel's and the init's length: the rest state is exact */
            const float len = sqrtf(dx * dx + dy * dy + dz * dz + SC_MSDS_MIN_LEN2_MM2);
            const float inv = 1.0f / len;
            const float u[3] = {dx * inv, dy * inv, dz * inv};
            const float fs = k * (len - l0); /* tension, N */
            /* f_int_i = -fs u, f_int_j = +fs u; r -= dt f_int */
            for (uint32_t c = 0; c < 3u; c++) {
                r3[4u * i + c] += dt * fs * u[c];
                r3[4u * j + c] -= dt * fs * u[c];
            }
            const float g = len > l0 ? k * (1.0f - l0 * inv) : 0.0f;
            const float a = k - g;
            add_spring_block(f->blk[f->row_start[i]], u, a, g, 1.0f);
            add_spring_block(f->blk[f->row_start[j]], u, a, g, 1.0f);
            add_spring_block(f->blk[b], u, a, g, -1.0f);
        }
    }
}

static void assemble_volume(const sc_msds *s, sc_fem *f, float dt, float *r3)
{
    const float vr = s->def.volume_stiffness_ratio;
    const float floor_frac = s->def.floor_volume_ratio;
    /* floor term: energy 1/2 K_f V0 ((V - V_f) / V0)^2 below V_f = floor_frac V0, i.e. per 6V
     * k = K_f / (6 V0 x 6) = K_f / (6 d0) with d0 = 6 V0 (N/mm^2 from Pa: 1e-6) */
    const float kf = s->def.floor_pa * 1e-6f / 6.0f;
    const float *x3 = f->x3;
    for (uint32_t t = 0; t < s->vol_count; t++) {
        float c = vr * s->kvol36[t];
        const uint32_t v[4] = {s->tv[0][t], s->tv[1][t], s->tv[2][t], s->tv[3][t]};
        const float *p0 = &x3[4u * v[0]];
        const float *p1 = &x3[4u * v[1]];
        const float *p2 = &x3[4u * v[2]];
        const float *p3 = &x3[4u * v[3]];
        /* the same float operations as the init's tet_d6 (rest state exact) */
        const float x0 = p0[0], y0 = p0[1], z0 = p0[2];
        const float e1x = p1[0] - x0, e1y = p1[1] - y0, e1z = p1[2] - z0;
        const float e2x = p2[0] - x0, e2y = p2[1] - y0, e2z = p2[2] - z0;
        const float e3x = p3[0] - x0, e3y = p3[1] - y0, e3z = p3[2] - z0;
        float g[4][3];
        g[1][0] = e2y * e3z - e2z * e3y;
        g[1][1] = e2z * e3x - e2x * e3z;
        g[1][2] = e2x * e3y - e2y * e3x;
        const float d6 = e1x * g[1][0] + e1y * g[1][1] + e1z * g[1][2];
        g[2][0] = e3y * e1z - e3z * e1y;
        g[2][1] = e3z * e1x - e3x * e1z;
        g[2][2] = e3x * e1y - e3y * e1x;
        g[3][0] = e1y * e2z - e1z * e2y;
        g[3][1] = e1z * e2x - e1x * e2z;
        g[3][2] = e1x * e2y - e1y * e2x;
        for (uint32_t q = 0; q < 3u; q++) {
            g[0][q] = -(g[1][q] + g[2][q] + g[3][q]);
        }
        float fd = c * (d6 - s->d0_mm3[t]); /* f_int_a = fd g_a */
        const float d0 = s->d0_mm3[t];
        const float dfloor = floor_frac * d0;
        if (d6 < dfloor && d0 > 0.0f) {
            /* walls that meet do not pass through each other (see sc_msds_implicit.h) */
            const float cf = kf / d0;
            fd += cf * (d6 - dfloor);
            c += cf;
        }
        if (!(c > 0.0f)) {
            continue;
        }
        for (uint32_t a = 0; a < 4u; a++) {
            float *B = f->blk[f->row_start[v[a]]];
            for (uint32_t q = 0; q < 3u; q++) {
                r3[4u * v[a] + q] -= dt * fd * g[a][q];
                for (uint32_t w = 0; w < 3u; w++) {
                    B[4u * q + w] += c * g[a][q] * g[a][w];
                }
            }
        }
        for (uint32_t p = 0; p < 6u; p++) {
            const uint32_t bi = f->tet_blk[t][p];
            const int tr = (bi & SC_FEM_BLK_TRANSPOSED) != 0u;
            const uint32_t a = tr ? k_pb[p] : k_pa[p];
            const uint32_t b = tr ? k_pa[p] : k_pb[p];
            float *B = f->blk[bi & ~SC_FEM_BLK_TRANSPOSED];
            for (uint32_t q = 0; q < 3u; q++) {
                for (uint32_t w = 0; w < 3u; w++) {
                    B[4u * q + w] += c * g[a][q] * g[b][w];
                }
            }
        }
    }
}

static void assemble(void *ctx, sc_fem *f, float dt, float *r3)
{
    const implicit_ctx *c = ctx;
    assemble_springs(c->s, f, dt, r3);
    assemble_volume(c->s, f, dt, r3);
}

void sc_msds_implicit_step(const sc_msds *s, sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                           uint32_t cg_iterations, const uint8_t *kinematic)
{
    SC_ASSERT(s != NULL && f != NULL && m != NULL && n != NULL);
    SC_ASSERT(s->node_count == m->node_count && s->vol_count <= m->tet_count);
    implicit_ctx c = {s, m};
    const sc_fem_custom cu = {
        .assemble = assemble,
        .ctx = &c,
        .beta_s = s->gamma_per_k_s,
        .alpha_per_s = s->def.drag_per_s,
    };
    sc_fem_step_custom(f, m, n, dt_s, cg_iterations, kinematic, &cu);
}
