/* test_sc_grid_split.c: the worker pool's split of the cell passes (sc_grid_asm_span) and of the
 * lumen law's passes (sc_lumen_split) for every mesh within the limits (nx, ny, nz from 2 to
 * SC_MAX_MESH_NX/NY/NZ). Both are chosen by the mesh alone, and both cut the work into ranges
 * that run two phases apart: the even ranges at the same time, then the odd ones. So for every
 * mesh, ranges two apart must touch no common node, and there must be no more ranges than the
 * per-range arrays hold. Until this test, 1,330 of these meshes (52x26x26 among them) failed
 * sc_grid_init's assert at case load. In 2,790 of them the lumen's ranges two apart shared
 * nodes, a race between the workers. A mesh of the kind that failed both is run on the pool in
 * test_sc_pool. */
#include "sc_test.h"

#include "sc_config.h"
#include "sc_grid.h"
#include "sc_lumen.h"

/* The next mesh within the limits after m (nx fastest), skipping node counts above SC_MAX_NODES;
 * start from {1, 2, 2}. Returns 0 past the last one. */
static int next_mesh(uint32_t m[3])
{
    static const uint32_t max[3] = {SC_MAX_MESH_NX, SC_MAX_MESH_NY, SC_MAX_MESH_NZ};
    do {
        uint32_t a = 0;
        while (a < 3u && ++m[a] > max[a]) {
            m[a] = 2u;
            a++;
        }
        if (a == 3u) {
            return 0;
        }
    } while ((uint64_t)m[0] * m[1] * m[2] > SC_MAX_NODES);
    return 1;
}

static void cell_pass_ranges_are_two_apart_for_every_mesh(void **state)
{
    (void)state;
    uint32_t meshes = 0, split = 0, balanced = 0;
    for (uint32_t m[3] = {1u, 2u, 2u}; next_mesh(m);) {
        const uint32_t nx = m[0], ny = m[1], nz = m[2];
        meshes++;
        const uint32_t nxy = nx * ny, nn = nxy * nz;
        const uint32_t cells = nn - (1u + nx + nxy);
        const uint32_t cell_end =
            (cells + SC_GRID_CELL_BLOCK - 1u) / SC_GRID_CELL_BLOCK * SC_GRID_CELL_BLOCK;
        const uint32_t span = sc_grid_asm_span(nx, ny, nz);
        const uint32_t ranges = (cell_end + span - 1u) / span;
        if (span % SC_GRID_CELL_BLOCK != 0u || span <= nxy + nx + SC_GRID_CELL_BLOCK ||
            ranges > SC_GRID_ASM_RANGES || ranges == 0u) {
            fail_msg("%ux%ux%u: cell span %u, %u ranges (two apart needs > %u, at most %u "
                     "ranges)",
                     nx, ny, nz, span, ranges, nxy + nx + SC_GRID_CELL_BLOCK,
                     (unsigned)SC_GRID_ASM_RANGES);
        }
        if (cell_end <= 2u * SC_GRID_ASM_SPAN) {
            /* up to two ranges: the serial loop's sums (every stored hash) */
            assert_int_equal(span, SC_GRID_ASM_SPAN);
        } else {
            split++;
            balanced += ranges % 4u == 0u;
        }
    }
    print_message("%u meshes, %u split finer, %u of those into a multiple of four ranges\n", meshes,
                  split, balanced);
    assert_true(split > 0u);
}

static void lumen_ranges_are_two_apart_for_every_mesh(void **state)
{
    (void)state;
    uint32_t meshes = 0, split = 0;
    for (uint32_t m[3] = {1u, 2u, 2u}; next_mesh(m);) {
        const uint32_t nx = m[0], ny = m[1], nz = m[2];
        meshes++;
        const uint32_t cells = (nx - 1u) * (ny - 1u) * (nz - 1u);
        uint32_t ranges = 0u, span = 0u;
        sc_lumen_split(nx, ny, nz, &ranges, &span);
        if (ranges == 0u || ranges > SC_LUMEN_RANGES || (uint64_t)ranges * span < cells ||
            (uint64_t)(ranges - 1u) * span >= cells) {
            fail_msg("%ux%ux%u: %u lumen ranges of %u cells for %u cells", nx, ny, nz, ranges, span,
                     cells);
        }
        if (ranges == 1u) {
            continue;
        }
        split++;
        /* cells c and c + d share a node only if d <= (nx - 1)(ny - 1) + nx; the nearest cells
         * of ranges two apart are span + 1 apart */
        if (span + 1u <= (nx - 1u) * (ny - 1u) + nx) {
            fail_msg("%ux%ux%u: lumen ranges of %u cells, two apart share nodes", nx, ny, nz, span);
        }
    }
    print_message("%u meshes, %u with the lumen's passes split\n", meshes, split);
    assert_true(split > 0u || SC_LUMEN_RANGES < 2u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cell_pass_ranges_are_two_apart_for_every_mesh),
        cmocka_unit_test(lumen_ranges_are_two_apart_for_every_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
