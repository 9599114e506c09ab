/* sc_fem.c: linear / corotated FEM with a fixed block-CSR pattern and fixed-count PCG, see
 * sc_fem.h.
 *
 * Element (linear tet, volume V, rest shape gradients n_a = grad N_a, a = 0..3):
 *   strain  eps = sym(grad u) = sym(sum_b u_b n_b^T),  stress sigma = lambda tr(eps) I + 2 mu eps
 *   force   f_a = -V sigma n_a
 *   block   K_ab = V (lambda n_a n_b^T + mu n_b n_a^T + mu (n_a . n_b) I),  K_ba = K_ab^T
 * Corotated: F = Ds Dm^-1, R = polar(F), eps = sym(R^T F) - I, f_a = -V R sigma n_a, and the
 * blocks use g_a = R n_a in place of n_a (that is R K_ab R^T).
 */
#include "sc_fem.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"

/* Vertex pairs (a < b) of a tet. tet_blk[e][p] is the index of the stored block of the node
 * pair: block (tet[a], tet[b]) if tet[a] < tet[b], else block (tet[b], tet[a]) with
 * SC_FEM_BLK_TRANSPOSED set (it holds K_ba = K_ab^T). */
static const uint8_t k_pair_a[6] = {0u, 0u, 0u, 1u, 1u, 2u};
static const uint8_t k_pair_b[6] = {1u, 2u, 3u, 2u, 3u, 3u};

/* E in Pa -> N/mm^2; density kg/m^3 * mm^3 -> kg (1e-9) -> N s^2/mm (1e-3). */
#define SC_FEM_PA_TO_NMM2      1.0e-6f
#define SC_FEM_RHO_VOL_TO_MASS 1.0e-12f
/* Newton iterations of the polar decomposition at most (quadratic convergence: a stretch of
 * 3:1 converges to float precision in about 6 scaled iterations). */
#define SC_FEM_POLAR_MAX_ITER 8u
/* det F below this: the element is flat or inverted; polar factor undefined: use R = I. */
#define SC_FEM_DET_MIN 1.0e-3f

/* 4-lane float vectors: GCC/Clang vector extension on targets with 128-bit SIMD (SSE2,
 * NEON); other compilers and targets (the Cortex-M7: the extension would be lowered to 4x
 * scalar code at twice the flash) take the scalar loops, and so does a build with
 * -DSC_FEM_SCALAR, to check this claim: both do the same IEEE operations per lane in the
 * same order, so the results are bitwise identical. */
#if defined(__GNUC__) && !defined(SC_FEM_SCALAR) &&                                                \
    (defined(__SSE2__) || defined(__ARM_NEON) || defined(__aarch64__))
