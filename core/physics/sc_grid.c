/* sc_grid.c: layout, step driver and reference helpers of the grid matrix; see sc_grid.h. The
 * hot loops (mat-vec, PCG, cell and spring assembly) are in sc_grid_kern.inc. */
#include "sc_grid.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_grid_kern.h"
#include "sc_grid_tmpl.h"
#include "sc_simd.h"

const sc_grid_kern *sc_grid_kern_selected(void)
{
    const sc_simd v = sc_simd_selected();
    (void)v;
#if defined(SC_SIMD_X86_64_V4_BUILT)
    if (v == SC_SIMD_X86_64_V4) {
        return &sc_grid_kern_x86_64_v4;
    }
#endif
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (v == SC_SIMD_X86_64_V3) {
        return &sc_grid_kern_x86_64_v3;
    }
#endif
    return &sc_grid_kern_generic;
}

/* the even template's tets (sc_mesh.h) */
#define SC_GRID_TET_ROW(q, a, b, c, d) {a, b, c, d},
static const uint8_t s_tets[5][4] = {SC_MESH_CELL_TETS(SC_GRID_TET_ROW)};
#undef SC_GRID_TET_ROW

static uint32_t bits(uint32_t c)
{
    return (c & 1u) + ((c >> 1) & 1u) + ((c >> 2) & 1u);
}

/* Edge slots of the template (corner pairs of its tets, a < b, in order of appearance). */
static void init_slots(sc_grid *g)
{
    memset(g->slot_of, -1, sizeof g->slot_of);
    uint32_t ns = 0;
    for (uint32_t q = 0; q < 5u; q++) {
        for (uint32_t i = 0; i < 4u; i++) {
            for (uint32_t j = i + 1u; j < 4u; j++) {
                const uint8_t a = s_tets[q][i] < s_tets[q][j] ? s_tets[q][i] : s_tets[q][j];
                const uint8_t b = s_tets[q][i] < s_tets[q][j] ? s_tets[q][j] : s_tets[q][i];
                if (g->slot_of[a][b] < 0) {
                    SC_ASSERT(ns < 18u);
                    g->slot[ns].a = a;
                    g->slot[ns].b = b;
                    g->slot_of[a][b] = (int8_t)ns;
                    g->slot_of[b][a] = (int8_t)ns;
                    ns++;
                }
            }
        }
    }
    SC_ASSERT(ns == 18u); /* 12 grid edges and 6 face diagonals */
    memset(g->corner_n, 0, sizeof g->corner_n);
    memset(g->slot_n, 0, sizeof g->slot_n);
    for (uint32_t q = 0; q < 5u; q++) {
        for (uint32_t i = 0; i < 4u; i++) {
            const uint8_t c = s_tets[q][i];
            SC_ASSERT(g->corner_n[c] < 4u);
            g->corner_tv[c][g->corner_n[c]][0] = (uint8_t)q;
            g->corner_tv[c][g->corner_n[c]][1] = (uint8_t)i;
            g->corner_n[c]++;
            for (uint32_t j = i + 1u; j < 4u; j++) {
                const uint8_t sl = (uint8_t)g->slot_of[s_tets[q][i]][s_tets[q][j]];
                const int first = s_tets[q][i] == g->slot[sl].a;
                SC_ASSERT(g->slot_n[sl] < 3u);
                uint8_t *tv = g->slot_tv[sl][g->slot_n[sl]];
                tv[0] = (uint8_t)q;
                tv[1] = (uint8_t)(first ? i : j);
                tv[2] = (uint8_t)(first ? j : i);
                g->slot_n[sl]++;
            }
        }
    }
}

/* Source slot and transposition of the stored block K(ra, rb) (real corners) in a cell of parity
 * p: the template corner c sits on the real corner c ^ p. */
static void edge_source(const sc_grid *g, uint32_t ra, uint32_t rb, uint32_t p, sc_grid_target *t)
{
    const uint32_t ta = ra ^ p, tb = rb ^ p;
    const int8_t s = g->slot_of[ta][tb];
    SC_ASSERT(s >= 0);
    t->src[p] = (uint8_t)s;
    t->tr[p] = (uint8_t)(g->slot[(uint8_t)s].a == ta ? 0u : 1u);
}

/* The 26 targets of a cell (sc_grid.h). */
static void init_targets(sc_grid *g)
{
    uint32_t nt = 0;
    for (uint32_t c = 0; c < 8u; c++) {
        sc_grid_target *t = &g->target[nt++];
        t->kind = 0u;
        t->axis = 0u;
        t->corner = (uint8_t)c;
        for (uint32_t p = 0; p < 2u; p++) {
            t->src[p] = (uint8_t)(c ^ p);
            t->tr[p] = 0u;
        }
    }
    for (uint32_t a = 0; a < 3u; a++) {
        const uint32_t ab = 1u << a;
        for (uint32_t c = 0; c < 8u; c++) {
            if ((c & ab) != 0u) {
                continue;
            }
            sc_grid_target *t = &g->target[nt++];
            t->kind = 1u;
            t->axis = (uint8_t)a;
            t->corner = (uint8_t)c;
            for (uint32_t p = 0; p < 2u; p++) {
                edge_source(g, c, c | ab, p, t);
            }
        }
    }
    /* planes: 0 x-y (fixed z), 1 x-z (fixed y), 2 y-z (fixed x) */
    static const uint8_t fixed_bit[3] = {4u, 2u, 1u};
    for (uint32_t w = 0; w < 3u; w++) {
        const uint32_t fb = fixed_bit[w];
        const uint32_t b1 = (w == 2u) ? 2u : 1u;            /* lower axis of the plane */
        const uint32_t b2 = (w == 0u) ? 2u : 4u;            /* upper axis */
        for (uint32_t side = 0; side < 2u; side++) {
            const uint32_t fo = side != 0u ? fb : 0u; /* lowest corner of the face */
            sc_grid_target *t = &g->target[nt++];
            t->kind = 2u;
            t->axis = (uint8_t)w;
            t->corner = (uint8_t)fo;
            for (uint32_t p = 0; p < 2u; p++) {
                /* the face's lowest node is odd iff p + bits(fo) is odd: then the diagonal is
                 * (fo, fo + b1 + b2) ("main"), else (fo + b1, fo + b2) */
                const uint32_t odd = (p + bits(fo)) & 1u;
                const uint32_t ra = odd ? fo : (fo | b1);
                const uint32_t rb = odd ? (fo | b1 | b2) : (fo | b2);
                edge_source(g, ra, rb, p, t);
            }
        }
    }
    SC_ASSERT(nt == SC_GRID_TARGETS);
}

static int same_node_set(const uint32_t a[4], const uint32_t b[4])
{
    for (uint32_t i = 0; i < 4u; i++) {
        int hit = 0;
        for (uint32_t j = 0; j < 4u; j++) {
            hit |= a[i] == b[j];
        }
        if (!hit) {
            return 0;
        }
    }
    return 1;
}

/* zero the used part of `rows` rows of the grid's row stride */
static void zero_rows(float *rows, uint32_t count, uint32_t used)
{
    for (uint32_t k = 0; k < count; k++) {
        memset(rows + (size_t)k * SC_GRID_ROW, 0, (size_t)used * sizeof(float));
    }
}

