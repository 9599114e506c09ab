/* sc_fem.c: linear / corotated FEM on the grid matrix (sc_grid.h); see sc_fem.h.
 *
 * Element (linear tet, volume V, rest shape gradients n_a = grad N_a, a = 0..3):
 *   strain  eps = sym(grad u) = sym(sum_b u_b n_b^T),  stress sigma = lambda tr(eps) I + 2 mu eps
 *   force   f_a = -V sigma n_a
 *   block   K_ab = V (lambda n_a n_b^T + mu n_b n_a^T + mu (n_a . n_b) I),  K_ba = K_ab^T
 * Corotated: F = I + grad u, R = polar(F), eps = sym(R^T F) - I, f_a = -V R sigma n_a, and the
 * blocks use g_a = R n_a in place of n_a (that is R K_ab R^T). The element pass is
 * sc_grid_kern.inc's fem_cells.
 */
#include "sc_fem.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_grid_kern.h"

/* E in Pa -> N/mm^2; density kg/m^3 * mm^3 -> kg (1e-9) -> N s^2/mm (1e-3). */
#define SC_FEM_PA_TO_NMM2      1.0e-6f
#define SC_FEM_RHO_VOL_TO_MASS 1.0e-12f

#define SC_FEM_TET_ROW(q, a, b, c, d) {a, b, c, d},
static const uint8_t s_tets[5][4] = {SC_MESH_CELL_TETS(SC_FEM_TET_ROW)};
#undef SC_FEM_TET_ROW

sc_fem_def sc_fem_default_def(void)
{
    sc_fem_def d;
    d.rayleigh_beta_s = 0.1f; /* paper Algorithm 1: gamma = 0.1 k per spring */
    d.rayleigh_alpha_per_s = 0.0f;
    d.corotated = 0u;
    d.floor_volume_ratio = 0.01f;
    d.floor_pa = 100.0e3f;
    d.cg_iterations = SC_PHYS_CG_ITERATIONS_DEFAULT;
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
        def->floor_volume_ratio < 0.0f || def->floor_volume_ratio > 0.5f || def->floor_pa < 0.0f ||
        def->cg_iterations < 1u || def->cg_iterations > SC_PHYS_ITERATIONS_MAX) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* The template's rest shape gradients per cell parity (an odd cell's template corner c sits at
 * the real corner c ^ 1: mirrored in x), volumes and the sign of the template order's 6V. */