#define SC_FEM_VEC 1
typedef float sc_fem_v4 __attribute__((vector_size(16)));
static inline sc_fem_v4 v4_load(const float *p)
{
    sc_fem_v4 v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline void v4_store(float *p, sc_fem_v4 v)
{
    memcpy(p, &v, sizeof v);
}
/* The same for 16-byte aligned p (block rows and solver vector nodes: SC_ALIGN_HOT arrays of
 * 4-float rows): lets the compiler use aligned loads and fold them into the arithmetic. */
static inline sc_fem_v4 v4_load_a(const float *p)
{
    sc_fem_v4 v;
    memcpy(&v, __builtin_assume_aligned(p, 16), sizeof v);
    return v;
}
static inline void v4_store_a(float *p, sc_fem_v4 v)
{
    memcpy(__builtin_assume_aligned(p, 16), &v, sizeof v);
}
static inline sc_fem_v4 v4_splat(float x)
{
    const sc_fem_v4 v = {x, x, x, x};
    return v;
}
#endif

/* Element lanes: the corotated element work (deformation gradient, polar factor, stress,
 * rotated gradients) runs on SC_FEM_W tets at once, one tet per lane of sc_fem_vt: 4 with the
 * vector extension, 1 (plain float) elsewhere. The code is written once against the vt_
 * helpers; each lane does the same IEEE operations in the same order as a single-lane run,
 * so both builds give bitwise the same results (sqrt and division are exactly rounded per
 * lane, -ffp-contract=off keeps a * b + c unfused). Masks: all-ones / zero lanes (vector) or
 * 1 / 0 (scalar). */
#if defined(SC_FEM_VEC)
#define SC_FEM_W 4u
typedef sc_fem_v4 sc_fem_vt;
typedef int sc_fem_mt __attribute__((vector_size(16)));
static inline sc_fem_vt vt_splat(float x)
{
    return v4_splat(x);
}
static inline sc_fem_vt vt_load(const float *p)
{
    return v4_load(p);
}
static inline float vt_lane(sc_fem_vt v, uint32_t l)
{
    return v[l];
}
static inline sc_fem_vt vt_sqrt(sc_fem_vt v)
{
    const sc_fem_vt r = {sqrtf(v[0]), sqrtf(v[1]), sqrtf(v[2]), sqrtf(v[3])};
    return r;
}
static inline sc_fem_mt vt_gt(sc_fem_vt a, sc_fem_vt b)
{
    return a > b;
}
static inline sc_fem_mt vt_lt(sc_fem_vt a, sc_fem_vt b)
{
    return a < b;
}
static inline sc_fem_vt vt_select(sc_fem_mt m, sc_fem_vt a, sc_fem_vt b)
{
    return (sc_fem_vt)((m & (sc_fem_mt)a) | (~m & (sc_fem_mt)b));
}
static inline sc_fem_mt mt_and_not(sc_fem_mt a, sc_fem_mt b)
{
    return a & ~b;
}
static inline int mt_lane(sc_fem_mt m, uint32_t l)
{
    return m[l] != 0;
}
static inline int mt_any(sc_fem_mt m)
{
    return ((m[0] | m[1]) | (m[2] | m[3])) != 0;
}
#else
#define SC_FEM_W 1u
typedef float sc_fem_vt;
typedef int sc_fem_mt;
static inline sc_fem_vt vt_splat(float x)
{
    return x;
}
static inline sc_fem_vt vt_load(const float *p)
{
    return *p;
}
static inline float vt_lane(sc_fem_vt v, uint32_t l)
{
    (void)l;
    return v;
}
static inline sc_fem_vt vt_sqrt(sc_fem_vt v)
{
    return sqrtf(v);
}
static inline sc_fem_mt vt_gt(sc_fem_vt a, sc_fem_vt b)
{
    return a > b;
}
static inline sc_fem_mt vt_lt(sc_fem_vt a, sc_fem_vt b)
{
    return a < b;
}
static inline sc_fem_vt vt_select(sc_fem_mt m, sc_fem_vt a, sc_fem_vt b)
{
    return m ? a : b;
}
static inline sc_fem_mt mt_and_not(sc_fem_mt a, sc_fem_mt b)
{
    return a && !b;
}
static inline int mt_lane(sc_fem_mt m, uint32_t l)
{
    (void)l;
    return m != 0;
}
static inline int mt_any(sc_fem_mt m)
{
    return m != 0;
}
#endif
_Static_assert(SC_FEM_TET_LANES % SC_FEM_W == 0u, "element lanes must tile a tet group");

/* Lane l's 3-vector (a[l], b[l], c[l]) as 4 floats (4th 0) in out[l], l < SC_FEM_W: the
 * transpose between the element lanes and the 4-float rows of the blocks and vectors. */
static inline void vt_to_rows(sc_fem_vt a, sc_fem_vt b, sc_fem_vt c, float out[SC_FEM_W][4])
{
#if defined(SC_FEM_VEC)
    const sc_fem_v4 z = v4_splat(0.0f);
    const sc_fem_v4 t0 = __builtin_shufflevector(a, b, 0, 4, 1, 5); /* a0 b0 a1 b1 */
    const sc_fem_v4 t1 = __builtin_shufflevector(a, b, 2, 6, 3, 7); /* a2 b2 a3 b3 */
    const sc_fem_v4 t2 = __builtin_shufflevector(c, z, 0, 4, 1, 5); /* c0 0 c1 0 */
    const sc_fem_v4 t3 = __builtin_shufflevector(c, z, 2, 6, 3, 7); /* c2 0 c3 0 */
    v4_store(out[0], __builtin_shufflevector(t0, t2, 0, 1, 4, 5));
    v4_store(out[1], __builtin_shufflevector(t0, t2, 2, 3, 6, 7));
    v4_store(out[2], __builtin_shufflevector(t1, t3, 0, 1, 4, 5));
    v4_store(out[3], __builtin_shufflevector(t1, t3, 2, 3, 6, 7));
#else
    out[0][0] = a;
    out[0][1] = b;
    out[0][2] = c;
    out[0][3] = 0.0f;
#endif
}

/* The inverse: out[0..2] lane l = in[l][0..2], l < SC_FEM_W (rows of 4 floats). */
static inline void rows_to_vt(const float in[SC_FEM_W][4], sc_fem_vt out[3])
{
#if defined(SC_FEM_VEC)
    const sc_fem_v4 r0 = v4_load(in[0]), r1 = v4_load(in[1]);
    const sc_fem_v4 r2 = v4_load(in[2]), r3 = v4_load(in[3]);
    const sc_fem_v4 t0 = __builtin_shufflevector(r0, r1, 0, 4, 1, 5); /* x0 x1 y0 y1 */
    const sc_fem_v4 t1 = __builtin_shufflevector(r2, r3, 0, 4, 1, 5); /* x2 x3 y2 y3 */
    const sc_fem_v4 t2 = __builtin_shufflevector(r0, r1, 2, 6, 3, 7); /* z0 z1 w0 w1 */
    const sc_fem_v4 t3 = __builtin_shufflevector(r2, r3, 2, 6, 3, 7); /* z2 z3 w2 w3 */
    out[0] = __builtin_shufflevector(t0, t1, 0, 1, 4, 5);
    out[1] = __builtin_shufflevector(t0, t1, 2, 3, 6, 7);
    out[2] = __builtin_shufflevector(t2, t3, 0, 1, 4, 5);
#else
    out[0] = in[0][0];
    out[1] = in[0][1];
    out[2] = in[0][2];
#endif
}

/* dst += src over 4 floats (one block row or one node of a solver vector). */
static inline void add4(float *restrict dst, const float *restrict src)
{
#if defined(SC_FEM_VEC)
    v4_store(dst, v4_load(dst) + v4_load(src));
#else
    for (uint32_t k = 0; k < 4u; k++) {
        dst[k] += src[k];
    }
#endif
}

/* dst -= src over 4 floats. */
static inline void sub4(float *restrict dst, const float *restrict src)
{
#if defined(SC_FEM_VEC)
    v4_store(dst, v4_load(dst) - v4_load(src));
#else
    for (uint32_t k = 0; k < 4u; k++) {
        dst[k] -= src[k];
    }
#endif
}

sc_fem_def sc_fem_default_def(void)
{
    sc_fem_def d;
    d.rayleigh_beta_s = 0.1f; /* paper Algorithm 1: gamma = 0.1 k per spring */
    d.rayleigh_alpha_per_s = 0.0f;
    d.corotated = 0u;
    d.floor_volume_ratio = 0.01f;
    d.floor_pa = 100.0e3f;
    return d;
}

int sc_fem_def_validate(const sc_fem_def *def)
{
    if (def == NULL || def->corotated > 1u) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(def->rayleigh_beta_s) || !isfinite(def->rayleigh_alpha_per_s) ||
        !isfinite(def->floor_volume_ratio) || !isfinite(def->floor_pa)) {
        return SC_ERR_NOT_FINITE;
    }
    if (def->rayleigh_beta_s < 0.0f || def->rayleigh_alpha_per_s < 0.0f ||
        def->rayleigh_beta_s > 100.0f || def->rayleigh_alpha_per_s > 1.0e6f ||
        def->floor_volume_ratio < 0.0f || def->floor_volume_ratio > 0.5f || def->floor_pa < 0.0f) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* ---- small dense helpers ------------------------------------------------------------------ */

/* Rotation of the polar decomposition F = R S, lane-wise, by scaled Newton iteration
 * X <- (g X + X^-T / g) / 2, g = sqrt(|X^-1|_F / |X|_F) (Higham 1986), started from F. A lane
 * stops when its update falls below 1e-4 (|dX|_F^2 < 1e-8; quadratic convergence: the result
 * is then good to about 1e-8) or after SC_FEM_POLAR_MAX_ITER iterations; a stopped lane keeps
 * its X while the others go on, so a lane's result does not depend on the other lanes.
 * Lanes with det F <= SC_FEM_DET_MIN (flat or inverted element: no proper rotation) get
 * R = I and a zero in the returned mask. Bounded cost: at most SC_FEM_POLAR_MAX_ITER
 * iterations of ~100 lane operations. */
static sc_fem_mt polar_rotation_vt(const sc_fem_vt F[9], sc_fem_vt R[9])
{
    const sc_fem_vt det_f = F[0] * (F[4] * F[8] - F[5] * F[7]) +
                            F[1] * (F[5] * F[6] - F[3] * F[8]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
    const sc_fem_mt ok = vt_gt(det_f, vt_splat(SC_FEM_DET_MIN));
    sc_fem_vt x[9];
    for (uint32_t i = 0; i < 9u; i++) {
        x[i] = vt_select(ok, F[i], vt_splat((i % 4u == 0u) ? 1.0f : 0.0f));
    }
    sc_fem_mt active = ok;
    for (uint32_t it = 0; it < SC_FEM_POLAR_MAX_ITER && mt_any(active); it++) {
        sc_fem_vt c[9];
        c[0] = x[4] * x[8] - x[5] * x[7];
        c[1] = x[5] * x[6] - x[3] * x[8];
        c[2] = x[3] * x[7] - x[4] * x[6];
        c[3] = x[2] * x[7] - x[1] * x[8];
        c[4] = x[0] * x[8] - x[2] * x[6];
        c[5] = x[1] * x[6] - x[0] * x[7];
        c[6] = x[1] * x[5] - x[2] * x[4];
        c[7] = x[2] * x[3] - x[0] * x[5];
        c[8] = x[0] * x[4] - x[1] * x[3];
        const sc_fem_vt det = x[0] * c[0] + x[1] * c[1] + x[2] * c[2];
        sc_fem_vt nx2 = x[0] * x[0], nc2 = c[0] * c[0];
        for (uint32_t i = 1; i < 9u; i++) {
            nx2 += x[i] * x[i];
            nc2 += c[i] * c[i];
        }
        /* |X^-1|_F = |C|_F / det (det > 0 is kept by the iteration) */
        const sc_fem_vt g = vt_sqrt(vt_sqrt(nc2) / (det * vt_sqrt(nx2)));
        const sc_fem_vt a = vt_splat(0.5f) * g;
        const sc_fem_vt b = vt_splat(0.5f) / (g * det);
        sc_fem_vt diff2 = vt_splat(0.0f);
        for (uint32_t i = 0; i < 9u; i++) {
            const sc_fem_vt nv = a * x[i] + b * c[i];
            const sc_fem_vt d = nv - x[i];
            diff2 += d * d;
            x[i] = vt_select(active, nv, x[i]);
        }
        active = mt_and_not(active, vt_lt(diff2, vt_splat(1.0e-8f)));
    }
    for (uint32_t i = 0; i < 9u; i++) {
        R[i] = x[i];
    }
    return ok;
}

int sc_fem_polar_rotation(const float F[9], float R[9])
{
    SC_ASSERT(F != NULL && R != NULL);
    sc_fem_vt fv[9], rv[9];
    for (uint32_t i = 0; i < 9u; i++) {
        fv[i] = vt_splat(F[i]);
    }
    const sc_fem_mt ok = polar_rotation_vt(fv, rv);
    for (uint32_t i = 0; i < 9u; i++) {
        R[i] = vt_lane(rv[i], 0u);
    }
    return mt_lane(ok, 0u);
}

/* Entry k of tet e's rest data in the lane-grouped arrays (tet_dmi, tet_vol). */
#define SC_FEM_TET_AT(arr, e, k) ((arr)[(e) / SC_FEM_TET_LANES][k][(e) % SC_FEM_TET_LANES])

/* Shape gradients of tet e (n[0] = -(n1 + n2 + n3)), 1/mm. */
static void tet_grads(const sc_fem *f, uint32_t e, float n[4][4])
{
    for (uint32_t d = 0; d < 3u; d++) {
        n[1][d] = SC_FEM_TET_AT(f->tet_dmi, e, d);
        n[2][d] = SC_FEM_TET_AT(f->tet_dmi, e, 3u + d);
        n[3][d] = SC_FEM_TET_AT(f->tet_dmi, e, 6u + d);
        n[0][d] = -(n[1][d] + n[2][d] + n[3][d]);
    }
    for (uint32_t a = 0; a < 4u; a++) {
        n[a][3] = 0.0f;
    }
}

/* Add the element blocks built from the rest gradients g into the matrix (the corotated
 * blocks are built lane-wise in corotated_lanes). */
/* Unit rows: the scaled identity of a block is added as dd * k_eye[r] (exact: dd * 1 = dd and
 * x + dd * 0 = x), so that a block row is one straight 4-lane expression. */
static const float k_eye[3][4] = {
    {1.0f, 0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f, 0.0f}};

static void add_tet_blocks(sc_fem *f, const uint32_t tet[4], const uint32_t blk_idx[6],
                           const float g[4][4], float lam_v, float mu_v)
{
    /* diagonal blocks K_aa = (lambda + mu) V g_a g_a^T + mu V |g_a|^2 I; element (r, c) is
     * lm * (g[r] * g[c]): the product is commutative, so the block is exactly symmetric */
    const float lm = lam_v + mu_v;
    for (uint32_t a = 0; a < 4u; a++) {
        float *B = f->blk[f->row_start[tet[a]]]; /* the diagonal block leads its row */
        const float dd = mu_v * (g[a][0] * g[a][0] + g[a][1] * g[a][1] + g[a][2] * g[a][2]);
#if defined(SC_FEM_VEC)
        const sc_fem_v4 ga = v4_load(g[a]), vlm = v4_splat(lm), vdd = v4_splat(dd);
        for (uint32_t r = 0; r < 3u; r++) {
            const sc_fem_v4 row = vlm * (v4_splat(g[a][r]) * ga) + vdd * v4_load(k_eye[r]);
            v4_store(&B[4u * r], v4_load(&B[4u * r]) + row);
        }
#else
        for (uint32_t r = 0; r < 3u; r++) {
            for (uint32_t c = 0; c < 4u; c++) {
                B[4u * r + c] += lm * (g[a][r] * g[a][c]) + dd * k_eye[r][c];
            }
        }
#endif
    }
    for (uint32_t p = 0; p < 6u; p++) {
        /* the stored block is K_ab, or K_ba = K_ab^T: the same formula with a and b swapped */
        const uint32_t bi = blk_idx[p];
        const int tr = (bi & SC_FEM_BLK_TRANSPOSED) != 0u;
        const uint32_t a = tr ? k_pair_b[p] : k_pair_a[p];
        const uint32_t b = tr ? k_pair_a[p] : k_pair_b[p];
        const float dd = mu_v * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
        float *B = f->blk[bi & ~SC_FEM_BLK_TRANSPOSED];
        /* row r of K_ab: (lambda V g_a[r]) g_b + (mu V g_b[r]) g_a + dd e_r */
#if defined(SC_FEM_VEC)
        const sc_fem_v4 ga = v4_load(g[a]), gb = v4_load(g[b]), vdd = v4_splat(dd);
        for (uint32_t r = 0; r < 3u; r++) {
            const sc_fem_v4 row = (v4_splat(lam_v * g[a][r]) * gb + v4_splat(mu_v * g[b][r]) * ga) +
                                  vdd * v4_load(k_eye[r]);
            v4_store(&B[4u * r], v4_load(&B[4u * r]) + row);
        }
#else
        for (uint32_t r = 0; r < 3u; r++) {
            const float la = lam_v * g[a][r], mb = mu_v * g[b][r];
            for (uint32_t c = 0; c < 4u; c++) {
                B[4u * r + c] += (la * g[b][c] + mb * g[a][c]) + dd * k_eye[r][c];
            }
        }
#endif
    }
}

static void zero_floats(float *p, uint32_t count)
{
    for (uint32_t i = 0; i < count; i++) {
        p[i] = 0.0f;
    }
}

/* Rest stiffness K (R = I). O(T). */
static void assemble_rest(sc_fem *f, const sc_mesh *m)
{
    zero_floats(&f->blk[0][0], SC_FEM_BLK_FLOATS * f->nnz_blocks);
    for (uint32_t e = 0; e < f->tet_count; e++) {
        float n[4][4];
        tet_grads(f, e, n);
        const uint8_t lab = m->tet_label[e];
        const float vol = SC_FEM_TET_AT(f->tet_vol, e, 0u);
        add_tet_blocks(f, m->tet[e], f->tet_blk[e], n, f->lambda_nmm2[lab] * vol,
                       f->mu_nmm2[lab] * vol);
    }
    f->matrix_is_rest = 1u;
}

/* Corotated element work of the lanes' tets e0 .. e0 + SC_FEM_W - 1 (lanes past the last tet
 * compute on zero rest data and are not scattered). Per tet, with F = Ds Dm^-1, R = polar(F),
 * rotated gradients g_a = R n_a and the element's share of the residual
 *   dt f_int + ck K v0 = R Q n_a,  Q = V sigma(E),  E = R^T (dt F + ck L) - dt I,
 * where L = Dv Dm^-1 is the velocity gradient of v0 and sigma(E) = lambda tr(E) I +
 * mu (E + E^T): the elastic force V R sigma(sym(R^T F) - I) n_a and the warped stiffness
 * times v0, V R sigma(R^T L) R^T g_a (sigma is isotropic), are one linear stress of one
 * combined strain, so the r0 mat-vec of the step is folded into the assembly. Vertex 0's
 * terms are minus the sum of the others' (n_0 = -(n_1 + n_2 + n_3)): the element's forces
 * balance by construction.
 * Scatters the blocks into blk and -R Q n_a into r3; returns the flat/inverted count. */
static uint32_t corotated_lanes(sc_fem *f, const sc_mesh *m, uint32_t e0, float dt, float ck,
                                float *restrict r3)
{
    const uint32_t nt = f->tet_count;
    const float *x3 = f->x3;
    const float *v3 = f->v3;
    /* edge vectors ds[k] = x_{k+1} - x_0 and y[k] = dt ds[k] + ck (v_{k+1} - v_0): per lane as
     * 4-float rows (one node is one 16-byte load), then transposed to lanes */
    float dsl[3][SC_FEM_W][4], yl[3][SC_FEM_W][4], laml[SC_FEM_W], mul[SC_FEM_W];
    for (uint32_t l = 0; l < SC_FEM_W; l++) {
        const uint32_t e = (e0 + l < nt) ? e0 + l : e0;
        const uint32_t *t = m->tet[e];
        const float *p0 = &x3[4u * t[0]], *w0 = &v3[4u * t[0]];
        for (uint32_t k = 0; k < 3u; k++) {
            const float *pk = &x3[4u * t[k + 1u]], *wk = &v3[4u * t[k + 1u]];
#if defined(SC_FEM_VEC)
            const sc_fem_v4 dx = v4_load(pk) - v4_load(p0);
            v4_store(dsl[k][l], dx);
            v4_store(yl[k][l], v4_splat(dt) * dx + v4_splat(ck) * (v4_load(wk) - v4_load(w0)));
#else
            for (uint32_t d = 0; d < 4u; d++) {
                const float dx = pk[d] - p0[d];
                dsl[k][l][d] = dx;
                yl[k][l][d] = dt * dx + ck * (wk[d] - w0[d]);
            }
#endif
        }
        const uint8_t lab = m->tet_label[e];
        laml[l] = f->lambda_nmm2[lab];
        mul[l] = f->mu_nmm2[lab];
    }
    sc_fem_vt dmi[9], ds[3][3], y[3][3];
    for (uint32_t k = 0; k < 9u; k++) {
        dmi[k] = vt_load(&SC_FEM_TET_AT(f->tet_dmi, e0, k));
    }
    for (uint32_t k = 0; k < 3u; k++) {
        rows_to_vt(dsl[k], ds[k]);
        rows_to_vt(yl[k], y[k]);
    }
    const sc_fem_vt vol = vt_load(&SC_FEM_TET_AT(f->tet_vol, e0, 0u));
    const sc_fem_vt lamv = vt_load(laml) * vol, muv = vt_load(mul) * vol;
    /* F = Ds Dm^-1 and Y Dm^-1 = dt F + ck L (rows of Dm^-1: n_1, n_2, n_3) */
    sc_fem_vt F[9], My[9];
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t c = 0; c < 3u; c++) {
            F[3u * r + c] = ds[0][r] * dmi[c] + ds[1][r] * dmi[3u + c] + ds[2][r] * dmi[6u + c];
            My[3u * r + c] = y[0][r] * dmi[c] + y[1][r] * dmi[3u + c] + y[2][r] * dmi[6u + c];
        }
    }
    sc_fem_vt R[9];
    const sc_fem_mt ok = polar_rotation_vt(F, R);
    /* E = R^T My - dt I; Q = lambda V tr(E) I + mu V (E + E^T) */
    sc_fem_vt E[9];
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t c = 0; c < 3u; c++) {
            E[3u * r + c] = R[r] * My[c] + R[3u + r] * My[3u + c] + R[6u + r] * My[6u + c];
        }
    }
    const sc_fem_vt vdt = vt_splat(dt);
    const sc_fem_vt tr = ((E[0] - vdt) + (E[4] - vdt)) + (E[8] - vdt);
    sc_fem_vt Q[9];
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t c = r; c < 3u; c++) {
            Q[3u * r + c] = muv * (E[3u * r + c] + E[3u * c + r]);
            Q[3u * c + r] = Q[3u * r + c];
        }
        Q[4u * r] = muv * ((E[4u * r] - vdt) + (E[4u * r] - vdt)) + lamv * tr;
    }
    /* per vertex k = 1..3: g_k = R n_k, h_k = R (Q n_k); vertex 0 takes minus their sum */
    sc_fem_vt g[4][3], h[4][3];
    for (uint32_t k = 1; k < 4u; k++) {
        const sc_fem_vt *n = &dmi[3u * (k - 1u)];
        sc_fem_vt qn[3];
        for (uint32_t r = 0; r < 3u; r++) {
            qn[r] = Q[3u * r] * n[0] + Q[3u * r + 1u] * n[1] + Q[3u * r + 2u] * n[2];
        }
        for (uint32_t r = 0; r < 3u; r++) {
            g[k][r] = R[3u * r] * n[0] + R[3u * r + 1u] * n[1] + R[3u * r + 2u] * n[2];
            h[k][r] = R[3u * r] * qn[0] + R[3u * r + 1u] * qn[1] + R[3u * r + 2u] * qn[2];
        }
    }
    for (uint32_t r = 0; r < 3u; r++) {
        g[0][r] = -((g[1][r] + g[2][r]) + g[3][r]);
        h[0][r] = -((h[1][r] + h[2][r]) + h[3][r]);
    }
    /* Element blocks, lane-wise, then added lane by lane (3 rows of 4 floats per block):
     *   K_aa = (lambda + mu) V g_a g_a^T + mu V |g_a|^2 I   (element (r, c) is lm (g_a[r] g_a[c]):
     *          commutative, so the block is exactly symmetric)
     *   K_ab = lambda V g_a g_b^T + mu V g_b g_a^T + mu V (g_a . g_b) I; where the stored block is
     *          K_ba = K_ab^T (SC_FEM_BLK_TRANSPOSED), the same with lambda and mu swapped. */
    const uint32_t lanes = (nt - e0 < SC_FEM_W) ? nt - e0 : SC_FEM_W;
    uint32_t bidx[10][SC_FEM_W];
    int trl[6][SC_FEM_W];
    uint32_t degenerate = 0;
    for (uint32_t l = 0; l < SC_FEM_W; l++) {
        const uint32_t e = (l < lanes) ? e0 + l : e0;
        for (uint32_t a = 0; a < 4u; a++) {
            bidx[a][l] = f->row_start[m->tet[e][a]]; /* the diagonal block leads its row */
        }
        for (uint32_t p = 0; p < 6u; p++) {
            const uint32_t bi = f->tet_blk[e][p];
            bidx[4u + p][l] = bi & ~SC_FEM_BLK_TRANSPOSED;
            trl[p][l] = (bi & SC_FEM_BLK_TRANSPOSED) != 0u;
        }
        degenerate += (l < lanes && !mt_lane(ok, l)) ? 1u : 0u;
    }
    const sc_fem_vt lm = lamv + muv;
    float rows[10][3][SC_FEM_W][4]; /* block b's row r for lane l: rows[b][r][l] */
    for (uint32_t a = 0; a < 4u; a++) {
        const sc_fem_vt *ga = g[a];
        const sc_fem_vt dd = muv * ((ga[0] * ga[0] + ga[1] * ga[1]) + ga[2] * ga[2]);
        sc_fem_vt kb[9];
        for (uint32_t r = 0; r < 3u; r++) {
            for (uint32_t c = r; c < 3u; c++) {
                kb[3u * r + c] = lm * (ga[r] * ga[c]);
                kb[3u * c + r] = kb[3u * r + c];
            }
            kb[4u * r] += dd;
        }
        for (uint32_t r = 0; r < 3u; r++) {
            vt_to_rows(kb[3u * r], kb[3u * r + 1u], kb[3u * r + 2u], rows[a][r]);
        }
    }
    for (uint32_t p = 0; p < 6u; p++) {
        const sc_fem_vt *ga = g[k_pair_a[p]], *gb = g[k_pair_b[p]];
        sc_fem_mt trm;
#if defined(SC_FEM_VEC)
        memcpy(&trm, trl[p], sizeof trm);
        trm = -trm; /* 1 -> all ones */
#else
        trm = trl[p][0];
#endif
        const sc_fem_vt c1 = vt_select(trm, muv, lamv), c2 = vt_select(trm, lamv, muv);
        const sc_fem_vt dd = muv * ((ga[0] * gb[0] + ga[1] * gb[1]) + ga[2] * gb[2]);
        sc_fem_vt kb[9];
        for (uint32_t r = 0; r < 3u; r++) {
            const sc_fem_vt ar = c1 * ga[r], br = c2 * gb[r];
            for (uint32_t c = 0; c < 3u; c++) {
                kb[3u * r + c] = ar * gb[c] + br * ga[c];
            }
            kb[4u * r] += dd;
        }
        for (uint32_t r = 0; r < 3u; r++) {
            vt_to_rows(kb[3u * r], kb[3u * r + 1u], kb[3u * r + 2u], rows[4u + p][r]);
        }
    }
    float hr[4][SC_FEM_W][4];
    for (uint32_t a = 0; a < 4u; a++) {
        vt_to_rows(h[a][0], h[a][1], h[a][2], hr[a]);
    }
    /* tet by tet, in the order of a one-lane build (a block or node shared by two tets of
     * the lanes then receives their terms in the same order: bitwise the same sums) */
    for (uint32_t l = 0; l < lanes; l++) {
        for (uint32_t b = 0; b < 10u; b++) {
            float *B = f->blk[bidx[b][l]];
            for (uint32_t r = 0; r < 3u; r++) {
                add4(&B[4u * r], rows[b][r][l]);
            }
        }
        const uint32_t *t = m->tet[e0 + l];
        for (uint32_t a = 0; a < 4u; a++) {
            sub4(&r3[4u * t[a]], hr[a][l]);
        }
    }
    return degenerate;
}