uint32_t sc_grid_asm_span(uint32_t nx, uint32_t ny, uint32_t nz)
{
    const uint32_t nxy = nx * ny, nn = nxy * nz;
    const uint32_t cells = nn - (1u + nx + nxy);
    const uint32_t cell_end = (cells + SC_GRID_CELL_BLOCK - 1u) / SC_GRID_CELL_BLOCK *
                              SC_GRID_CELL_BLOCK;
    /* the pool's split, by the mesh alone (sc_grid.h): up to two ranges of SC_GRID_ASM_SPAN and
     * one sum block the serial loops' sums, bigger meshes finer ranges for the workers */
    if (cell_end <= 2u * SC_GRID_ASM_SPAN) {
        return SC_GRID_ASM_SPAN;
    }
    const uint32_t apart = nxy + nx + SC_GRID_CELL_BLOCK + 1u;
    const uint32_t span = (apart + SC_GRID_CELL_BLOCK - 1u) / SC_GRID_CELL_BLOCK *
                          SC_GRID_CELL_BLOCK;
    uint32_t asm_span = span > SC_GRID_ASM_SPAN_MIN ? span : SC_GRID_ASM_SPAN_MIN;
    /* balance (sc_grid.h): the ranges' count down to a multiple of four, the span widened to
     * match, so that each phase has an even number of ranges (two workers take as many of each
     * phase's as the other: 11 per phase at 48x24x24 left one worker a range idle). A count
     * that is a multiple of four already keeps its span: re-cut, the span rounded to whole cell
     * blocks could come out narrower than the two-apart minimum above (52x26x26: 1,408 origins
     * against 1,421; 1,330 of the meshes within the limits tripped sc_grid_init's assert). */
    const uint32_t n = (cell_end + asm_span - 1u) / asm_span;
    if (n >= 8u && n % 4u != 0u) {
        const uint32_t want = n / 4u * 4u;
        const uint32_t wide = (cell_end + want - 1u) / want;
        asm_span = (wide + SC_GRID_CELL_BLOCK - 1u) / SC_GRID_CELL_BLOCK * SC_GRID_CELL_BLOCK;
    }
    return asm_span;
}

/* The node loops' ranges and the dot products' blocks (sc_grid.h): split, a multiple of four
 * ranges of about SC_GRID_POOL_RANGE nodes (whole chunks) and a block per range; else ranges of
 * SC_GRID_POOL_RANGE and one block of SC_GRID_SUM_BLOCK (the serial loop's sums). */
static void set_ranges(sc_grid *g, int split)
{
    g->range = SC_GRID_POOL_RANGE;
    g->sum_block = SC_GRID_SUM_BLOCK;
    if (split) {
        uint32_t count = (g->node_end + SC_GRID_POOL_RANGE - 1u) / SC_GRID_POOL_RANGE;
        count = (count + 3u) / 4u * 4u;
        const uint32_t size = (g->node_end + count - 1u) / count;
        g->range = (size + SC_GRID_CHUNK - 1u) / SC_GRID_CHUNK * SC_GRID_CHUNK;
        g->sum_block = g->range;
    }
    SC_ASSERT((g->node_end + g->range - 1u) / g->range <= SC_GRID_RANGES_MAX);
}

/* Everything of sc_grid_init but the rest positions and the cells' nodes: sizes, ranges,
 * templates, zeroed rows and masks (cell_ok, used and the rest positions are the caller's). */
static void init_layout(sc_grid *g, uint32_t nx, uint32_t ny, uint32_t nz, const float cell_mm[3])
{
    const uint32_t nxy = nx * ny, nn = nx * ny * nz;
    g->nx = nx;
    g->ny = ny;
    g->nz = nz;
    g->nxy = nxy;
    g->node_count = nn;
    g->node_end = (nn + SC_GRID_CHUNK - 1u) / SC_GRID_CHUNK * SC_GRID_CHUNK;
    for (uint32_t c = 0; c < 8u; c++) {
        g->off[c] = ((c & 1u) ? 1u : 0u) + ((c & 2u) ? nx : 0u) + ((c & 4u) ? nxy : 0u);
    }
    /* cell origins 0 .. nn - off[7] - 1 (the last plane, row and column have none) */
    const uint32_t cells = nn - g->off[7];
    g->cell_end = (cells + SC_GRID_CELL_BLOCK - 1u) / SC_GRID_CELL_BLOCK * SC_GRID_CELL_BLOCK;
    g->asm_span = sc_grid_asm_span(nx, ny, nz);
    SC_ASSERT(g->asm_span % SC_GRID_CELL_BLOCK == 0u &&
              g->asm_span > nxy + nx + SC_GRID_CELL_BLOCK &&
              (g->cell_end + g->asm_span - 1u) / g->asm_span <= SC_GRID_ASM_RANGES);
    set_ranges(g, g->node_end > SC_GRID_SUM_BLOCK);
    g->rest_saved = 0u;
    g->rest_patched = 0u;
    g->prefetch = (uint8_t)(nn > SC_GRID_PREFETCH_NODES);
    g->springs_fused = (uint8_t)(nn > SC_GRID_SPRINGS_FUSED_NODES);
    g->face_pairs = (uint8_t)(SC_GRID_PAIRS && nn <= SC_GRID_PAIRS_NODES);
    g->step_max_mm =
        2.0f * sqrtf(cell_mm[0] * cell_mm[0] + cell_mm[1] * cell_mm[1] + cell_mm[2] * cell_mm[2]);
    init_slots(g);
    init_targets(g);
    /* the kernels' constant tables are this derivation */
    for (uint32_t sl = 0; sl < 18u; sl++) {
        SC_ASSERT(g->slot[sl].a == sc_grid_tmpl_slot[sl][0] &&
                  g->slot[sl].b == sc_grid_tmpl_slot[sl][1] &&
                  g->slot_n[sl] == sc_grid_tmpl_slot_n[sl] &&
                  memcmp(g->slot_tv[sl], sc_grid_tmpl_slot_tv[sl], 3u * g->slot_n[sl]) == 0);
    }
    for (uint32_t c = 0; c < 8u; c++) {
        SC_ASSERT(g->corner_n[c] == sc_grid_tmpl_corner_n[c] &&
                  memcmp(g->corner_tv[c], sc_grid_tmpl_corner_tv[c], 2u * g->corner_n[c]) == 0);
    }
    for (uint32_t ti = 0; ti < SC_GRID_TARGETS; ti++) {
        const sc_grid_target *t = &g->target[ti];
        const uint8_t *k = sc_grid_tmpl_target[ti];
        SC_ASSERT(t->kind == k[0] && t->axis == k[1] && t->corner == k[2] && t->src[0] == k[3] &&
                  t->src[1] == k[4] && t->tr[0] == k[5] && t->tr[1] == k[6]);
        (void)t;
        (void)k;
    }
    /* write_cell's groups: every template entry in exactly one group (computed once) */
    for (uint32_t e = 0; e < 8u + 18u; e++) {
        uint32_t in = 0;
        for (uint32_t gi = 0; gi < SC_GRID_TMPL_GROUPS; gi++) {
            const uint8_t *gr = sc_grid_tmpl_group[gi];
            const uint32_t base = gr[0] == 0u ? 0u : 8u;
            in += (uint32_t)(e == base + gr[1]) + (uint32_t)(gr[2] != gr[1] && e == base + gr[2]);
        }
        SC_ASSERT(in == 1u);
        (void)in;
    }
    /* write_cell's walk (groups, then their targets, backwards; a target is written by the group
     * that holds its even source): each target once, its odd source in the same group, and
     * within a row family (kind and axis) the corner offsets descending, so a node's sums run
     * in cell order (sc_grid.h) */
    uint8_t order[SC_GRID_TARGETS], seen[SC_GRID_TARGETS] = {0};
    uint32_t no = 0;
    for (uint32_t gn = SC_GRID_TMPL_GROUPS; gn-- > 0u;) {
        const uint8_t *gr = sc_grid_tmpl_group[gn];
        for (uint32_t ti = SC_GRID_TARGETS; ti-- > 0u;) {
            const uint8_t *k = sc_grid_tmpl_target[ti];
            if ((k[0] == 0u) == (gr[0] == 0u) && (k[3] == gr[1] || k[3] == gr[2])) {
                SC_ASSERT(no < SC_GRID_TARGETS && seen[ti] == 0u &&
                          (k[4] == gr[1] || k[4] == gr[2]));
                seen[ti] = 1u;
                order[no++] = (uint8_t)ti;
            }
        }
    }
    SC_ASSERT(no == SC_GRID_TARGETS);
    for (uint32_t a = 0; a < no; a++) {
        for (uint32_t b = a + 1u; b < no; b++) {
            const uint8_t *ka = sc_grid_tmpl_target[order[a]], *kb = sc_grid_tmpl_target[order[b]];
            SC_ASSERT(ka[0] != kb[0] || ka[1] != kb[1] || g->off[ka[2]] > g->off[kb[2]]);
            (void)ka;
            (void)kb;
        }
    }
    /* write_cell's pairs: two targets naming each other, of one row family, the upper one (odd
     * corner) one node after the lower one and written first, with no other target of that
     * family between them in the walk */
    for (uint32_t a = 0; a < no; a++) {
        const uint32_t hi = order[a], lo = sc_grid_tmpl_pair[hi];
        if (lo == 0xffu) {
            continue;
        }
        SC_ASSERT(lo < SC_GRID_TARGETS && sc_grid_tmpl_pair[lo] == hi);
        const uint8_t *kh = sc_grid_tmpl_target[hi], *kl = sc_grid_tmpl_target[lo];
        SC_ASSERT(((kh[2] ^ kl[2]) & 1u) == 1u); /* one upper, one lower */
        if ((kh[2] & 1u) == 0u) {
            continue; /* the lower one: checked from its upper one */
        }
        SC_ASSERT(kh[0] == kl[0] && kh[1] == kl[1] && g->off[kh[2]] == g->off[kl[2]] + 1u);
        uint32_t b = a + 1u;
        while (b < no && (sc_grid_tmpl_target[order[b]][0] != kh[0] ||
                          sc_grid_tmpl_target[order[b]][1] != kh[1])) {
            b++;
        }
        SC_ASSERT(b < no && order[b] == lo);
        (void)kl;
    }
    memset(&g->stats, 0, sizeof g->stats);
    memset(g->below_n, 0, sizeof g->below_n);
    memset(g->floor_dirty, 0, sizeof g->floor_dirty);
    g->forces_vanish_at_rest = 0u;
    g->pool = NULL;

    /* every row is zero outside the mesh's nodes: the loops read and add there */
    const uint32_t used = SC_GRID_HEAD + g->node_end + SC_GRID_PAD;
    SC_ASSERT(used <= SC_GRID_ROW && g->cell_end + g->off[7] <= g->node_end + SC_GRID_PAD);
    zero_rows(&g->d[0][0], 6u, used);
    zero_rows(&g->e[0][0][0], 27u, used);
    zero_rows(&g->f[0][0][0], 27u, used);
    zero_rows(g->mass, 1u, used);
    zero_rows(&g->x[0][0], 3u, used);
    zero_rows(&g->x0[0][0], 3u, used);
    zero_rows(&g->v[0][0], 3u, used);
    zero_rows(&g->r[0][0], 3u, used);
    zero_rows(&g->z[0][0], 3u, used);
    zero_rows(&g->p[0][0], 3u, used);
    zero_rows(&g->q[0][0], 3u, used);
    zero_rows(&g->pc[0][0], 3u, used);
#if SC_GRID_PAIRS
    if (nn <= SC_GRID_PAIRS_NODES) {
        /* zero outside the packed pairs: the face sums by pair read there (sc_grid.h) */
        SC_ASSERT(SC_GRID_PHEAD + g->node_end / 2u + (nxy + nx + 1u) / 2u + 1u <= SC_GRID_PROW &&
                  (nxy + nx + 1u) / 2u + 1u <= SC_GRID_PHEAD);
        memset(g->fpair, 0, sizeof g->fpair);
        memset(g->ppair, 0, sizeof g->ppair);
    }
#endif
    memset(g->odd, 0, (size_t)used * sizeof(int32_t));
    memset(g->cell_odd, 0, (size_t)used * sizeof(int32_t));
    memset(g->cell_ok, 0, (size_t)used * sizeof(int32_t));
    memset(g->con, 1, (size_t)used); /* padding: held */
    memset(g->used, 0, nn);
    /* the node and cell parities, and which origins have a cell: the grid's sizes alone */
    const uint32_t h = SC_GRID_HEAD;
    for (uint32_t t = 0; t < nn; t++) {
        const uint32_t i = t % nx, j = (t / nx) % ny, k = t / nxy;
        const int32_t odd = ((i + j + k) & 1u) != 0u ? -1 : 0;
        g->odd[h + t] = odd;
        if (i + 1u < nx && j + 1u < ny && k + 1u < nz) {
            g->cell_ok[h + t] = -1;
            g->cell_odd[h + t] = odd;
        }
    }
#if SC_GRID_COARSE
    g->coarse = NULL;
#endif
}

