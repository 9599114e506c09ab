/* test_sc_bscan_pool.c: the B-scan's lines on the worker pool (sc_bscan_set_pool) give the
 * serial path's image and status, bit for bit, for every worker count.
 *
 * Scenes of tools/bench_bscan/bscan_scene.h: a dented and wobbled 32x16x16 mesh seen straight
 * and tilted, the vein squashed, and a 16x8x8 mesh with a node pushed through its neighbours (a
 * fold: the walker locates across it, which needs the region bins: the first frame's ranges hand
 * their lines to the caller, the next frame's find the bins built up front). Each scene runs a
 * short sequence of frames on one sc_bscan (held pose: the margin memo; a new pose) with no
 * pool, the host simulator's pool of 1, 2 and 4 workers and 2 real threads; every displayed
 * byte, the order the lines leave in, every line hook call (line, labels, runs, positions) and
 * every status field are compared.
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../../tools/bench_bscan/bscan_scene.h"
#include "sc_bscan.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_hs_pool.h"
#include "sc_mesh.h"
#include "sc_pool_linux.h"

#define IMG_MAX (SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES)
#define FRAMES 4

static scn_volume g_vol;
static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_bscan g_b;
static sc_hs_display g_disp;

/* What one run of a scene recorded, per frame. */
typedef struct run_rec {
    uint8_t img[FRAMES][IMG_MAX];
    sc_bscan_status st[FRAMES];
    int rc[FRAMES];
    uint64_t hook_hash[FRAMES];  /* FNV-1a over every hook call's view, in call order */
    uint32_t hook_calls[FRAMES];
    uint32_t order_errors[FRAMES]; /* lines that left out of order (display or hook) */
} run_rec;

static run_rec g_ref, g_run;

/* ---- a display that checks the line order, in front of the host simulator's ---------------- */

typedef struct order_disp {
    sc_display_dev inner;
    uint32_t next_line;
    uint32_t *errors;
} order_disp;

static order_disp g_od;

static int od_begin(void *ctx, const sc_display_frame_info *info)
{
    order_disp *o = ctx;
    o->next_line = 0u;
    return sc_display_frame_begin(&o->inner, info);
}

static int od_line(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                   uint16_t count)
{
    order_disp *o = ctx;
    if (line_index != o->next_line) {
        (*o->errors)++;
    }
    o->next_line = line_index + 1u;
    return sc_display_line(&o->inner, frame_no, line_index, samples, count);
}

static int od_end(void *ctx, const sc_display_end_info *end)
{
    order_disp *o = ctx;
    return sc_display_frame_end(&o->inner, end);
}

static int od_link(void *ctx, sc_display_link_state *state)
{
    order_disp *o = ctx;
    return o->inner.ops->link_state(o->inner.ctx, state);
}

static const sc_display_ops k_od_ops = {
    .frame_begin = od_begin, .line = od_line, .frame_end = od_end, .link_state = od_link};

/* ---- a line hook that hashes what it sees and draws into the line ------------------------- */

typedef struct hook_state {
    uint64_t h;
    uint32_t calls;
    uint32_t next_line;
    uint32_t *errors;
} hook_state;

static hook_state g_hook;

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++) {
        h = (h ^ b[i]) * UINT64_C(0x100000001b3);
    }
    return h;
}

static void hook(void *ctx, const sc_bscan_line_view *v)
{
    hook_state *s = ctx;
    if (v->line != s->next_line) {
        (*s->errors)++;
    }
    s->next_line = v->line + 1u;
    s->calls++;
    s->h = fnv(s->h, &v->line, sizeof v->line);
    s->h = fnv(s->h, &v->run_count, sizeof v->run_count);
    s->h = fnv(s->h, v->labels, v->samples_n);
    s->h = fnv(s->h, v->out, v->samples_n);
    for (uint32_t i = 0; i < v->run_count; i++) {
        s->h = fnv(s->h, &v->runs[i].k0, sizeof v->runs[i].k0);
        s->h = fnv(s->h, &v->runs[i].k1, sizeof v->runs[i].k1);
        s->h = fnv(s->h, v->runs[i].a, sizeof v->runs[i].a);
        s->h = fnv(s->h, v->runs[i].b, sizeof v->runs[i].b);
    }
    s->h = fnv(s->h, v->f0, sizeof v->f0);
    s->h = fnv(s->h, v->fd, sizeof v->fd);
    const float geo[4] = {v->org_x, v->org_z, v->dir_x, v->dir_z};
    s->h = fnv(s->h, geo, sizeof geo);
    s->h = fnv(s->h, v->img2vol, sizeof *v->img2vol);
    /* draw as the needle does: into the displayed samples, a mark on every 16th line */
    if ((v->line & 15u) == 0u) {
        for (uint32_t k = 0; k < v->samples_n; k += 7u) {
            v->out[k] = 255u;
        }
    }
}

static int group_setup(void **state)
{
    (void)state;
    scn_make_volume(&g_vol);
    return 0;
}