/* Corotated: the warped K into blk, and r3 -= dt f_int(x) + ck K v0 (see corotated_lanes).
 * O(T). */
static void assemble_corotated(sc_fem *f, const sc_mesh *m, float dt, float ck, float *restrict r3)
{
    zero_floats(&f->blk[0][0], SC_FEM_BLK_FLOATS * f->nnz_blocks);
    uint32_t degenerate = 0;
    for (uint32_t e0 = 0; e0 < f->tet_count; e0 += SC_FEM_W) {
        degenerate += corotated_lanes(f, m, e0, dt, ck, r3);
    }
    f->stats.degenerate_tets = degenerate;
    f->matrix_is_rest = 0u;
}

/* q = cm M p + ck K p over the symmetric block CSR (upper triangle stored: each row is its
 * diagonal block, then the blocks (i, j > i); block (i, j) also acts as (j, i)^T). Vectors and
 * block rows have 4 lanes (the 4th is 0): per block 3 row loads, one load of p_j and one
 * load/store of q_j, 6 SIMD multiplies and 6 adds. Row i's products B p_j are accumulated
 * lane-wise and summed once at the end of the row. O(B). */
static void matvec(const sc_fem *f, const float *restrict p, float *restrict q, float cm, float ck)
{
    const uint32_t nn = f->node_count;
    const uint32_t *rs = f->row_start;
    const uint32_t *col = f->col;
    for (uint32_t i = 0; i < nn; i++) {
        const float mi = cm * f->mass[i];
#if defined(SC_FEM_VEC)
        v4_store_a(&q[4u * i], v4_splat(mi) * v4_load_a(&p[4u * i]));
#else
        for (uint32_t k = 0; k < 4u; k++) {
            q[4u * i + k] = mi * p[4u * i + k];
        }
#endif
    }
    for (uint32_t i = 0; i < nn; i++) {
        const uint32_t beg = rs[i], end = rs[i + 1u];
        const float *pi = &p[4u * i];
        const float *D = f->blk[beg];
        const float ci0 = ck * pi[0], ci1 = ck * pi[1], ci2 = ck * pi[2];
#if defined(SC_FEM_VEC)
        const sc_fem_v4 vpi = v4_load_a(pi);
        const sc_fem_v4 c0 = v4_splat(ci0), c1 = v4_splat(ci1), c2 = v4_splat(ci2);
        sc_fem_v4 a0 = v4_load_a(D) * vpi;
        sc_fem_v4 a1 = v4_load_a(D + 4) * vpi;
        sc_fem_v4 a2 = v4_load_a(D + 8) * vpi;
#pragma GCC unroll 2
        for (uint32_t b = beg + 1u; b < end; b++) {
            const float *B = f->blk[b];
            const uint32_t j4 = 4u * col[b];
            const sc_fem_v4 b0 = v4_load_a(B), b1 = v4_load_a(B + 4), b2 = v4_load_a(B + 8);
            const sc_fem_v4 pj = v4_load_a(&p[j4]);
            a0 += b0 * pj;
            a1 += b1 * pj;
            a2 += b2 * pj;
            v4_store_a(&q[j4], v4_load_a(&q[j4]) + ((b0 * c0 + b1 * c1) + b2 * c2));
        }
        /* the three row sums (a_k[0] + a_k[1]) + (a_k[2] + a_k[3]) at once: transpose
         * (a0, a1, a2, 0) and add the columns in that order (the scalar path's sums) */
        const sc_fem_v4 z = v4_splat(0.0f);
        const sc_fem_v4 t0 = __builtin_shufflevector(a0, a1, 0, 4, 1, 5); /* a00 a10 a01 a11 */
        const sc_fem_v4 t1 = __builtin_shufflevector(a0, a1, 2, 6, 3, 7); /* a02 a12 a03 a13 */
        const sc_fem_v4 t2 = __builtin_shufflevector(a2, z, 0, 4, 1, 5);  /* a20 0 a21 0 */
        const sc_fem_v4 t3 = __builtin_shufflevector(a2, z, 2, 6, 3, 7);  /* a22 0 a23 0 */
        const sc_fem_v4 sum = (__builtin_shufflevector(t0, t2, 0, 1, 4, 5) +
                               __builtin_shufflevector(t0, t2, 2, 3, 6, 7)) +
                              (__builtin_shufflevector(t1, t3, 0, 1, 4, 5) +
                               __builtin_shufflevector(t1, t3, 2, 3, 6, 7));
        v4_store_a(&q[4u * i], v4_load_a(&q[4u * i]) + v4_splat(ck) * sum); /* lane 3: + 0 */
#else
        float a0[4], a1[4], a2[4];
        for (uint32_t k = 0; k < 4u; k++) {
            a0[k] = D[k] * pi[k];
            a1[k] = D[4u + k] * pi[k];
            a2[k] = D[8u + k] * pi[k];
        }
        for (uint32_t b = beg + 1u; b < end; b++) {
            const float *B = f->blk[b];
            const uint32_t j4 = 4u * col[b];
            const float *pj = &p[j4];
            float *qj = &q[j4];
            for (uint32_t k = 0; k < 4u; k++) {
                a0[k] += B[k] * pj[k];
                a1[k] += B[4u + k] * pj[k];
                a2[k] += B[8u + k] * pj[k];
                qj[k] += (B[k] * ci0 + B[4u + k] * ci1) + B[8u + k] * ci2;
            }
        }
        const float s0 = (a0[0] + a0[1]) + (a0[2] + a0[3]);
        const float s1 = (a1[0] + a1[1]) + (a1[2] + a1[3]);
        const float s2 = (a2[0] + a2[1]) + (a2[2] + a2[3]);
        q[4u * i] += ck * s0;
        q[4u * i + 1u] += ck * s1;
        q[4u * i + 2u] += ck * s2;
#endif
    }
}

