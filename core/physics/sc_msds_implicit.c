/* sc_msds_implicit.c: backward Euler for the MSDS on the grid matrix; see
 * sc_msds_implicit.h. The springs' and the volume term's assembly is sc_grid_kern.inc's
 * msds_assemble (msds_springs and msds_cells). */
#include "sc_msds_implicit.h"

#include <math.h>
#include <stddef.h>

#include "sc_assert.h"
#include "sc_grid_kern.h"

void sc_msds_implicit_step(const sc_msds *s, sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                           uint32_t cg_iterations, const uint8_t *kinematic)
{
    SC_ASSERT(s != NULL && f != NULL && m != NULL && n != NULL);
    SC_ASSERT(s->node_count == m->node_count && f->node_count == m->node_count);
    SC_ASSERT(isfinite(dt_s) && dt_s > 0.0f);
    SC_ASSERT(cg_iterations >= 1u && cg_iterations <= SC_PHYS_ITERATIONS_MAX);
    const float beta = s->gamma_per_k_s, alpha = s->def.drag_per_s;
    const float ck = dt_s * beta + dt_s * dt_s;
    const sc_grid_kern *k = sc_grid_kern_selected();
    /* every edge and face block is written by the springs (a family's missing springs as
     * zeros): only the diagonal is zeroed; the FEM's rest K is gone */
    sc_grid_begin(&f->grid, m, n, dt_s, beta, alpha, kinematic);
    sc_grid_clear(&f->grid, SC_GRID_CLEAR_DIAG);
    f->rest_k = 0u;
    k->msds_assemble(&f->grid, s, dt_s, ck,
                     s->def.volume_stiffness_ratio > 0.0f ||
                         (s->def.floor_volume_ratio > 0.0f && s->def.floor_pa > 0.0f));
    f->stats.degenerate_tets = 0u;
    const int rc = sc_grid_solve(&f->grid, n, dt_s, beta, alpha, cg_iterations);
    f->stats.cg_iterations_run = f->grid.stats.cg_iterations_run;
    f->stats.residual_ratio = f->grid.stats.residual_ratio;
    if (rc != 0) {
        f->unstable = 1u;
        f->stats.unstable_steps++;
    }
}