static void build_mesh(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = nx;
    md.ny = ny;
    md.nz = nz;
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
}

static void wobble(void)
{
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        float u[3];
        scn_displacement(SCN_DEFORM_WOBBLE, 1.0f, g_mesh.rest_x[i], g_mesh.rest_y[i],
                         g_mesh.rest_z[i], u);
        g_nodes.x[i] += u[0];
        g_nodes.y[i] += u[1];
        g_nodes.z[i] += u[2];
    }
}

/* A fold: the node nearest (20, 10, 8) pushed up through its upper neighbours' cells (as
 * test_sc_bscan's fold test). Returns its rest y (the image plane goes through it). */
static float fold_mesh(void)
{
    build_mesh(16, 8, 8);
    scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 4.0f);
    uint32_t best = 0;
    float bd = 1e9f;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float dx = g_mesh.rest_x[i] - 20.0f, dy = g_mesh.rest_y[i] - 10.0f,
                    dz = g_mesh.rest_z[i] - 8.0f;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < bd) {
            bd = d2;
            best = i;
        }
    }
    g_nodes.z[best] -= 1.6f * g_mesh.cell_mm[2];
    return g_mesh.rest_y[best];
}

/* FRAMES frames of the poses (the last ones repeated) on one sc_bscan with the pool. */
static void run_scene(const sc_bscan_def *def, const sc_xform *poses, uint32_t npose, int with_hook,
                      const sc_pool_dev *pool, run_rec *out)
{
    assert_int_equal(sc_bscan_init(&g_b, def), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    sc_bscan_set_pool(&g_b, pool);
    sc_hs_display_init(&g_disp);
    g_od.inner = sc_hs_display_dev(&g_disp);
    const sc_display_dev dev = {&k_od_ops, &g_od};
    for (uint32_t f = 0; f < FRAMES; f++) {
        out->order_errors[f] = 0u;
        g_od.errors = &out->order_errors[f];
        memset(&g_hook, 0, sizeof g_hook);
        g_hook.h = UINT64_C(0xcbf29ce484222325);
        g_hook.errors = &out->order_errors[f];
        if (with_hook) {
            sc_bscan_set_line_hook(&g_b, hook, &g_hook);
        }
        const sc_xform *p = &poses[f < npose ? f : npose - 1u];
        out->rc[f] = sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, p, 1, &dev, 10u + f);
        assert_int_equal(g_disp.frames_complete, f + 1u);
        assert_int_equal(g_disp.protocol_errors, 0);
        memcpy(out->img[f], g_disp.last, (size_t)def->scan.lines_n * def->scan.samples_n);
        out->st[f] = g_b.status;
        out->hook_hash[f] = g_hook.h;
        out->hook_calls[f] = g_hook.calls;
    }
}

static void assert_same_status(const sc_bscan_status *a, const sc_bscan_status *b)
{
    assert_int_equal(a->frame_no, b->frame_no);
    assert_int_equal(a->contact, b->contact);
    assert_int_equal(a->areas_valid, b->areas_valid);
    assert_memory_equal(a->area_now_mm2, b->area_now_mm2, sizeof a->area_now_mm2);
    assert_memory_equal(a->area_rest_mm2, b->area_rest_mm2, sizeof a->area_rest_mm2);
    assert_memory_equal(a->area_ratio, b->area_ratio, sizeof a->area_ratio);
    assert_memory_equal(&a->image_area_mm2, &b->image_area_mm2, sizeof a->image_area_mm2);
    assert_int_equal(a->pixels_in_mesh, b->pixels_in_mesh);
    assert_int_equal(a->plane_hull_segments, b->plane_hull_segments);
    assert_int_equal(a->plane_tets, b->plane_tets);
    assert_int_equal(a->walk_steps, b->walk_steps);
    assert_int_equal(a->walk_aborts, b->walk_aborts);
    assert_int_equal(a->event_overflows, b->event_overflows);
    assert_int_equal(a->line_fallbacks, b->line_fallbacks);
    assert_int_equal(a->walk_relocations, b->walk_relocations);
    assert_int_equal(a->region_overflows, b->region_overflows);
    assert_int_equal(a->display_errors, b->display_errors);
}

static void assert_same_run(const sc_bscan_def *def, const run_rec *a, const run_rec *b)
{
    const size_t n = (size_t)def->scan.lines_n * def->scan.samples_n;
    for (uint32_t f = 0; f < FRAMES; f++) {
        assert_int_equal(a->rc[f], b->rc[f]);
        assert_memory_equal(a->img[f], b->img[f], n);
        assert_same_status(&a->st[f], &b->st[f]);
        assert_true(a->hook_hash[f] == b->hook_hash[f]);
        assert_int_equal(a->hook_calls[f], b->hook_calls[f]);
        assert_int_equal(b->order_errors[f], 0);
    }
}

/* The scene with no pool (the reference), then each pool: the same record. Returns the
 * reference's fold relocations (the caller checks the scene does what it says). */