/* Dot product with 8 partial sums in a fixed order (deterministic; two 4-lane accumulators
 * with the vector extension, the same sums lane by lane as the scalar loop). */
static float dot(const float *restrict a, const float *restrict b, uint32_t count)
{
    float s[8] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    uint32_t i = 0;
#if defined(SC_FEM_VEC)
    sc_fem_v4 s0 = v4_splat(0.0f), s1 = v4_splat(0.0f);
    for (; i + 8u <= count; i += 8u) {
        s0 += v4_load(&a[i]) * v4_load(&b[i]);
        s1 += v4_load(&a[i + 4u]) * v4_load(&b[i + 4u]);
    }
    for (uint32_t k = 0; k < 4u; k++) {
        s[k] = s0[k];
        s[4u + k] = s1[k];
    }
#else
    for (; i + 8u <= count; i += 8u) {
        for (uint32_t k = 0; k < 8u; k++) {
            s[k] += a[i + k] * b[i + k];
        }
    }
#endif
    for (; i < count; i++) {
        s[0] += a[i] * b[i];
    }
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/* The CG update v += alpha p, r -= alpha q, z = inv r over count floats, returning r . z
 * summed exactly as dot(r, z, count) would (same partial sums, same order): one pass over
 * the vectors instead of two. */
static float cg_update(float *restrict v, float *restrict r, float *restrict z,
                       const float *restrict p, const float *restrict q, const float *restrict inv,
                       float alpha, uint32_t count)
{
    float s[8] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    uint32_t i = 0;
#if defined(SC_FEM_VEC)
    const sc_fem_v4 va = v4_splat(alpha);
    sc_fem_v4 s0 = v4_splat(0.0f), s1 = v4_splat(0.0f);
    for (; i + 8u <= count; i += 8u) {
        for (uint32_t h = 0; h < 8u; h += 4u) {
            v4_store_a(&v[i + h], v4_load_a(&v[i + h]) + va * v4_load_a(&p[i + h]));
            const sc_fem_v4 rv = v4_load_a(&r[i + h]) - va * v4_load_a(&q[i + h]);
            const sc_fem_v4 zv = v4_load_a(&inv[i + h]) * rv;
            v4_store_a(&r[i + h], rv);
            v4_store_a(&z[i + h], zv);
            if (h == 0u) {
                s0 += rv * zv;
            } else {
                s1 += rv * zv;
            }
        }
    }
    for (uint32_t k = 0; k < 4u; k++) {
        s[k] = s0[k];
        s[4u + k] = s1[k];
    }
#else
    for (; i + 8u <= count; i += 8u) {
        for (uint32_t k = 0; k < 8u; k++) {
            v[i + k] += alpha * p[i + k];
            r[i + k] -= alpha * q[i + k];
            z[i + k] = inv[i + k] * r[i + k];
            s[k] += r[i + k] * z[i + k];
        }
    }
#endif
    for (; i < count; i++) {
        v[i] += alpha * p[i];
        r[i] -= alpha * q[i];
        z[i] = inv[i] * r[i];
        s[0] += r[i] * z[i];
    }
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/* Floor term (sc_fem.h) of every tet below its floor volume: K_f / V0 grad V grad V^T into the
 * blocks and r3 -= dt f + ck K_f v0 (f_a = K_f (V - V_f) / V0 grad_a V). Returns the number
 * of tets below the floor. O(T). */
static uint32_t floor_pass(sc_fem *f, const sc_mesh *m, float dt, float ck, float *restrict r3)
{
    const float frac = f->def.floor_volume_ratio;
    const float kf = f->def.floor_pa * SC_FEM_PA_TO_NMM2;
    if (!(frac > 0.0f) || !(kf > 0.0f)) {
        return 0u;
    }
    const float *x3 = f->x3, *v3 = f->v3;
    uint32_t active = 0;
    for (uint32_t e = 0; e < f->tet_count; e++) {
        const uint32_t *t = m->tet[e];
        const float *p0 = &x3[4u * t[0]], *p1 = &x3[4u * t[1]], *p2 = &x3[4u * t[2]],
                    *p3 = &x3[4u * t[3]];
        const float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        const float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        const float e3[3] = {p3[0] - p0[0], p3[1] - p0[1], p3[2] - p0[2]};
        float g[4][3];
        g[1][0] = e2[1] * e3[2] - e2[2] * e3[1];
        g[1][1] = e2[2] * e3[0] - e2[0] * e3[2];
        g[1][2] = e2[0] * e3[1] - e2[1] * e3[0];
        const float vol = (e1[0] * g[1][0] + e1[1] * g[1][1] + e1[2] * g[1][2]) / 6.0f;
        const float v0 = SC_FEM_TET_AT(f->tet_vol, e, 0u);
        const float vf = frac * v0;
        if (!(vol < vf) || !(v0 > 0.0f)) {
            continue;
        }
        active++;
        g[2][0] = e3[1] * e1[2] - e3[2] * e1[1];
        g[2][1] = e3[2] * e1[0] - e3[0] * e1[2];
        g[2][2] = e3[0] * e1[1] - e3[1] * e1[0];
        g[3][0] = e1[1] * e2[2] - e1[2] * e2[1];
        g[3][1] = e1[2] * e2[0] - e1[0] * e2[2];
        g[3][2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (uint32_t q = 0; q < 3u; q++) {
            g[1][q] /= 6.0f; /* grad V */
            g[2][q] /= 6.0f;
            g[3][q] /= 6.0f;
            g[0][q] = -(g[1][q] + g[2][q] + g[3][q]);
        }
        const float c = kf / v0;
        float gv = 0.0f; /* grad V . v0 */
        for (uint32_t a = 0; a < 4u; a++) {
            const float *va = &v3[4u * t[a]];
            gv += g[a][0] * va[0] + g[a][1] * va[1] + g[a][2] * va[2];
        }
        const float fr = dt * c * (vol - vf) + ck * c * gv; /* times g_a */
        for (uint32_t a = 0; a < 4u; a++) {
            float *B = f->blk[f->row_start[t[a]]];
            for (uint32_t q = 0; q < 3u; q++) {
                r3[4u * t[a] + q] -= fr * g[a][q];
                for (uint32_t w = 0; w < 3u; w++) {
                    B[4u * q + w] += c * g[a][q] * g[a][w];
                }
            }
        }
        for (uint32_t p = 0; p < 6u; p++) {
            const uint32_t bi = f->tet_blk[e][p];
            const int tr = (bi & SC_FEM_BLK_TRANSPOSED) != 0u;
            const uint32_t a = tr ? k_pair_b[p] : k_pair_a[p];
            const uint32_t b = tr ? k_pair_a[p] : k_pair_b[p];
            float *B = f->blk[bi & ~SC_FEM_BLK_TRANSPOSED];
            for (uint32_t q = 0; q < 3u; q++) {
                for (uint32_t w = 0; w < 3u; w++) {
                    B[4u * q + w] += c * g[a][q] * g[b][w];
                }
            }
        }
    }
    return active;
}

/* Column code of the 27-stencil: (di + 1) + 3 (dj + 1) + 9 (dk + 1); -1 when not neighbours. */
static int32_t stencil_code(const sc_mesh *m, uint32_t a, uint32_t b)
{
    const int32_t ai = (int32_t)(a % m->nx), aj = (int32_t)((a / m->nx) % m->ny),
                  ak = (int32_t)(a / (m->nx * m->ny));
    const int32_t bi = (int32_t)(b % m->nx), bj = (int32_t)((b / m->nx) % m->ny),
                  bk = (int32_t)(b / (m->nx * m->ny));
    const int32_t di = bi - ai, dj = bj - aj, dk = bk - ak;
    if (di < -1 || di > 1 || dj < -1 || dj > 1 || dk < -1 || dk > 1) {
        return -1;
    }
    return (di + 1) + 3 * (dj + 1) + 9 * (dk + 1);
}

/* CSR index of block (a, b), or UINT32_MAX. O(log 27). */
static uint32_t find_block(const sc_fem *f, uint32_t a, uint32_t b)
{
    uint32_t lo = f->row_start[a], hi = f->row_start[a + 1u];
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2u;
        if (f->col[mid] < b) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return (lo < f->row_start[a + 1u] && f->col[lo] == b) ? lo : UINT32_MAX;
}

#ifdef SC_ENABLE_VALIDATE
/* Expensive invariant: every row starts with its diagonal block, then strictly increasing
 * columns above the diagonal. */
static int pattern_is_upper_sorted(const sc_fem *f)
{
    for (uint32_t i = 0; i < f->node_count; i++) {
        if (f->row_start[i] >= f->row_start[i + 1u] || f->col[f->row_start[i]] != i) {
            return 0;
        }
        for (uint32_t b = f->row_start[i] + 1u; b < f->row_start[i + 1u]; b++) {
            if (f->col[b] <= f->col[b - 1u]) {
                return 0;
            }
        }
    }
    return 1;
}
#endif

int sc_fem_init(sc_fem *f, const sc_mesh *m, const sc_material_table *mat, const sc_fem_def *def)
{
    if (f == NULL || m == NULL || mat == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    int rc = sc_fem_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    rc = sc_material_table_validate(mat);
    if (rc != SC_OK) {
        return rc;
    }
    const uint32_t mat_count = mat->count;
    if (m->node_count == 0u || m->node_count > SC_MAX_NODES || m->tet_count == 0u ||
        m->tet_count > SC_MAX_TETS || m->nx == 0u || m->ny == 0u ||
        m->nx * m->ny * m->nz != m->node_count) {
        return SC_ERR_INVALID_ARG;
    }
    for (uint32_t l = 0; l < mat_count; l++) {
        const sc_material *q = &mat->row[l];
        const float e = q->e_pa * SC_FEM_PA_TO_NMM2;
        const float nu = q->poisson;
        f->lambda_nmm2[l] = e * nu / ((1.0f + nu) * (1.0f - 2.0f * nu));
        f->mu_nmm2[l] = e / (2.0f * (1.0f + nu));
    }
    for (uint32_t l = mat_count; l < SC_MAX_LABELS; l++) {
        f->lambda_nmm2[l] = 0.0f;
        f->mu_nmm2[l] = 0.0f;
    }
    const uint32_t nn = m->node_count;
    const uint32_t nt = m->tet_count;
    for (uint32_t e = 0; e < nt; e++) {
        if (m->tet_label[e] >= mat_count) {
            return SC_ERR_CASE_LABEL;
        }
        for (uint32_t v = 0; v < 4u; v++) {
            if (m->tet[e][v] >= nn) {
                return SC_ERR_INVALID_ARG;
            }
        }
    }
    f->def = *def;
    f->node_count = nn;
    f->tet_count = nt;
    f->unstable = 0u;
    f->stats.cg_iterations_run = 0u;
    f->stats.residual_ratio = 0.0f;
    f->stats.degenerate_tets = 0u;
    f->stats.unstable_steps = 0u;

    /* Pattern: a 27-bit stencil mask per node (bit 13: itself; bits above: neighbours with a
     * larger index), kept in row_start until the rows are built. */
    for (uint32_t i = 0; i < nn; i++) {
        f->row_start[i] = 1u << 13;
        f->node_used[i] = 0u;
    }
    for (uint32_t e = 0; e < nt; e++) {
        const uint32_t *t = m->tet[e];
        for (uint32_t p = 0; p < 6u; p++) {
            uint32_t a = t[k_pair_a[p]], b = t[k_pair_b[p]];
            if (a > b) {
                const uint32_t tmp = a;
                a = b;
                b = tmp;
            }
            const int32_t code = stencil_code(m, a, b);
            if (code <= 13) { /* not neighbours (or a < b not above the diagonal) */
                return SC_ERR_FEM_PATTERN;
            }
            f->row_start[a] |= 1u << (uint32_t)code;
        }
        for (uint32_t v = 0; v < 4u; v++) {
            f->node_used[t[v]] = 1u;
        }
    }
    uint32_t nnz = 0;
    const int32_t sx = 1, sy = (int32_t)m->nx, sz = (int32_t)(m->nx * m->ny);
    for (uint32_t i = 0; i < nn; i++) {
        const uint32_t mask = f->row_start[i];
        f->row_start[i] = nnz;
        uint32_t prev = 0;
        for (uint32_t code = 0; code < 27u; code++) {
            if ((mask & (1u << code)) == 0u) {
                continue;
            }
            if (nnz >= SC_MAX_FEM_NNZ_BLOCKS) {
                return SC_ERR_FEM_PATTERN;
            }
            const int32_t di = (int32_t)(code % 3u) - 1, dj = (int32_t)((code / 3u) % 3u) - 1,
                          dk = (int32_t)(code / 9u) - 1;
            const uint32_t c = (uint32_t)((int32_t)i + di * sx + dj * sy + dk * sz);
            /* stencil order is column order for grid neighbours; checked */
            if (nnz > f->row_start[i] && c <= prev) {
                return SC_ERR_FEM_PATTERN;
            }
            prev = c;
            f->col[nnz] = c;
            nnz++;
        }
    }
    f->row_start[nn] = nnz;
    f->nnz_blocks = nnz;

    /* Per-tet rest data, block indices and lumped masses. */
    for (uint32_t i = 0; i < nn; i++) {
        f->mass[i] = 0.0f;
        f->rest3[4u * i] = m->rest_x[i];
        f->rest3[4u * i + 1u] = m->rest_y[i];
        f->rest3[4u * i + 2u] = m->rest_z[i];
        f->rest3[4u * i + 3u] = 0.0f;
    }
    /* lanes past the last tet in its group: zero rest data (computed on, never scattered) */
    for (uint32_t e = nt; e % SC_FEM_TET_LANES != 0u; e++) {
        for (uint32_t k = 0; k < 9u; k++) {
            SC_FEM_TET_AT(f->tet_dmi, e, k) = 0.0f;
        }
        SC_FEM_TET_AT(f->tet_vol, e, 0u) = 0.0f;
    }
    for (uint32_t e = 0; e < nt; e++) {
        const uint32_t *t = m->tet[e];
        float ed[3][3];
        for (uint32_t k = 0; k < 3u; k++) {
            ed[k][0] = m->rest_x[t[k + 1u]] - m->rest_x[t[0]];
            ed[k][1] = m->rest_y[t[k + 1u]] - m->rest_y[t[0]];
            ed[k][2] = m->rest_z[t[k + 1u]] - m->rest_z[t[0]];
        }
        /* rows of Dm^-1 (Dm = [e1 e2 e3]): (e2 x e3, e3 x e1, e1 x e2) / det */
        float cr[3][3];
        for (uint32_t k = 0; k < 3u; k++) {
            const float *u = ed[(k + 1u) % 3u], *w = ed[(k + 2u) % 3u];
            cr[k][0] = u[1] * w[2] - u[2] * w[1];
            cr[k][1] = u[2] * w[0] - u[0] * w[2];
            cr[k][2] = u[0] * w[1] - u[1] * w[0];
        }
        const float det = ed[0][0] * cr[0][0] + ed[0][1] * cr[0][1] + ed[0][2] * cr[0][2];
        if (!(det > 0.0f) || !isfinite(det)) {
            return SC_ERR_MESH_ORIENTATION;
        }
        for (uint32_t k = 0; k < 3u; k++) {
            for (uint32_t d = 0; d < 3u; d++) {
                SC_FEM_TET_AT(f->tet_dmi, e, 3u * k + d) = cr[k][d] / det;
            }
        }
        const float vol = det / 6.0f;
        SC_FEM_TET_AT(f->tet_vol, e, 0u) = vol;
        for (uint32_t p = 0; p < 6u; p++) {
            const uint32_t a = t[k_pair_a[p]], b = t[k_pair_b[p]];
            const uint32_t bi = (a < b) ? find_block(f, a, b) : find_block(f, b, a);
            SC_ASSERT(bi != UINT32_MAX); /* every tet edge is in the pattern by construction */
            f->tet_blk[e][p] = (a < b) ? bi : (bi | SC_FEM_BLK_TRANSPOSED);
        }
        const float mq =
            mat->row[m->tet_label[e]].density_kg_m3 * vol * SC_FEM_RHO_VOL_TO_MASS * 0.25f;
        for (uint32_t v = 0; v < 4u; v++) {
            f->mass[t[v]] += mq;
        }
    }
    assemble_rest(f, m);
    SC_VALIDATE(pattern_is_upper_sorted(f));
    return SC_OK;
}

void sc_fem_set_corotated(sc_fem *f, int on)
{
    SC_ASSERT(f != NULL);
    f->def.corotated = on ? 1u : 0u;
}

int sc_fem_status(const sc_fem *f)
{
    SC_ASSERT(f != NULL);
    return f->unstable ? SC_ERR_PHYS_UNSTABLE : SC_OK;
}

void sc_fem_step(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s, uint32_t cg_iterations)
{
    sc_fem_step_kinematic(f, m, n, dt_s, cg_iterations, NULL);
}

void sc_fem_step_kinematic(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                           uint32_t cg_iterations, const uint8_t *kinematic)
{
    sc_fem_step_custom(f, m, n, dt_s, cg_iterations, kinematic, NULL);
}

void sc_fem_step_custom(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                        uint32_t cg_iterations, const uint8_t *kinematic, const sc_fem_custom *cu)
{
    SC_ASSERT(f != NULL && m != NULL && n != NULL);
    SC_ASSERT(cu == NULL || (cu->assemble != NULL && isfinite(cu->beta_s) && cu->beta_s >= 0.0f &&
                             isfinite(cu->alpha_per_s) && cu->alpha_per_s >= 0.0f));
    SC_ASSERT(f->node_count == m->node_count && f->tet_count == m->tet_count);
    SC_ASSERT(isfinite(dt_s) && dt_s > 0.0f);
    SC_ASSERT(cg_iterations >= 1u && cg_iterations <= SC_PHYS_ITERATIONS_MAX);
    const uint32_t nn = f->node_count;
    const uint32_t n3 = 4u * nn; /* 4 lanes per node, the 4th stays 0 */
    float *restrict x3 = f->x3;
    float *restrict v3 = f->v3;
    float *restrict r3 = f->r3;
    float *restrict z3 = f->z3;
    float *restrict p3 = f->p3;
    float *restrict q3 = f->q3;
    float *restrict inv = f->inv_diag3;
    const float *restrict rest3 = f->rest3;
    const float *restrict mass = f->mass;

    /* Warm start v0 = v beta / (beta + dt): the exact one-step decay of an over-damped,
     * stiffness-damped mode (mass negligible: (beta + dt) K v+ = -K u). Modes that the
     * fixed-count CG leaves unconverged then keep relaxing; a plain v0 = v lets them coast on
     * a stale velocity, which overshoots and oscillates at 1-5 CG iterations. */
    const float damp_s = cu != NULL ? cu->beta_s : f->def.rayleigh_beta_s;
    const float alpha_per_s = cu != NULL ? cu->alpha_per_s : f->def.rayleigh_alpha_per_s;
    const float warm = damp_s / (damp_s + dt_s);
    const float cm = 1.0f + dt_s * alpha_per_s;
    const float ck = dt_s * damp_s + dt_s * dt_s;
    const float dta = dt_s * alpha_per_s;
    /* Gather the shared SoA state; Dirichlet DOFs: fixed (v = 0) and kinematic (v given). */
    for (uint32_t i = 0; i < nn; i++) {
        uint8_t con = 0u;
        const uint8_t fixed = m->node_fixed[i];
        if (fixed == SC_MESH_FIXED_ALL || f->node_used[i] == 0u) {
            con = 1u;
        } else if (kinematic != NULL && kinematic[i] != 0u) {
            con = 2u;
        } else if (fixed != 0u) {
            const uint32_t axes = SC_MESH_ROLLER_X | SC_MESH_ROLLER_Y | SC_MESH_ROLLER_Z;
            con = (uint8_t)(0x80u | (fixed & axes));
        }
        f->constrained[i] = con;
        x3[4u * i] = n->x[i];
        x3[4u * i + 1u] = n->y[i];
        x3[4u * i + 2u] = n->z[i];
        x3[4u * i + 3u] = 0.0f;
        const float keep = (con == 1u) ? 0.0f : (con == 2u) ? 1.0f : warm;
        /* rollers: the held axes have velocity 0 (bit 1 << (d + 1) of axis d) */
        v3[4u * i] = (con & SC_MESH_ROLLER_X) != 0u && con >= 0x80u ? 0.0f : keep * n->vx[i];
        v3[4u * i + 1u] = (con & SC_MESH_ROLLER_Y) != 0u && con >= 0x80u ? 0.0f : keep * n->vy[i];
        v3[4u * i + 2u] = (con & SC_MESH_ROLLER_Z) != 0u && con >= 0x80u ? 0.0f : keep * n->vz[i];
        v3[4u * i + 3u] = 0.0f;
        /* the node terms of r0 (below) */
        r3[4u * i] = dt_s * n->fx[i] - dta * mass[i] * v3[4u * i];
        r3[4u * i + 1u] = dt_s * n->fy[i] - dta * mass[i] * v3[4u * i + 1u];
        r3[4u * i + 2u] = dt_s * n->fz[i] - dta * mass[i] * v3[4u * i + 2u];
        r3[4u * i + 3u] = 0.0f;
    }

    /* r0 = b - A v0 with b = M v + dt (f_ext - f_int(x)) and v0 = v (warm start):
     *   r0 = dt f_ext - dt alpha M v0 - dt f_int(x) - ck K v0. */
    if (cu != NULL) {
        /* the caller's K(x) and dt f_int(x); then ck K v0 by one mat-vec */
        zero_floats(&f->blk[0][0], SC_FEM_BLK_FLOATS * f->nnz_blocks);
        cu->assemble(cu->ctx, f, dt_s, r3);
        f->matrix_is_rest = 0u;
        f->stats.degenerate_tets = 0u;
        for (uint32_t k = 0; k < n3; k++) {
            p3[k] = ck * v3[k];
        }
        matvec(f, p3, q3, 0.0f, 1.0f);
        for (uint32_t k = 0; k < n3; k++) {
            r3[k] -= q3[k];
        }
    } else if (f->def.corotated != 0u) {
        assemble_corotated(f, m, dt_s, ck, r3); /* element terms, with K v0 folded in */
    } else {
        if (f->matrix_is_rest == 0u) {
            assemble_rest(f, m);
        }
        f->stats.degenerate_tets = 0u;
        /* K (x - X) dt + ck K v0 = K (dt (x - X) + ck v0): one mat-vec */
        for (uint32_t k = 0; k < n3; k++) {
            p3[k] = dt_s * (x3[k] - rest3[k]) + ck * v3[k];
        }
        matvec(f, p3, q3, 0.0f, 1.0f);
        for (uint32_t k = 0; k < n3; k++) {
            r3[k] -= q3[k]; /* lane 3: 0 - 0 */
        }
    }
    if (cu == NULL && floor_pass(f, m, dt_s, ck, r3) != 0u) {
        f->matrix_is_rest = 0u; /* the floor blocks are in it: the next linear step re-assembles */
    }

    /* Jacobi preconditioner, zero on Dirichlet DOFs (projects the CG onto the free DOFs). */
    for (uint32_t i = 0; i < nn; i++) {
        const float *D = f->blk[f->row_start[i]];
        for (uint32_t d = 0; d < 3u; d++) {
            const float a = cm * mass[i] + ck * D[5u * d];
            const uint8_t con = f->constrained[i];
            const int free_dof = con == 0u || (con >= 0x80u && (con & (2u << d)) == 0u);
            inv[4u * i + d] = (free_dof && a > 0.0f) ? 1.0f / a : 0.0f;
        }
        inv[4u * i + 3u] = 0.0f;
    }

    for (uint32_t k = 0; k < n3; k++) {
        z3[k] = inv[k] * r3[k];
        p3[k] = z3[k];
    }
    float rz = dot(r3, z3, n3);
    const float rz0 = rz;
    uint32_t it = 0;
    for (; it < cg_iterations; it++) {
        if (!(rz > 0.0f)) {
            break; /* exactly converged (or no free DOF) */
        }
        matvec(f, p3, q3, cm, ck);
        const float pq = dot(p3, q3, n3);
        if (!(pq > 0.0f)) {
            break;
        }
        const float alpha = rz / pq;
        const float rz_new = cg_update(v3, r3, z3, p3, q3, inv, alpha, n3);
        const float gamma = rz_new / rz;
        for (uint32_t k = 0; k < n3; k++) {
            p3[k] = z3[k] + gamma * p3[k];
        }
        rz = rz_new;
    }
    f->stats.cg_iterations_run = it;
    f->stats.residual_ratio = (rz0 > 0.0f && rz >= 0.0f) ? sqrtf(rz / rz0) : 0.0f;

    /* Refuse a non-finite solution: the shared state stays as it was. */
    float vsum = 0.0f;
    for (uint32_t k = 0; k < n3; k++) {
        vsum += v3[k] * v3[k];
    }
    if (!isfinite(vsum)) {
        f->unstable = 1u;
        f->stats.unstable_steps++;
        return;
    }
    for (uint32_t i = 0; i < nn; i++) {
        n->vx[i] = v3[4u * i];
        n->vy[i] = v3[4u * i + 1u];
        n->vz[i] = v3[4u * i + 2u];
        n->x[i] = x3[4u * i] + dt_s * v3[4u * i];
        n->y[i] = x3[4u * i + 1u] + dt_s * v3[4u * i + 1u];
        n->z[i] = x3[4u * i + 2u] + dt_s * v3[4u * i + 2u];
    }
}