static void template_cells(sc_grid_fem_in *el, const float cell_mm[3])
{
    for (uint32_t p = 0; p < 2u; p++) {
        for (uint32_t q = 0; q < 5u; q++) {
            float pos[4][3];
            for (uint32_t a = 0; a < 4u; a++) {
                const uint32_t c = (uint32_t)s_tets[q][a] ^ p;
                for (uint32_t k = 0; k < 3u; k++) {
                    pos[a][k] = ((c >> k) & 1u) != 0u ? cell_mm[k] : 0.0f;
                }
            }
            float ed[3][3];
            for (uint32_t k = 0; k < 3u; k++) {
                for (uint32_t c = 0; c < 3u; c++) {
                    ed[k][c] = pos[k + 1u][c] - pos[0][c];
                }
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
            for (uint32_t k = 0; k < 3u; k++) {
                for (uint32_t c = 0; c < 3u; c++) {
                    el->grad[p][q][k + 1u][c] = cr[k][c] / det;
                }
            }
            for (uint32_t c = 0; c < 3u; c++) {
                el->grad[p][q][0][c] =
                    -((el->grad[p][q][1][c] + el->grad[p][q][2][c]) + el->grad[p][q][3][c]);
            }
            el->sign[p][q] = det > 0.0f ? 1.0f : -1.0f;
            el->vol_mm3[q] = fabsf(det) / 6.0f;
        }
    }
}

static void init_template(sc_fem *f, const sc_mesh *m)
{
    sc_grid_fem_in *el = &f->element;
    template_cells(el, m->cell_mm);
    el->floor_ratio = f->def.floor_volume_ratio;
    el->floor_nmm2 = f->def.floor_pa * SC_FEM_PA_TO_NMM2;
    el->floor_step_mm = fminf(m->cell_mm[0], fminf(m->cell_mm[1], m->cell_mm[2]));
    el->lamv = NULL;
    el->muv = NULL;
    el->corotated = 0;
}

/* the element data with this f's rows and model */
static sc_grid_fem_in element_in(const sc_fem *f, int corotated)
{
    sc_grid_fem_in in = f->element;
    in.lamv = &f->lamv[0][0];
    in.muv = &f->muv[0][0];
    in.corotated = corotated;
    in.floor_only = 0;
    return in;
}

#if SC_GRID_COARSE
/* The two-grid correction's coarse grid (sc_grid.h, sc_grid_coarse): layout and masses from the
 * fine grid, and the linear rest K of cells twice the size whose lambda and mu are the means
 * over the 8 fine cells each covers (the fine lamv, muv summed, over 8 cell volumes). The
 * same coarse K serves the MSDS, whose springs model the same E and nu. O(N). */
static int build_coarse(sc_fem *f, const sc_mesh *m)
{
    sc_grid_coarse *c = &f->coarse;
    const sc_grid *g = &f->grid;
    int rc = sc_grid_coarse_init(c, g, m->cell_mm);
    if (rc != SC_OK) {
        return rc;
    }
    sc_grid *gc = &c->grid;
    const float cell2[3] = {2.0f * m->cell_mm[0], 2.0f * m->cell_mm[1], 2.0f * m->cell_mm[2]};
    sc_grid_fem_in in;
    memset(&in, 0, sizeof in);
    template_cells(&in, cell2);
    float cell_vol = 0.0f;
    for (uint32_t q = 0; q < 5u; q++) {
        cell_vol += f->element.vol_mm3[q];
    }
    const uint32_t h = SC_GRID_HEAD, used = SC_GRID_HEAD + gc->node_end + SC_GRID_PAD;
    for (uint32_t q = 0; q < 5u; q++) {
        memset(c->lamv[q], 0, (size_t)used * sizeof(float));
        memset(c->muv[q], 0, (size_t)used * sizeof(float));
    }
    const uint32_t nx = g->nx, nxy = g->nxy;
    for (uint32_t t = 0; t < gc->node_count; t++) {
        if (gc->cell_ok[h + t] == 0) {
            continue;
        }
        const uint32_t a = t % gc->nx, b = (t / gc->nx) % gc->ny, k = t / gc->nxy;
        float sl = 0.0f, sm = 0.0f;
        for (uint32_t d = 0; d < 8u; d++) {
            const uint32_t tf = (2u * a + (d & 1u)) + nx * (2u * b + ((d >> 1) & 1u)) +
                                nxy * (2u * k + ((d >> 2) & 1u));
            for (uint32_t q = 0; q < 5u; q++) {
                sl += f->lamv[q][h + tf];
                sm += f->muv[q][h + tf];
            }
        }
        for (uint32_t q = 0; q < 5u; q++) {
            c->lamv[q][h + t] = sl / (8.0f * cell_vol) * in.vol_mm3[q];
            c->muv[q][h + t] = sm / (8.0f * cell_vol) * in.vol_mm3[q];
        }
    }
    for (uint32_t ax = 0; ax < 3u; ax++) {
        memcpy(gc->x[ax], gc->x0[ax], (size_t)used * sizeof(float));
    }
    in.lamv = &c->lamv[0][0];
    in.muv = &c->muv[0][0];
    in.floor_step_mm = fminf(cell2[0], fminf(cell2[1], cell2[2]));
    sc_grid_kern_selected()->fem_cells(gc, &in, 0.0f, 0.0f);
    return SC_OK;
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
    if (m->node_count == 0u || m->node_count > SC_MAX_NODES || m->tet_count == 0u ||
        m->tet_count > SC_MAX_TETS || m->nx < 2u || m->ny < 2u ||
        m->nx * m->ny * m->nz != m->node_count) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t nn = m->node_count, nt = m->tet_count;
    for (uint32_t e = 0; e < nt; e++) {
        if (m->tet_label[e] >= mat->count) {
            return SC_ERR_CASE_LABEL;
        }
        for (uint32_t v = 0; v < 4u; v++) {
            if (m->tet[e][v] >= nn) {
                return SC_ERR_INVALID_ARG;
            }
        }
    }
    rc = sc_grid_init(&f->grid, m);
    if (rc != SC_OK) {
        return rc == SC_ERR_INVALID_ARG ? SC_ERR_FEM_PATTERN : rc;
    }
    for (uint32_t l = 0; l < SC_MAX_LABELS; l++) {
        f->lambda_nmm2[l] = 0.0f;
        f->mu_nmm2[l] = 0.0f;
    }
    for (uint32_t l = 0; l < mat->count; l++) {
        const sc_material *q = &mat->row[l];
        const float e = q->e_pa * SC_FEM_PA_TO_NMM2;
        const float nu = q->poisson;
        f->lambda_nmm2[l] = e * nu / ((1.0f + nu) * (1.0f - 2.0f * nu));
        f->mu_nmm2[l] = e / (2.0f * (1.0f + nu));
    }
    f->def = *def;
    f->node_count = nn;
    f->tet_count = nt;
    f->unstable = 0u;
    memset(&f->stats, 0, sizeof f->stats);
    init_template(f, m);

    /* lambda V, mu V per cell and tet (0 where no cell is: the kernel computes on them), and
     * the lumped masses (density x volume / 4 per tet corner) */
    sc_grid *g = &f->grid;
    const uint32_t h = SC_GRID_HEAD, used = SC_GRID_HEAD + g->node_end + SC_GRID_PAD;
    for (uint32_t q = 0; q < 5u; q++) {
        memset(f->lamv[q], 0, (size_t)used * sizeof(float));
        memset(f->muv[q], 0, (size_t)used * sizeof(float));
    }
    const uint32_t nx = m->nx, ny = m->ny;
    for (uint32_t e = 0; e < nt; e++) {
        const uint32_t cube = e / 5u, q = e % 5u;
        const uint32_t ci = cube % (nx - 1u), cj = (cube / (nx - 1u)) % (ny - 1u),
                       ck = cube / ((nx - 1u) * (ny - 1u));
        const uint32_t t = ci + nx * (cj + ny * ck);
        const uint8_t lab = m->tet_label[e];
        const float vol = f->element.vol_mm3[q];
        f->lamv[q][h + t] = f->lambda_nmm2[lab] * vol;
        f->muv[q][h + t] = f->mu_nmm2[lab] * vol;
        const float mq = mat->row[lab].density_kg_m3 * vol * SC_FEM_RHO_VOL_TO_MASS * 0.25f;
        for (uint32_t v = 0; v < 4u; v++) {
            g->mass[h + m->tet[e][v]] += mq;
        }
    }
    /* the rest K (the linear model's matrix; sc_grid_block reads it; every step assembles its
     * own): the element pass at rest with dt = ck = 0 adds no residual */
    for (uint32_t c = 0; c < 3u; c++) {
        memcpy(g->x[c], g->x0[c], (size_t)used * sizeof(float));
    }
    const sc_grid_fem_in in = element_in(f, 0);
    sc_grid_kern_selected()->fem_cells(g, &in, 0.0f, 0.0f);
    f->rest_k = 1u;
    (void)sc_grid_save_rest(g); /* a big mesh keeps it aside (sc_grid.h) */
#if SC_GRID_COARSE
    if (nn > SC_GRID_COARSE_NODES && build_coarse(f, m) == SC_OK) {
        g->coarse = &f->coarse;
    }
#endif
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

/* the linear step's r0 loops over a range of sc_grid.range nodes */
typedef struct r0_job {
    sc_grid *g;
    float dt, ck;
} r0_job;

static void r0_span(const sc_grid *g, uint32_t r, uint32_t *i0, uint32_t *i1)
{
    const uint32_t h = SC_GRID_HEAD, end = h + g->node_end;
    *i0 = h + r * g->range;
    *i1 = *i0 + g->range < end ? *i0 + g->range : end;
}

/* p = dt (x - X) + ck v0 */
static void job_r0_p(void *arg, uint32_t r)
{
    const r0_job *j = (const r0_job *)arg;
    sc_grid *g = j->g;
    uint32_t i0, i1;
    r0_span(g, r, &i0, &i1);
    for (uint32_t c = 0; c < 3u; c++) {
        for (uint32_t i = i0; i < i1; i++) {
            g->p[c][i] = j->dt * (g->x[c][i] - g->x0[c][i]) + j->ck * g->v[c][i];
        }
    }
}

/* r -= q */
static void job_r0_r(void *arg, uint32_t r)
{
    const r0_job *j = (const r0_job *)arg;
    sc_grid *g = j->g;
    uint32_t i0, i1;
    r0_span(g, r, &i0, &i1);
    for (uint32_t c = 0; c < 3u; c++) {
        for (uint32_t i = i0; i < i1; i++) {
            g->r[c][i] -= g->q[c][i];
        }
    }
}

void sc_fem_step_kinematic(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                           uint32_t cg_iterations, const uint8_t *kinematic)
{
    SC_ASSERT(f != NULL && m != NULL && n != NULL);
    SC_ASSERT(f->node_count == m->node_count && f->tet_count == m->tet_count);
    SC_ASSERT(isfinite(dt_s) && dt_s > 0.0f);
    SC_ASSERT(cg_iterations >= 1u && cg_iterations <= SC_PHYS_ITERATIONS_MAX);
    const float beta = f->def.rayleigh_beta_s, alpha = f->def.rayleigh_alpha_per_s;
    const float ck = dt_s * beta + dt_s * dt_s;
    const sc_grid_kern *k = sc_grid_kern_selected();
    sc_grid *g = &f->grid;
    sc_grid_begin(g, m, n, dt_s, beta, alpha, kinematic);
    const int corotated = f->def.corotated != 0u;
    const sc_grid_fem_in in = element_in(f, corotated);
    uint32_t below = 0u;
    if (!corotated && (f->rest_k || g->rest_saved)) {
        below = k->fem_below(g, &in);
        if (!f->rest_k) {
            /* a big mesh: the rest K back from its copy (the last step left K + floor, or the
             * MSDS its own matrix) */
            (void)sc_grid_load_rest(g);
            f->rest_k = 1u;
        }
    }
    if (!corotated && f->rest_k && (below == 0u || g->rest_saved)) {
        /* linear, the rest K in place: r -= K (dt (x - X) + ck v0), one mat-vec; the
         * element-wise loops and the mat-vec on the pool (every node its own: the same bits) */
        r0_job j = {g, dt_s, ck};
        const uint32_t ranges = (g->node_end + g->range - 1u) / g->range;
        sc_pool_run(g->pool, job_r0_p, &j, ranges);
        k->matvec(g, 0.0f, 1.0f);
        sc_pool_run(g->pool, job_r0_r, &j, ranges);
        f->stats.degenerate_tets = 0u;
        if (below > 0u) {
            /* the floor's blocks and residual onto the rest K, cells with a tet below it only
             * (sc_grid.h, "rest K kept aside"); the grid then holds K + floor */
            sc_grid_fem_in fo = in;
            fo.floor_only = 1;
            (void)k->fem_cells(g, &fo, dt_s, ck);
            f->rest_k = 0u;
        }
    } else {
        sc_grid_clear(g, SC_GRID_CLEAR_DIAG | SC_GRID_CLEAR_BLOCKS);
        f->stats.degenerate_tets = k->fem_cells(g, &in, dt_s, ck);
        f->rest_k = (uint8_t)(!corotated && k->fem_below(g, &in) == 0u);
    }
    const int rc = sc_grid_solve(g, n, dt_s, beta, alpha, cg_iterations);
    f->stats.cg_iterations_run = f->grid.stats.cg_iterations_run;
    f->stats.residual_ratio = f->grid.stats.residual_ratio;
    if (rc != SC_OK) {
        f->unstable = 1u;
        f->stats.unstable_steps++;
    }
}

int sc_fem_polar_rotation(const float F[9], float R[9])
{
    SC_ASSERT(F != NULL && R != NULL);
    return sc_grid_kern_generic.polar(F, R);
}