static void compare_pools(const sc_bscan_def *def, const sc_xform *poses, uint32_t npose,
                          int with_hook)
{
    print_message("%ux%u, mapper %u, hook %d, acoustics %u\n", (unsigned)def->scan.lines_n,
                  (unsigned)def->scan.samples_n, (unsigned)def->mapper, with_hook,
                  (unsigned)def->acoustics);
    run_scene(def, poses, npose, with_hook, NULL, &g_ref);
    for (uint32_t f = 0; f < FRAMES; f++) {
        assert_int_equal(g_ref.order_errors[f], 0);
        assert_int_equal(g_ref.hook_calls[f], with_hook ? def->scan.lines_n : 0u);
        assert_true(g_ref.st[f].pixels_in_mesh > 0u);
    }
    for (uint32_t w = 1u; w <= 4u; w *= 2u) {
        sc_hs_pool hp;
        sc_pool_dev dev;
        sc_hs_pool_init(&hp, w, &dev);
        run_scene(def, poses, npose, with_hook, &dev, &g_run);
        assert_same_run(def, &g_ref, &g_run);
        print_message("  host pool, %u worker(s): the serial record\n", (unsigned)w);
        /* more than one worker: the lines went through the pool (one job per frame at least) */
        assert_true(w == 1u || hp.jobs >= FRAMES);
    }
    static sc_pool_linux lp;
    sc_pool_dev dev;
    assert_int_equal(sc_pool_linux_start(&lp, 2u, -1, 50u, &dev), 0);
    run_scene(def, poses, npose, with_hook, &dev, &g_run);
    const uint64_t jobs = lp.jobs;
    sc_pool_linux_stop(&lp);
    assert_same_run(def, &g_ref, &g_run);
    assert_true(jobs >= FRAMES);
    print_message("  2 threads: the serial record\n");
}

static void dented_mesh_straight_and_tilted_give_the_serial_image_on_every_pool(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 8.0f);
    wobble();
    /* straight (held for a frame: the margin memo), then tilted 4 and 15 degrees */
    const sc_xform poses[3] = {scn_probe(19.0f, 10.5f, 7.0f, 0.0f),
                               scn_probe(19.0f, 10.5f, 7.0f, 4.0f),
                               scn_probe(21.0f, 9.0f, 6.0f, 15.0f)};
    const sc_xform seq[4] = {poses[0], poses[0], poses[1], poses[2]};
    sc_bscan_def d = sc_bscan_default_def();
    compare_pools(&d, seq, 4u, 1);
    compare_pools(&d, seq, 4u, 0); /* without a hook: the runs not kept */
    d.acoustics = 1u;
    compare_pools(&d, seq, 4u, 1);
    /* the paper's region path, and a curvilinear probe */
    sc_bscan_def r = sc_bscan_default_def();
    r.mapper = SC_BSCAN_MAP_REGIONS;
    compare_pools(&r, seq, 4u, 1);
    sc_bscan_def cv = sc_bscan_default_def();
    cv.scan.kind = SC_SCAN_GEOM_CURVILINEAR;
    cv.scan.lines_n = 200u;
    compare_pools(&cv, seq, 4u, 1);
}

static void squashed_vein_gives_the_serial_areas_on_every_pool(void **state)
{
    (void)state;
    build_mesh(32, 16, 16);
    scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_SQUASH_VEIN, 1.0f);
    const sc_xform seq[2] = {scn_probe(20.0f, 10.0f, 6.0f, 0.0f),
                             scn_probe(20.0f, 11.0f, 6.5f, -6.0f)};
    sc_bscan_def d = sc_bscan_default_def();
    d.scan.lines_n = 97u; /* ranges of unequal length */
    compare_pools(&d, seq, 2u, 1);
    assert_true(g_ref.st[0].areas_valid);
}

static void fold_located_by_the_walker_gives_the_serial_image_on_every_pool(void **state)
{
    (void)state;
    const float y = fold_mesh();
    const sc_xform seq[2] = {scn_probe(20.0f, y, 4.0f, 0.0f), scn_probe(20.0f, y, 4.0f, 3.0f)};
    sc_bscan_def d = sc_bscan_default_def();
    d.scan.lines_n = 64u;
    d.scan.samples_n = 160u;
    compare_pools(&d, seq, 2u, 1);
    /* the scene crosses the fold by locating: the region bins were needed */
    assert_true(g_ref.st[0].walk_relocations > 0u);
    assert_true(g_ref.st[FRAMES - 1u].walk_relocations > g_ref.st[0].walk_relocations);
    d.mapper = SC_BSCAN_MAP_ORACLE;
    d.scan.lines_n = 24u;
    d.scan.samples_n = 64u;
    compare_pools(&d, seq, 2u, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(dented_mesh_straight_and_tilted_give_the_serial_image_on_every_pool),
        cmocka_unit_test(squashed_vein_gives_the_serial_areas_on_every_pool),
        cmocka_unit_test(fold_located_by_the_walker_gives_the_serial_image_on_every_pool),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