int sc_grid_init(sc_grid *g, const sc_mesh *m)
{
    if (g == NULL || m == NULL || m->nx < 2u || m->ny < 2u || m->nz < 2u ||
        m->nx > SC_MAX_MESH_NX || m->ny > SC_MAX_MESH_NY || m->nz > SC_MAX_MESH_NZ ||
        m->node_count != m->nx * m->ny * m->nz ||
        m->tet_count != 5u * (m->nx - 1u) * (m->ny - 1u) * (m->nz - 1u)) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t nx = m->nx, ny = m->ny, nz = m->nz, nxy = nx * ny, nn = m->node_count;
    init_layout(g, nx, ny, nz, m->cell_mm);
    const uint32_t h = SC_GRID_HEAD;
    for (uint32_t t = 0; t < nn; t++) {
        const uint32_t i = t % nx, j = (t / nx) % ny, k = t / nxy;
        g->x0[0][h + t] = m->rest_x[t];
        g->x0[1][h + t] = m->rest_y[t];
        g->x0[2][h + t] = m->rest_z[t];
        if (g->cell_ok[h + t] != 0) {
            const uint32_t par = (i + j + k) & 1u;
            const uint32_t cube = i + (nx - 1u) * (j + (ny - 1u) * k);
            for (uint32_t q = 0; q < 5u; q++) {
                uint32_t v[4];
                for (uint32_t a = 0; a < 4u; a++) {
                    v[a] = t + g->off[s_tets[q][a] ^ par];
                }
                if (!same_node_set(v, m->tet[5u * cube + q])) {
                    return SC_ERR_INVALID_ARG; /* not the mesh of sc_mesh_build */
                }
                for (uint32_t a = 0; a < 4u; a++) {
                    g->used[v[a]] = 1u;
                }
            }
        }
    }
    return SC_OK;
}

static int nonzero(float v)
{
    return v < 0.0f || v > 0.0f;
}

/* 1 if the held DOFs (fixed nodes' and rollers' axes) pin every rigid motion of the mesh, so
 * that the rest state is the only unloaded equilibrium: the 6 rigid modes (translations, and
 * rotations about the box centre scaled by its size) restricted to the held DOFs are
 * independent (their 6x6 Gram matrix is positive definite, Cholesky pivots above 1e-9 of its
 * trace). O(N). */
static int rigid_motions_pinned(const sc_grid *g)
{
    const uint32_t nn = g->node_count, h = SC_GRID_HEAD;
    double c[3] = {0.0, 0.0, 0.0}, ext = 0.0;
    for (uint32_t k = 0; k < 3u; k++) {
        c[k] = 0.5 * ((double)g->x0[k][h] + (double)g->x0[k][h + nn - 1u]);
        ext = fmax(ext, fabs((double)g->x0[k][h + nn - 1u] - (double)g->x0[k][h]));
    }
    ext = ext > 0.0 ? ext : 1.0;
    double G[6][6];
    memset(G, 0, sizeof G);
    for (uint32_t i = 0; i < nn; i++) {
        const uint8_t con = g->con[h + i];
        if (con == 0u || con == 2u) {
            continue;
        }
        const double X[3] = {((double)g->x0[0][h + i] - c[0]) / ext,
                             ((double)g->x0[1][h + i] - c[1]) / ext,
                             ((double)g->x0[2][h + i] - c[2]) / ext};
        for (uint32_t a = 0; a < 3u; a++) {
            if (con != 1u && (con & (2u << a)) == 0u) {
                continue; /* a roller's free axis */
            }
            /* DOF a of the node under the 6 modes: e_a, and (w x X)_a for w = e_0, e_1, e_2 */
            double r[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            r[a] = 1.0;
            r[3u + (a + 1u) % 3u] = -X[(a + 2u) % 3u];
            r[3u + (a + 2u) % 3u] = X[(a + 1u) % 3u];
            for (uint32_t p = 0; p < 6u; p++) {
                for (uint32_t q = 0; q < 6u; q++) {
                    G[p][q] += r[p] * r[q];
                }
            }
        }
    }
    double tr = 0.0;
    for (uint32_t p = 0; p < 6u; p++) {
        tr += G[p][p];
    }
    for (uint32_t p = 0; p < 6u; p++) {
        for (uint32_t k = 0; k < p; k++) {
            G[p][p] -= G[p][k] * G[p][k];
        }
        if (!(G[p][p] > 1e-9 * tr)) {
            return 0;
        }
        const double d = sqrt(G[p][p]);
        G[p][p] = d;
        for (uint32_t q = p + 1u; q < 6u; q++) {
            for (uint32_t k = 0; k < p; k++) {
                G[q][p] -= G[q][k] * G[p][k];
            }
            G[q][p] /= d;
        }
    }
    return 1;
}

/* The step's node loops on the worker pool (sc_grid.h): ranges of sc_grid.range nodes,
 * every node's values its own (the serial loops' bits); the loaded test is an OR per range and
 * the solution's sum of squares is summed per sc_grid.sum_block nodes and added in block order
 * (one block up to 32x16x16: the serial sum). */
typedef struct step_job {
    sc_grid *g;
    const sc_mesh *m;
    const sc_nodes *n;
    sc_nodes *out;
    const uint8_t *kinematic;
    float dt, dta, warm, pull, cm, ck;
    int release;
    uint8_t loaded[SC_GRID_RANGES_MAX];
    uint32_t clamped[SC_GRID_RANGES_MAX];
    float vsum[SC_GRID_SUM_BLOCKS];
} step_job;

static uint32_t job_ranges(const sc_grid *g, uint32_t size)
{
    return (g->node_count + size - 1u) / size;
}

/* nodes [i0, i1) of range r of `size` nodes of g (the last one cut at the node count) */
static void node_span(const sc_grid *g, uint32_t r, uint32_t size, uint32_t *i0, uint32_t *i1)
{
    *i0 = r * size;
    *i1 = *i0 + size < g->node_count ? *i0 + size : g->node_count;
}

static void job_span(const step_job *j, uint32_t r, uint32_t size, uint32_t *i0, uint32_t *i1)
{
    node_span(j->g, r, size, i0, i1);
}

/* loaded: a kinematic node or an external force that does not vanish at rest */
static void job_loaded(void *arg, uint32_t r)
{
    step_job *j = (step_job *)arg;
    uint32_t i0, i1;
    job_span(j, r, j->g->range, &i0, &i1);
    const sc_nodes *n = j->n;
    int loaded = 0;
    for (uint32_t i = i0; i < i1 && !loaded; i++) {
        loaded = (j->kinematic != NULL && j->kinematic[i] != 0u) ||
                 (j->g->forces_vanish_at_rest == 0u &&
                  (nonzero(n->fx[i]) || nonzero(n->fy[i]) || nonzero(n->fz[i])));
    }
    j->loaded[r] = (uint8_t)loaded;
}

static void job_flags(void *arg, uint32_t r)
{
    step_job *j = (step_job *)arg;
    sc_grid *g = j->g;
    uint32_t i0, i1;
    job_span(j, r, j->g->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    for (uint32_t i = i0; i < i1; i++) {
        uint8_t con = 0u;
        const uint8_t fixed = j->m->node_fixed[i];
        if (fixed == SC_MESH_FIXED_ALL || g->used[i] == 0u) {
            con = 1u;
        } else if (j->kinematic != NULL && j->kinematic[i] != 0u) {
            con = 2u;
        } else if (fixed != 0u) {
            const uint32_t axes = SC_MESH_ROLLER_X | SC_MESH_ROLLER_Y | SC_MESH_ROLLER_Z;
            con = (uint8_t)(0x80u | (fixed & axes));
        }
        g->con[h + i] = con;
    }
}

static void job_start(void *arg, uint32_t r)
{
    step_job *j = (step_job *)arg;
    sc_grid *g = j->g;
    const sc_nodes *n = j->n;
    uint32_t i0, i1;
    job_span(j, r, j->g->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    const float *const nv[3] = {n->vx, n->vy, n->vz};
    const float *const nx[3] = {n->x, n->y, n->z};
    const float *const nf[3] = {n->fx, n->fy, n->fz};
    for (uint32_t i = i0; i < i1; i++) {
        const uint8_t con = g->con[h + i];
        for (uint32_t c = 0; c < 3u; c++) {
            const float xc = nx[c][i];
            g->x[c][h + i] = xc;
            float v0 = 0.0f;
            const int held = con == 1u || (con >= 0x80u && (con & (2u << c)) != 0u);
            if (con == 2u) {
                v0 = nv[c][i]; /* kinematic: moves with its velocity */
            } else if (!held) {
                v0 = j->release ? j->pull * (xc - g->x0[c][h + i]) : j->warm * nv[c][i];
            }
            g->v[c][h + i] = v0;
            g->r[c][h + i] = j->dt * nf[c][i] - j->dta * g->mass[h + i] * v0;
        }
    }
}

void sc_grid_begin(sc_grid *g, const sc_mesh *m, const sc_nodes *n, float dt_s, float beta_s,
                   float alpha_per_s, const uint8_t *kinematic)
{
    SC_ASSERT(g != NULL && m != NULL && n != NULL && g->node_count == m->node_count);
    SC_ASSERT(isfinite(dt_s) && dt_s > 0.0f && isfinite(beta_s) && beta_s >= 0.0f &&
              isfinite(alpha_per_s) && alpha_per_s >= 0.0f);
    step_job j;
    j.g = g;
    j.m = m;
    j.n = n;
    j.out = NULL;
    j.kinematic = kinematic;
    j.dt = dt_s;
    j.dta = dt_s * alpha_per_s;
    j.warm = beta_s / (beta_s + dt_s);
    j.pull = -1.0f / (beta_s + dt_s);
    j.cm = j.ck = 0.0f;
    const uint32_t ranges = job_ranges(g, g->range);
    /* unloaded: no kinematic node and no external force (the probe is off the skin); the release
     * warm start needs the rest state to be the only unloaded equilibrium (checked below, after
     * the flags) */
    sc_pool_run(g->pool, job_loaded, &j, ranges);
    int loaded = 0;
    for (uint32_t r = 0; r < ranges && r < SC_GRID_RANGES_MAX; r++) {
        loaded |= j.loaded[r];
    }
    sc_pool_run(g->pool, job_flags, &j, ranges);
    j.release = !loaded && rigid_motions_pinned(g);
    g->stats.unloaded_steps += j.release ? 1u : 0u;
    sc_pool_run(g->pool, job_start, &j, ranges);
}

/* The matrix rows' passes on the pool (sc_grid_clear, and the rest K's copy to and from
 * sc_grid.rest): the used part of the rows cut into ranges of SC_GRID_POOL_RANGE floats (each
 * float its own: any split gives the same bits; 60 rows of 262 KB each at 64x32x32 was a
 * serial 16 MB memset of the corotated step). which: SC_GRID_CLEAR_DIAG and/or
 * SC_GRID_CLEAR_BLOCKS, or ROWS_SAVE / ROWS_LOAD (every row, to / from the rest copy). */
#define ROWS_SAVE 4u
#define ROWS_LOAD 8u
typedef struct rows_job {
    sc_grid *g;
    uint32_t which, used;
} rows_job;

static void job_rows(void *arg, uint32_t r)
{
    const rows_job *j = (const rows_job *)arg;
    sc_grid *g = j->g;
    const uint32_t a = r * SC_GRID_POOL_RANGE;
    const uint32_t b = a + SC_GRID_POOL_RANGE < j->used ? a + SC_GRID_POOL_RANGE : j->used;
    const size_t bytes = (size_t)(b - a) * sizeof(float);
    if ((j->which & SC_GRID_CLEAR_DIAG) != 0u) {
        for (uint32_t k = 0; k < 6u; k++) {
            memset(&g->d[k][a], 0, bytes);
        }
    }
    if ((j->which & SC_GRID_CLEAR_BLOCKS) != 0u) {
        for (uint32_t k = 0; k < 27u; k++) {
            memset(&g->e[0][0][0] + (size_t)k * SC_GRID_ROW + a, 0, bytes);
            memset(&g->f[0][0][0] + (size_t)k * SC_GRID_ROW + a, 0, bytes);
        }
    }
#if SC_GRID_REST_COPY
    if ((j->which & (ROWS_SAVE | ROWS_LOAD)) != 0u) {
        float *mat = &g->d[0][0];
        for (uint32_t k = 0; k < SC_GRID_MAT_ROWS; k++) {
            float *m = mat + (size_t)k * SC_GRID_ROW + a, *s = &g->rest[k][a];
            if ((j->which & ROWS_SAVE) != 0u) {
                memcpy(s, m, bytes);
            } else {
                memcpy(m, s, bytes);
            }
        }
    }
#endif
}

static void rows_run(sc_grid *g, uint32_t which)
{
    rows_job j = {g, which, SC_GRID_HEAD + g->node_end + SC_GRID_PAD};
    sc_pool_run(g->pool, job_rows, &j, (j.used + SC_GRID_POOL_RANGE - 1u) / SC_GRID_POOL_RANGE);
}

int sc_grid_save_rest(sc_grid *g)
{
    SC_ASSERT(g != NULL);
#if SC_GRID_REST_COPY
    if (g->node_count > SC_GRID_REST_COPY_NODES) {
        rows_run(g, ROWS_SAVE);
        g->rest_saved = 1u;
        return 1;
    }
#endif
    g->rest_saved = 0u;
    return 0;
}

#if SC_GRID_REST_COPY
/* the partial restore's spans of nodes, one per dirty cell range (sc_grid_load_rest) */
typedef struct load_job {
    sc_grid *g;
    uint32_t a[SC_GRID_ASM_RANGES], b[SC_GRID_ASM_RANGES];
    uint32_t n;
} load_job;

static void job_load(void *arg, uint32_t r)
{
    const load_job *j = (const load_job *)arg;
    float *mat = &j->g->d[0][0];
    const uint32_t a = j->a[r];
    for (uint32_t k = 0; k < SC_GRID_MAT_ROWS; k++) {
        memcpy(mat + (size_t)k * SC_GRID_ROW + a, &j->g->rest[k][a],
               (size_t)(j->b[r] - a) * sizeof(float));
    }
}
#endif

int sc_grid_load_rest(sc_grid *g)
{
    SC_ASSERT(g != NULL);
#if SC_GRID_REST_COPY
    if (g->rest_saved && g->rest_patched) {
        /* the floor's additions only: the nodes range r's cells reach, c0 .. c1 - 1 + off[7],
         * on the pool: a dirty range followed by a dirty one stops where that one starts, so
         * the copies are apart (off[7] < asm_span: a range's reach ends inside the next one) */
        const uint32_t ranges = (g->cell_end + g->asm_span - 1u) / g->asm_span;
        load_job j = {g, {0}, {0}, 0u};
        for (uint32_t r = 0; r < ranges && r < SC_GRID_ASM_RANGES; r++) {
            if (!g->floor_dirty[r]) {
                continue;
            }
            const uint32_t c0 = r * g->asm_span;
            const uint32_t c1 = c0 + g->asm_span < g->cell_end ? c0 + g->asm_span : g->cell_end;
            uint32_t b = SC_GRID_HEAD + c1 + g->off[7];
            if (r + 1u < ranges && r + 1u < SC_GRID_ASM_RANGES && g->floor_dirty[r + 1u]) {
                b = SC_GRID_HEAD + c1;
            }
            SC_ASSERT(b <= SC_GRID_ROW);
            j.a[j.n] = SC_GRID_HEAD + c0;
            j.b[j.n] = b;
            j.n++;
            g->floor_dirty[r] = 0u;
        }
        sc_pool_run(g->pool, job_load, &j, j.n);
        g->rest_patched = 0u;
        return 1;
    }
    if (g->rest_saved) {
        rows_run(g, ROWS_LOAD);
        return 1;
    }
#endif
    return 0;
}

void sc_grid_clear(sc_grid *g, uint32_t which)
{
    SC_ASSERT(g != NULL);
    g->rest_patched = 0u;
    rows_run(g, which & (SC_GRID_CLEAR_DIAG | SC_GRID_CLEAR_BLOCKS));
}

static void job_precond(void *arg, uint32_t r)
{
    step_job *j = (step_job *)arg;
    sc_grid *g = j->g;
    uint32_t i0, i1;
    job_span(j, r, j->g->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    static const uint32_t diag_entry[3] = {0u, 3u, 5u};
    for (uint32_t i = i0; i < i1; i++) {
        const uint8_t con = g->con[h + i];
        for (uint32_t c = 0; c < 3u; c++) {
            const float a = j->cm * g->mass[h + i] + j->ck * g->d[diag_entry[c]][h + i];
            const int free_dof = con == 0u || (con >= 0x80u && (con & (2u << c)) == 0u);
            g->pc[c][h + i] = (free_dof && a > 0.0f) ? 1.0f / a : 0.0f;
        }
    }
}

/* the solution's sum of squares over a block, components then nodes (the serial loop's order) */
static void job_vsum(void *arg, uint32_t b)
{
    step_job *j = (step_job *)arg;
    const sc_grid *g = j->g;
    uint32_t i0, i1;
    job_span(j, b, g->sum_block, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    float vsum = 0.0f;
    for (uint32_t c = 0; c < 3u; c++) {
        for (uint32_t i = i0; i < i1; i++) {
            vsum += g->v[c][h + i] * g->v[c][h + i];
        }
    }
    j->vsum[b] = vsum;
}

static void job_finish(void *arg, uint32_t r)
{
    step_job *j = (step_job *)arg;
    const sc_grid *g = j->g;
    uint32_t i0, i1;
    job_span(j, r, j->g->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    float *const nv[3] = {j->out->vx, j->out->vy, j->out->vz};
    float *const nx[3] = {j->out->x, j->out->y, j->out->z};
    /* The step clamp: a free node moves at most step_max_mm in a step (its free components
     * scaled down together; the prescribed ones are the probe's). Ten CG iterations on a
     * stiff tissue around a crushed, nearly massless lumen can leave a lumen node's step
     * tens of mm long (64x32x32, the probe lost at the deepest press); a node of a real
     * tissue never moves two cells in one frame. Per node, so any split gives the same. The
     * copy-out notes whether any node (prescribed ones too) is faster than the bound; only
     * such a range looks at its nodes' free components. */
    const float lim2 = (g->step_max_mm * g->step_max_mm) / (j->dt * j->dt);
    int over = 0;
    for (uint32_t i = i0; i < i1; i++) {
        const float v0 = g->v[0][h + i], v1 = g->v[1][h + i], v2 = g->v[2][h + i];
        nv[0][i] = v0;
        nv[1][i] = v1;
        nv[2][i] = v2;
        nx[0][i] = g->x[0][h + i] + j->dt * v0;
        nx[1][i] = g->x[1][h + i] + j->dt * v1;
        nx[2][i] = g->x[2][h + i] + j->dt * v2;
        over |= ((v0 * v0 + v1 * v1) + v2 * v2) > lim2;
    }
    uint32_t clamped = 0;
    for (uint32_t i = i0; over && i < i1; i++) {
        float v2 = 0.0f;
        for (uint32_t c = 0; c < 3u; c++) {
            const float v = g->pc[c][h + i] > 0.0f ? g->v[c][h + i] : 0.0f;
            v2 += v * v;
        }
        if (v2 > lim2) {
            const float s = sqrtf(lim2 / v2);
            for (uint32_t c = 0; c < 3u; c++) {
                if (g->pc[c][h + i] > 0.0f) {
                    const float v = g->v[c][h + i] * s;
                    nv[c][i] = v;
                    nx[c][i] = g->x[c][h + i] + j->dt * v;
                }
            }
            clamped++;
        }
    }
    j->clamped[r] = clamped;
}

#if SC_GRID_COARSE
int sc_grid_init_box(sc_grid *g, uint32_t nx, uint32_t ny, uint32_t nz, const float origin_mm[3],
                     const float cell_mm[3])
{
    if (g == NULL || origin_mm == NULL || cell_mm == NULL || nx < 2u || ny < 2u || nz < 2u ||
        nx > SC_MAX_MESH_NX || ny > SC_MAX_MESH_NY || nz > SC_MAX_MESH_NZ) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t nxy = nx * ny, nn = nxy * nz;
    init_layout(g, nx, ny, nz, cell_mm);
    const uint32_t h = SC_GRID_HEAD;
    for (uint32_t t = 0; t < nn; t++) {
        const uint32_t i = t % nx, j = (t / nx) % ny, k = t / nxy;
        g->x0[0][h + t] = origin_mm[0] + (float)i * cell_mm[0];
        g->x0[1][h + t] = origin_mm[1] + (float)j * cell_mm[1];
        g->x0[2][h + t] = origin_mm[2] + (float)k * cell_mm[2];
        g->used[t] = 1u; /* every node is a corner of a cell (each count at least 2) */
    }
    return SC_OK;
}

/* P along one axis: the coarse nodes (1 or 2) and weights fine node i takes (cn coarse nodes) */
static uint32_t coarse_of_fine(uint32_t i, uint32_t cn, uint32_t idx[2], float w[2])
{
    const uint32_t a = i / 2u;
    idx[0] = a;
    w[0] = 1.0f;
    if ((i & 1u) == 0u || a + 1u >= cn) {
        return 1u; /* on a coarse node, or past the last one */
    }
    w[0] = 0.5f;
    idx[1] = a + 1u;
    w[1] = 0.5f;
    return 2u;
}

/* P^T along one axis: the fine nodes (1 to 3) and weights coarse node a gathers (n fine nodes,
 * cn coarse): P's column a */
static uint32_t fine_of_coarse(uint32_t a, uint32_t n, uint32_t cn, uint32_t idx[3], float w[3])
{
    uint32_t k = 0;
    if (a > 0u) {
        idx[k] = 2u * a - 1u;
        w[k++] = 0.5f;
    }
    idx[k] = 2u * a;
    w[k++] = 1.0f;
    if (2u * a + 1u < n) {
        idx[k] = 2u * a + 1u;
        w[k++] = a + 1u < cn ? 0.5f : 1.0f;
    }
    return k;
}

/* Row (b, k) of P^T src over the fine nodes whose mask is nonzero (mask NULL: every node): the
 * fine rows (y, z) of the coarse row's column, weighted, then x; out[a] for its cnx nodes. */
static void restrict_row(const sc_grid *g, const sc_grid *gc, uint32_t b, uint32_t k,
                         const float *src, const float *mask, float out[SC_MAX_MESH_NX])
{
    uint32_t iy[3], iz[3];
    float wy[3], wz[3];
    const uint32_t ky = fine_of_coarse(b, g->ny, gc->ny, iy, wy);
    const uint32_t kz = fine_of_coarse(k, g->nz, gc->nz, iz, wz);
    const uint32_t cnx = gc->nx, nx = g->nx;
    for (uint32_t a = 0; a < cnx; a++) {
        out[a] = 0.0f;
    }
    for (uint32_t z = 0; z < kz; z++) {
        for (uint32_t y = 0; y < ky; y++) {
            const float w = wz[z] * wy[y];
            const uint32_t base = SC_GRID_HEAD + g->nxy * iz[z] + nx * iy[y];
            const float *rr = &src[base], *m = mask != NULL ? &mask[base] : NULL;
            for (uint32_t a = 0; a < cnx; a++) {
                const uint32_t x = 2u * a;
                float sum = (m == NULL || nonzero(m[x])) ? rr[x] : 0.0f;
                if (a > 0u && (m == NULL || nonzero(m[x - 1u]))) {
                    sum += 0.5f * rr[x - 1u];
                }
                if (x + 1u < nx && (m == NULL || nonzero(m[x + 1u]))) {
                    sum += (a + 1u < cnx ? 0.5f : 1.0f) * rr[x + 1u];
                }
                out[a] += w * sum;
            }
        }
    }
}

int sc_grid_coarse_init(sc_grid_coarse *c, const sc_grid *g, const float cell_mm[3])
{
    if (c == NULL || g == NULL || cell_mm == NULL || g->nx < 3u || g->ny < 3u || g->nz < 3u) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t h = SC_GRID_HEAD;
    const float origin[3] = {g->x0[0][h], g->x0[1][h], g->x0[2][h]};
    const float cell[3] = {2.0f * cell_mm[0], 2.0f * cell_mm[1], 2.0f * cell_mm[2]};
    sc_grid *gc = &c->grid;
    const int rc =
        sc_grid_init_box(gc, (g->nx + 1u) / 2u, (g->ny + 1u) / 2u, (g->nz + 1u) / 2u, origin, cell);
    if (rc != SC_OK) {
        return rc;
    }
    /* the coarse grid's loops split as a large mesh's, whatever its size (32x16x16 under
     * 64x32x32: 8 ranges of 1,024 nodes, 24x12x12 under 48x24x24: 4 of 864): with one block of
     * 8,192 its CG's p.Ap and update jobs ran on the caller alone, 20 times a step, while the
     * workers waited (sc_pool_run runs a job of one range on the caller) */
    set_ranges(gc, 1);
    c->iterations = SC_GRID_COARSE_ITERATIONS;
    c->alpha = 0.0f;
    for (uint32_t t = 0; t < gc->node_count; t += gc->nx) { /* P^T M P, lumped */
        restrict_row(g, gc, (t / gc->nx) % gc->ny, t / gc->nxy, g->mass, NULL, &gc->mass[h + t]);
    }
    return SC_OK;
}

/* the two-grid correction's loops (sc_grid_coarse): ranges of the coarse grid's range
 * (restriction) or the fine grid's (prolongation, update); every node its own */
typedef struct coarse_job {
    sc_grid *g;
    sc_grid *gc;
    float alpha;
    float pr[SC_GRID_SUM_BLOCKS], pq[SC_GRID_SUM_BLOCKS];
} coarse_job;

/* coarse flags from the fine nodes under them, r_c = P^T r on the free fine DOFs, e_c = 0 */
static void job_coarse_restrict(void *arg, uint32_t r)
{
    const coarse_job *j = (const coarse_job *)arg;
    const sc_grid *g = j->g;
    sc_grid *gc = j->gc;
    uint32_t i0, i1;
    node_span(gc, r, gc->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    const uint32_t n[3] = {g->nx, g->ny, g->nz}, cn[3] = {gc->nx, gc->ny, gc->nz};
    float row[3][SC_MAX_MESH_NX];
    for (uint32_t t = i0; t < i1; t++) {
        const uint32_t ca[3] = {t % gc->nx, (t / gc->nx) % gc->ny, t / gc->nxy};
        if (t == i0 || ca[0] == 0u) {
            for (uint32_t c = 0; c < 3u; c++) {
                restrict_row(g, gc, ca[1], ca[2], g->r[c], g->pc[c], row[c]);
            }
        }
        /* held where a fine node it carries whole is held: its own, and on an axis of an even
         * fine count the last fine node past it (else the coarse grid would miss that face's
         * support: the far sides and the bottom) */
        uint32_t f0[3], f1[3];
        for (uint32_t ax = 0; ax < 3u; ax++) {
            f0[ax] = 2u * ca[ax];
            f1[ax] = ca[ax] + 1u == cn[ax] && f0[ax] + 1u < n[ax] ? f0[ax] + 1u : f0[ax];
        }
        uint32_t held = 0u;
        for (uint32_t d = 0; d < 8u; d++) {
            const uint32_t i = ((d & 1u) ? f1[0] : f0[0]) + g->nx * ((d & 2u) ? f1[1] : f0[1]) +
                               g->nxy * ((d & 4u) ? f1[2] : f0[2]);
            const uint8_t con = g->con[h + i];
            held |= con == 1u || con == 2u ? 7u : (con >= 0x80u ? (con >> 1) & 7u : 0u);
        }
        gc->con[h + t] = held == 7u ? 1u : (held != 0u ? (uint8_t)(0x80u | (held << 1)) : 0u);
        for (uint32_t c = 0; c < 3u; c++) {
            gc->r[c][h + t] = row[c][ca[0]];
            gc->v[c][h + t] = 0.0f;
        }
    }
}

/* p = P e_c on the free fine DOFs (0 on the held ones): per fine row (y, z) the coarse rows
 * under it weighted, then x */
static void job_coarse_prolong(void *arg, uint32_t r)
{
    const coarse_job *j = (const coarse_job *)arg;
    sc_grid *g = j->g;
    const sc_grid *gc = j->gc;
    uint32_t i0, i1;
    node_span(g, r, g->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD, cnx = gc->nx;
    float row[3][SC_MAX_MESH_NX];
    for (uint32_t i = i0; i < i1; i++) {
        const uint32_t x = i % g->nx;
        if (i == i0 || x == 0u) {
            const uint32_t y = (i / g->nx) % g->ny, z = i / g->nxy;
            uint32_t iy[2], iz[2];
            float wy[2], wz[2];
            const uint32_t ky = coarse_of_fine(y, gc->ny, iy, wy);
            const uint32_t kz = coarse_of_fine(z, gc->nz, iz, wz);
            for (uint32_t c = 0; c < 3u; c++) {
                for (uint32_t a = 0; a < cnx; a++) {
                    row[c][a] = 0.0f;
                }
                for (uint32_t zz = 0; zz < kz; zz++) {
                    for (uint32_t yy = 0; yy < ky; yy++) {
                        const float w = wz[zz] * wy[yy];
                        const float *vc = &gc->v[c][h + gc->nxy * iz[zz] + cnx * iy[yy]];
                        for (uint32_t a = 0; a < cnx; a++) {
                            row[c][a] += w * vc[a];
                        }
                    }
                }
            }
        }
        const uint32_t a = x / 2u;
        for (uint32_t c = 0; c < 3u; c++) {
            const float val =
                ((x & 1u) == 0u || a + 1u >= cnx) ? row[c][a] : 0.5f * (row[c][a] + row[c][a + 1u]);
            g->p[c][h + i] = nonzero(g->pc[c][h + i]) ? val : 0.0f;
        }
    }
}

/* p.r and p.q over a sum block, components then nodes */
static void job_coarse_dots(void *arg, uint32_t b)
{
    coarse_job *j = (coarse_job *)arg;
    const sc_grid *g = j->g;
    uint32_t i0, i1;
    node_span(g, b, g->sum_block, &i0, &i1);
    i0 += SC_GRID_HEAD;
    i1 += SC_GRID_HEAD;
    float pr = 0.0f, pq = 0.0f;
    for (uint32_t c = 0; c < 3u; c++) {
        for (uint32_t i = i0; i < i1; i++) {
            pr += g->p[c][i] * g->r[c][i];
            pq += g->p[c][i] * g->q[c][i];
        }
    }
    j->pr[b] = pr;
    j->pq[b] = pq;
}

/* v += alpha p, r -= alpha q (q = A p) */
static void job_coarse_update(void *arg, uint32_t r)
{
    const coarse_job *j = (const coarse_job *)arg;
    sc_grid *g = j->g;
    uint32_t i0, i1;
    node_span(g, r, g->range, &i0, &i1);
    const uint32_t h = SC_GRID_HEAD;
    const float alpha = j->alpha;
    for (uint32_t c = 0; c < 3u; c++) {
        for (uint32_t i = h + i0; i < h + i1; i++) {
            g->v[c][i] += alpha * g->p[c][i];
            g->r[c][i] -= alpha * g->q[c][i];
        }
    }
}

/* The two-grid correction of the warm start (sc_grid_coarse), after the fine preconditioner. */
static void coarse_correct(sc_grid *g, float cm, float ck)
{
    sc_grid_coarse *c = g->coarse;
    sc_grid *gc = &c->grid;
    gc->pool = g->pool;
    coarse_job cj;
    memset(&cj, 0, sizeof cj);
    cj.g = g;
    cj.gc = gc;
    sc_pool_run(g->pool, job_coarse_restrict, &cj, job_ranges(gc, gc->range));
    step_job j;
    memset(&j, 0, sizeof j);
    j.g = gc;
    j.cm = cm;
    j.ck = ck;
    sc_pool_run(g->pool, job_precond, &j, job_ranges(gc, gc->range));
    sc_grid_cg_out out;
    const sc_grid_kern *k = sc_grid_kern_selected();
    k->cg(gc, cm, ck, c->iterations, &out);
    sc_pool_run(g->pool, job_coarse_prolong, &cj, job_ranges(g, g->range));
    k->matvec(g, cm, ck);
    /* the step along P e_c that minimises the fine error's energy, (p.r) / (p.A p): the coarse
     * K is not P^T K P (its own cells, the fine model's nonlinear and floor terms left out), and
     * a correction scaled by it never raises the error's A-norm */
    const uint32_t blocks = job_ranges(g, g->sum_block);
    sc_pool_run(g->pool, job_coarse_dots, &cj, blocks);
    float pr = 0.0f, pq = 0.0f;
    for (uint32_t b = 0; b < blocks && b < SC_GRID_SUM_BLOCKS; b++) {
        pr += cj.pr[b];
        pq += cj.pq[b];
    }
    cj.alpha = (pq > 0.0f && isfinite(pr / pq)) ? pr / pq : 0.0f;
    c->alpha = cj.alpha;
    sc_pool_run(g->pool, job_coarse_update, &cj, job_ranges(g, g->range));
}
#endif

int sc_grid_solve(sc_grid *g, sc_nodes *n, float dt_s, float beta_s, float alpha_per_s,
                  uint32_t cg_iterations)
{
    SC_ASSERT(g != NULL && n != NULL);
    SC_ASSERT(cg_iterations >= 1u && cg_iterations <= SC_PHYS_ITERATIONS_MAX);
    const float cm = 1.0f + dt_s * alpha_per_s;
    const float ck = dt_s * beta_s + dt_s * dt_s;
    step_job j;
    j.g = g;
    j.m = NULL;
    j.n = NULL;
    j.out = n;
    j.kinematic = NULL;
    j.dt = dt_s;
    j.cm = cm;
    j.ck = ck;
    const uint32_t ranges = job_ranges(g, g->range);
    /* Jacobi preconditioner, zero on Dirichlet DOFs (projects the CG onto the free DOFs) */
    sc_pool_run(g->pool, job_precond, &j, ranges);
    /* the correction's mat-vec stands for one of the CG's: a step still costs cg_iterations
     * fine mat-vecs (64x32x32 at 9 + 1 against 10 + 1: vein 0.140 / 0.032 against 0.136 / 0.025
     * MSDS, 0.094 / 0.008 against 0.089 / 0.007 FEM, docs/physics.md) */
    uint32_t fine_its = cg_iterations, corrected = 0u;
#if SC_GRID_COARSE
    if (g->coarse != NULL) {
        coarse_correct(g, cm, ck);
        corrected = 1u;
        fine_its = cg_iterations > 1u ? cg_iterations - 1u : 1u;
    }
#endif
    sc_grid_cg_out out;
    sc_grid_kern_selected()->cg(g, cm, ck, fine_its, &out);
    g->stats.cg_iterations_run = out.iterations + corrected;
    g->stats.residual_ratio = (out.rz0 > 0.0f && out.rz >= 0.0f) ? sqrtf(out.rz / out.rz0) : 0.0f;
    /* refuse a non-finite solution: the shared state stays as it was */
    const uint32_t blocks = job_ranges(g, g->sum_block);
    sc_pool_run(g->pool, job_vsum, &j, blocks);
    float vsum = j.vsum[0];
    for (uint32_t b = 1; b < blocks && b < SC_GRID_SUM_BLOCKS; b++) {
        vsum += j.vsum[b];
    }
    if (!isfinite(vsum)) {
        g->stats.unstable_steps++;
        return SC_ERR_PHYS_UNSTABLE;
    }
    sc_pool_run(g->pool, job_finish, &j, ranges);
    uint32_t clamped = 0;
    for (uint32_t r = 0; r < ranges && r < SC_GRID_RANGES_MAX; r++) {
        clamped += j.clamped[r];
    }
    g->stats.clamped_nodes = clamped;
    g->stats.clamped_steps += clamped != 0u ? 1u : 0u;
    return SC_OK;
}

/* K(i, j) (row-major) into out for j = i + d (d: x, y, z steps of -1, 0 or 1, j inside the
 * grid): the diagonal block (d = 0), a grid edge's block (e at the lower node), a face diagonal's
 * of odd nodes (f at the face's lowest node: the main diagonal's lower end, or the anti
 * diagonal's face one back along d1), read transposed when it is stored as K(j, i). Returns 0
 * (out untouched) where no block is stored: a body diagonal, or a face diagonal of even nodes. */
static int block_at(const sc_grid *g, uint32_t i, uint32_t j, const int d[3], float out[9])
{
    static const uint8_t sym[9] = {0u, 1u, 2u, 1u, 3u, 4u, 2u, 4u, 5u};
    const ptrdiff_t h = SC_GRID_HEAD;
    const ptrdiff_t o[3] = {1, (ptrdiff_t)g->nx, (ptrdiff_t)g->nxy};
    const int moved = (d[0] != 0) + (d[1] != 0) + (d[2] != 0);
    if (moved == 0) {
        for (uint32_t q = 0; q < 9u; q++) {
            out[q] = g->d[sym[q]][h + (ptrdiff_t)i];
        }
        return 1;
    }
    const float *blk = NULL;
    int tr = 0;
    if (moved == 1) {
        const uint32_t a = d[0] != 0 ? 0u : (d[1] != 0 ? 1u : 2u);
        tr = d[a] < 0;
        blk = &g->e[a][0][h + (ptrdiff_t)(tr ? j : i)];
    } else if (moved == 2 && g->odd[h + (ptrdiff_t)i] != 0) {
        /* plane w of the two axes a1 < a2 that move */
        const uint32_t w = d[2] == 0 ? 0u : (d[1] == 0 ? 1u : 2u);
        const uint32_t a1 = w == 2u ? 1u : 0u, a2 = w == 0u ? 1u : 2u;
        ptrdiff_t at = (ptrdiff_t)i; /* (+, +): the main diagonal from i */
        if (d[a1] < 0 && d[a2] < 0) {
            at = (ptrdiff_t)j; /* the main diagonal from j */
            tr = 1;
        } else if (d[a1] < 0) {
            at = (ptrdiff_t)i - o[a1]; /* the anti diagonal, i its upper end */
        } else if (d[a2] < 0) {
            at = (ptrdiff_t)i - o[a2]; /* the anti diagonal, j its upper end */
            tr = 1;
        }
        blk = &g->f[w][0][h + at];
    }
    if (blk == NULL) {
        return 0;
    }
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t c = 0; c < 3u; c++) {
            out[3u * r + c] = blk[(size_t)(tr ? 3u * c + r : 3u * r + c) * SC_GRID_ROW];
        }
    }
    return 1;
}

int sc_grid_block(const sc_grid *g, uint32_t i, uint32_t j, float out[9])
{
    SC_ASSERT(g != NULL && out != NULL);
    for (uint32_t k = 0; k < 9u; k++) {
        out[k] = 0.0f;
    }
    if (i >= g->node_count || j >= g->node_count) {
        return 0;
    }
    const uint32_t nx = g->nx, ny = g->ny;
    const int64_t ci[3] = {i % nx, (i / nx) % ny, i / (nx * ny)};
    const int64_t cj[3] = {j % nx, (j / nx) % ny, j / (nx * ny)};
    int d[3];
    for (uint32_t a = 0; a < 3u; a++) {
        const int64_t s = cj[a] - ci[a];
        if (s < -1 || s > 1) {
            return 0; /* farther than the neighbourhood: no block */
        }
        d[a] = (int)s;
    }
    return block_at(g, i, j, d, out);
}

void sc_grid_row_disp(const sc_grid *g, uint32_t i, const uint32_t ci[3], const float *const x[3],
                      const float *const x0[3], float f[3])
{
    SC_ASSERT(g != NULL && ci != NULL && x != NULL && x0 != NULL && f != NULL);
    const uint32_t nx = g->nx, ny = g->ny, nz = g->nz;
    for (int dz = -1; dz <= 1; dz++) {
        for (int dy = -1; dy <= 1; dy++) {
            for (int dx = -1; dx <= 1; dx++) {
                const int jx = (int)ci[0] + dx, jy = (int)ci[1] + dy, jz = (int)ci[2] + dz;
                if (jx < 0 || jy < 0 || jz < 0 || jx >= (int)nx || jy >= (int)ny ||
                    jz >= (int)nz) {
                    continue;
                }
                const uint32_t j = (uint32_t)jx + nx * ((uint32_t)jy + ny * (uint32_t)jz);
                const int d[3] = {dx, dy, dz};
                float k[9];
                if (!block_at(g, i, j, d, k)) {
                    continue;
                }
                const float u[3] = {x[0][j] - x0[0][j], x[1][j] - x0[1][j], x[2][j] - x0[2][j]};
                for (uint32_t c = 0; c < 3u; c++) {
                    f[c] += k[3u * c] * u[0] + k[3u * c + 1u] * u[1] + k[3u * c + 2u] * u[2];
                }
            }
        }
    }
}

void sc_grid_apply_ref(const sc_grid *g, float cm, float ck, const double *p, double *q)
{
    SC_ASSERT(g != NULL && p != NULL && q != NULL);
    const uint32_t nn = g->node_count;
    for (uint32_t i = 0; i < 3u * nn; i++) {
        q[i] = (double)cm * (double)g->mass[SC_GRID_HEAD + i / 3u] * p[i];
    }
    const uint32_t nbr[13] = {0u, 1u, g->nx, g->nxy, g->nx + 1u, g->nx - 1u, g->nxy + 1u,
                              g->nxy - 1u, g->nxy + g->nx, g->nxy - g->nx, 0u, 0u, 0u};
    for (uint32_t i = 0; i < nn; i++) {
        for (uint32_t k = 0; k < 10u; k++) {
            const uint32_t j = i + nbr[k];
            int dup = 0; /* offsets coincide on the smallest grids (nx = 2: nx - 1 = 1) */
            for (uint32_t k2 = 0; k2 < k; k2++) {
                dup |= nbr[k2] == nbr[k];
            }
            if (dup || j >= nn) {
                continue;
            }
            float b[9];
            if (!sc_grid_block(g, i, j, b)) {
                continue;
            }
            for (uint32_t r = 0; r < 3u; r++) {
                for (uint32_t c = 0; c < 3u; c++) {
                    const double v = (double)ck * (double)b[3u * r + c];
                    q[3u * i + r] += v * p[3u * j + c];
                    if (j != i) {
                        q[3u * j + c] += v * p[3u * i + r];
                    }
                }
            }
        }
    }
}
