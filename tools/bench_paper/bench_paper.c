/* bench_paper.c: the paper's evidence in one run (Table I, Table II, Fig. 9), for its four
 * meshes and 48x24x24, 64x32x32, on 1 and 2 workers, with Bullet's soft body beside ours.
 *
 * Scene: the clinical block of tests/support/sc_test_tissue_scene.h (40 x 20 x 30 mm, fat,
 * muscle, vein, artery, 0.5 mm volume), skin off, the probe pressed from 0.5 mm above the skin to
 * 3 mm in over 30 frames and held there (contacts every frame), as bench-scale. Per mesh, method
 * (the stable MSDS and the linear FEM, the engine's defaults; corotated with --methods) and worker
 * count (platform/linux/sc_pool_linux.h, pinned from CPU 0): `repeats` runs of `frames` frames.
 * Each frame, as the engine's stages do it (core/sc_engine.c):
 *   step      sc_tissue_step (collider + solver + guard) on the pool: Table I "simulation";
 *   collision sc_collider_detect alone once more on the result: Table I "collision response";
 *   sampling  sc_bscan_frame (the engine's default B-scan, 256 lines) into a display that drops
 *             the lines: Table I "volume sampling";
 *   output    sc_bscan_frame into the output sink, the engine's display HAL: the PNG sink
 *             (platform/linux/sc_png_sink.h: lines copied in the frame loop, a writer thread
 *             scan-converts and writes the PNG, a frame it is still busy with is skipped and
 *             counted, as in `sonocomp --png-dir`), or the UDP display link (--sink udp:HOST:PORT);
 * Table II: frames per second without output = 1000 / step, with output = 1000 / (step + output).
 * Per run the median frame of each (wall clock, CLOCK_MONOTONIC) and the process CPU time of the
 * step; printed: the median over runs and the spread (min .. max of the runs' medians). Every
 * run's state hash is checked against the one-worker run of its mesh and method (a mismatch is
 * printed, exit status 1). Bullet (bench_bullet.h states exactly what it is asked to do) runs the
 * same mesh and press on one thread, timed the same way (its step includes its collision).
 * The B-scan runs its lines on the same pool (sc_bscan_set_pool). Its CPU time is kept beside
 * its wall time (a shared machine's wall clock counts the time the thread waited for a CPU):
 * sampling: the process's (all workers, as the step's; with the PNG sink the writer thread's
 * too, so read it with --sink none), output: the frame thread's.
 * Out: the tables on stdout, one CSV row per run (--csv), Fig. 9 as PNG bar charts of the step
 * per mesh, method and workers, Bullet, and the paper's own figures: --png the wall medians,
 * --png-cpu the CPU times.
 *
 * Usage: bench-paper [--frames N] [--repeats R] [--workers 1,2] [--meshes 20x10x10,...]
 *                    [--methods msds,fem,corot] [--sink png|none|udp:HOST:PORT]
 *                    [--png-dir DIR] [--bullet on|off] [--csv FILE] [--png FILE]
 *                    [--png-cpu FILE]
 * Defaults: 20 frames, 5 repeats, workers 1,2, the six meshes, msds,fem, sink png into
 * out/bench-paper/frames, bullet on (when built), out/bench-paper/bench-paper.csv, fig9.png and
 * fig9-cpu.png.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "bench_bullet.h"
#include "bench_chart.h"
#include "bench_pages.h"
#include "bench_scene.h"
#include "sc_bscan.h"
#include "sc_collider.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_png_sink.h"
#include "sc_pool_linux.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"
#include "sc_udp_display.h"

static sc_tissue g_t;
static sc_test_scene g_scene;
static sc_bscan g_bscan;

/* the solvers of bench_scene.h, then Bullet */
typedef enum method {
    M_MSDS = BENCH_MSDS,
    M_FEM = BENCH_FEM,
    M_COROT = BENCH_COROT,
    M_COUNT = BENCH_METHODS,
    M_BULLET = M_COUNT
} method;
static const char *const k_method_name[M_COUNT + 1] = {"msds", "fem", "corot", "bullet"};

typedef struct opts {
    bench_opts b;
    int bullet;
    const char *sink; /* "png", "none", "udp:HOST:PORT" */
    const char *png_dir, *csv, *png, *png_cpu;
} opts;

/* one row of the tables: medians over runs, spread of the step */
typedef struct row {
    int valid;
    uint32_t nodes, tets;
    double step, step_min, step_max, cpu, coll, sampl, out, with_out, with_min, with_max;
    double sampl_cpu, out_cpu; /* CPU ms of the B-scan (least disturbed run): sampling the
                                  process's (all workers), output the frame thread's */
    double disp_mm;
    uint64_t hash;
} row;

static row g_rows[BENCH_MAX_LIST][M_COUNT + 1][BENCH_MAX_LIST]; /* mesh, method, workers index */

static int usage(void)
{
    fprintf(stderr,
            "usage: bench-paper [--frames N] [--repeats R] [--workers 1,2] "
            "[--meshes 20x10x10,...] [--methods msds,fem,corot] [--sink png|none|udp:HOST:PORT] "
            "[--png-dir DIR] [--bullet on|off] [--csv FILE] [--png FILE] [--png-cpu FILE]\n");
    return 2;
}

/* "udp:HOST:PORT" -> host (into buf) and port; 0 or -1 */
static int parse_udp(const char *s, char *host, size_t hostn, uint16_t *port)
{
    if (strncmp(s, "udp:", 4) != 0) {
        return -1;
    }
    const char *h = s + 4, *colon = strrchr(h, ':');
    if (!colon || colon == h || (size_t)(colon - h) >= hostn) {
        return -1;
    }
    char *end = NULL;
    uint32_t p;
    if (bench_parse_u32(colon + 1, 1u, 65535u, &p, &end) || *end) {
        return -1;
    }
    memcpy(host, h, (size_t)(colon - h));
    host[colon - h] = '\0';
    *port = (uint16_t)p;
    return 0;
}

static int parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    static const int msds_fem[BENCH_METHODS] = {1, 1, 0};
    bench_opts_default(&o->b, 20, msds_fem);
    o->bullet = 1;
    o->sink = "png";
    o->png_dir = "out/bench-paper/frames";
    o->csv = "out/bench-paper/bench-paper.csv";
    o->png = "out/bench-paper/fig9.png";
    o->png_cpu = "out/bench-paper/fig9-cpu.png";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (i + 1 >= argc) {
            return usage();
        }
        const char *v = argv[++i];
        const int c = bench_opts_parse(&o->b, a, v);
        if (c < 0) {
            return usage();
        }
        if (c > 0) {
            continue;
        }
        if (strcmp(a, "--sink") == 0) {
            char host[256];
            uint16_t port;
            if (strcmp(v, "png") != 0 && strcmp(v, "none") != 0 &&
                parse_udp(v, host, sizeof host, &port) != 0) {
                return usage();
            }
            o->sink = v;
        } else if (strcmp(a, "--bullet") == 0) {
            if (strcmp(v, "on") == 0) {
                o->bullet = 1;
            } else if (strcmp(v, "off") == 0) {
                o->bullet = 0;
            } else {
                return usage();
            }
        } else if (strcmp(a, "--png-dir") == 0) {
            o->png_dir = v;
        } else if (strcmp(a, "--csv") == 0) {
            o->csv = v;
        } else if (strcmp(a, "--png") == 0) {
            o->png = v;
        } else if (strcmp(a, "--png-cpu") == 0) {
            o->png_cpu = v;
        } else {
            return usage();
        }
    }
    return 0;
}

/* ---- displays ------------------------------------------------------------------------- */

static int null_begin(void *ctx, const sc_display_frame_info *info)
{
    (void)ctx;
    (void)info;
    return SC_OK;
}

static int null_line(void *ctx, uint32_t frame_no, uint16_t line, const uint8_t *s, uint16_t n)
{
    (void)ctx;
    (void)frame_no;
    (void)line;
    (void)s;
    (void)n;
    return SC_OK;
}

static int null_end(void *ctx, const sc_display_end_info *end)
{
    (void)ctx;
    (void)end;
    return SC_OK;
}

static const sc_display_ops k_null_ops = {null_begin, null_line, null_end, NULL, NULL, NULL};
static const sc_display_dev k_null_dev = {&k_null_ops, NULL};

typedef struct sink {
    sc_display_dev dev;
    sc_png_sink *png;
    sc_udp_display udp;
    int is_udp;
} sink;

static sink g_sink;

static int mkdirs(const char *path)
{
    char buf[1024];
    if (strlen(path) >= sizeof buf) {
        return -1;
    }
    strcpy(buf, path);
    for (char *p = buf + 1; *p; p++) {
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
                return -1;
            }
            *p = '/';
        }
    }
    return (mkdir(buf, 0777) != 0 && errno != EEXIST) ? -1 : 0;
}

/* the parent folder of a file path */
static int mkparent(const char *file)
{
    char buf[1024];
    const char *slash = strrchr(file, '/');
    if (!slash || slash == file) {
        return 0;
    }
    if ((size_t)(slash - file) >= sizeof buf) {
        return -1;
    }
    memcpy(buf, file, (size_t)(slash - file));
    buf[slash - file] = '\0';
    return mkdirs(buf);
}

static int sink_open(const opts *o, sink *s)
{
    memset(s, 0, sizeof *s);
    if (strcmp(o->sink, "none") == 0) {
        s->dev = k_null_dev;
        return 0;
    }
    if (strcmp(o->sink, "png") == 0) {
        if (mkdirs(o->png_dir) != 0) {
            fprintf(stderr, "bench-paper: %s: %s\n", o->png_dir, strerror(errno));
            return -1;
        }
        const sc_png_sink_def d = {o->png_dir, 0u, 0u, 1u, 0u};
        const int rc = sc_png_sink_open(&s->png, &d);
        if (rc != SC_OK) {
            fprintf(stderr, "bench-paper: PNG sink in %s: %s\n", o->png_dir, sc_err_name(rc));
            return -1;
        }
        s->dev = sc_png_sink_dev(s->png);
        return 0;
    }
    char host[256];
    sc_udp_display_def d = sc_udp_display_default_def();
    if (parse_udp(o->sink, host, sizeof host, &d.port) != 0) {
        return -1;
    }
    d.host = host;
    const int rc = sc_udp_display_open(&s->udp, &d);
    if (rc != SC_OK) {
        fprintf(stderr, "bench-paper: display link %s: %s\n", o->sink, sc_err_name(rc));
        return -1;
    }
    s->is_udp = 1;
    s->dev = sc_udp_display_dev(&s->udp);
    return 0;
}

static void sink_close(sink *s)
{
    if (s->png) {
        sc_png_sink_stats st;
        sc_png_sink_get_stats(s->png, &st);
        printf("PNG sink: %llu frames, %llu written, %llu skipped (writer busy), %llu write "
               "errors\n",
               (unsigned long long)st.frames, (unsigned long long)st.frames_written,
               (unsigned long long)st.frames_busy, (unsigned long long)st.write_errors);
        sc_png_sink_close(s->png);
    }
    if (s->is_udp) {
        printf("display link: %llu frames, %llu lines sent, %llu dropped, %llu send errors\n",
               (unsigned long long)s->udp.frames, (unsigned long long)s->udp.lines_sent,
               (unsigned long long)s->udp.lines_dropped, (unsigned long long)s->udp.send_errors);
        sc_udp_display_close(&s->udp);
    }
}

/* ---- ours ----------------------------------------------------------------------------- */

static void csv_row(FILE *csv, const uint32_t mesh[3], uint32_t nodes, uint32_t tets, int m,
                    uint32_t w, int run, int frames, double step, double cpu, double coll,
                    double sampl, double out, double disp, double sampl_cpu, double out_cpu)
{
    if (!csv) {
        return;
    }
    fprintf(csv, "%ux%ux%u,%u,%u,%s,%u,%d,%d,%.4f,%.4f,", mesh[0], mesh[1], mesh[2], nodes, tets,
            k_method_name[m], (unsigned)w, run, frames, step, cpu);
    if (m == M_BULLET) {
        fprintf(csv, ",,,,%.2f,,%.3f,,\n", 1000.0 / step, disp);
    } else {
        fprintf(csv, "%.4f,%.4f,%.4f,%.4f,%.2f,%.2f,%.3f,%.4f,%.4f\n", coll, sampl, out, step + out,
                1000.0 / step, 1000.0 / (step + out), disp, sampl_cpu, out_cpu);
    }
}

/* build, press, then `repeats` runs of `frames` frames; pool may be NULL */
static int bench_ours(const uint32_t mesh[3], method m, const sc_pool_dev *pool, uint32_t w,
                      const opts *o, row *out, FILE *csv)
{
    sc_pose pose;
    sc_collider_grid g;
    int rc = bench_scene_press(&g_t, &g_scene, mesh, (bench_method)m, pool, &pose, &g);
    if (rc != SC_OK) {
        return rc;
    }
    const sc_bscan_def bd = sc_bscan_default_def();
    if ((rc = sc_bscan_init(&g_bscan, &bd)) != SC_OK ||
        (rc = sc_bscan_attach_mesh(&g_bscan, &g_t.mesh)) != SC_OK) {
        return rc;
    }
    sc_bscan_set_pool(&g_bscan, pool); /* its lines on the step's workers, as in the engine */
    const sc_xform to_volume = sc_xform_from_pose(&pose);
    static sc_contact_set cs;
    static uint64_t st[BENCH_MAX_FRAMES], cp[BENCH_MAX_FRAMES], co[BENCH_MAX_FRAMES],
        sa[BENCH_MAX_FRAMES], ou[BENCH_MAX_FRAMES], wo[BENCH_MAX_FRAMES], sac[BENCH_MAX_FRAMES],
        ouc[BENCH_MAX_FRAMES];
    double r_step[BENCH_MAX_REPEATS], r_cpu[BENCH_MAX_REPEATS], r_coll[BENCH_MAX_REPEATS],
        r_sampl[BENCH_MAX_REPEATS], r_out[BENCH_MAX_REPEATS], r_with[BENCH_MAX_REPEATS],
        r_sac[BENCH_MAX_REPEATS], r_ouc[BENCH_MAX_REPEATS];
    static uint32_t frame_no;
    for (int r = 0; r < o->b.repeats; r++) {
        for (int f = 0; f < o->b.frames; f++) {
            const uint64_t c0 = bench_cpu_ns();
            const uint64_t t0 = bench_now_ns();
            rc = sc_tissue_step(&g_t, &pose);
            const uint64_t t1 = bench_now_ns();
            cp[f] = bench_cpu_ns() - c0;
            if (rc != SC_OK) {
                return rc;
            }
            sc_collider_detect(&g_t.collider, &g, g_t.nodes.x, g_t.nodes.y, g_t.nodes.z,
                               g_t.mesh.node_fixed, g_t.stats.max_disp_mm, &cs);
            /* the sampling's CPU: the process's (the pool's workers included, as the step's;
             * with the PNG sink its writer thread's too: read it with --sink none) */
            const uint64_t c2 = bench_cpu_ns();
            const uint64_t t2 = bench_now_ns();
            const int contact = g_t.stats.contacts > 0u;
            rc = sc_bscan_frame(&g_bscan, &g_t.mesh, &g_t.nodes, &g_scene.vol, &to_volume, contact,
                                &k_null_dev, frame_no);
            const uint64_t t3 = bench_now_ns();
            const uint64_t c3s = bench_cpu_ns();
            const uint64_t c3 = bench_thread_cpu_ns();
            if (rc != SC_OK) {
                return rc;
            }
            /* frame numbers cycle over 8 so the PNG sink overwrites 8 files */
            rc = sc_bscan_frame(&g_bscan, &g_t.mesh, &g_t.nodes, &g_scene.vol, &to_volume, contact,
                                &g_sink.dev, frame_no % 8u);
            const uint64_t t4 = bench_now_ns();
            ouc[f] = bench_thread_cpu_ns() - c3;
            sac[f] = c3s - c2;
            frame_no++;
            /* a sink still busy with the last frame (the PNG writer) or a link down is the
             * sink's count, as in the engine (imaging_errors) */
            if (rc != SC_OK && rc != SC_ERR_WOULD_BLOCK && rc != SC_ERR_IO) {
                return rc;
            }
            st[f] = t1 - t0;
            co[f] = t2 - t1;
            sa[f] = t3 - t2;
            ou[f] = t4 - t3;
            wo[f] = st[f] + ou[f];
        }
        r_step[r] = bench_median_ms(st, o->b.frames);
        r_cpu[r] = bench_median_ms(cp, o->b.frames);
        r_coll[r] = bench_median_ms(co, o->b.frames);
        r_sampl[r] = bench_median_ms(sa, o->b.frames);
        r_out[r] = bench_median_ms(ou, o->b.frames);
        r_with[r] = bench_median_ms(wo, o->b.frames);
        r_sac[r] = bench_median_ms(sac, o->b.frames);
        r_ouc[r] = bench_median_ms(ouc, o->b.frames);
        csv_row(csv, mesh, g_t.mesh.node_count, g_t.mesh.tet_count, (int)m, w, r, o->b.frames,
                r_step[r], r_cpu[r], r_coll[r], r_sampl[r], r_out[r], g_t.stats.max_disp_mm,
                r_sac[r], r_ouc[r]);
    }
    out->valid = 1;
    out->nodes = g_t.mesh.node_count;
    out->tets = g_t.mesh.tet_count;
    out->step = bench_median_d(r_step, o->b.repeats);
    out->step_min = r_step[0];
    out->step_max = r_step[o->b.repeats - 1];
    qsort(r_cpu, (size_t)o->b.repeats, sizeof r_cpu[0], bench_cmp_d);
    out->cpu = r_cpu[0]; /* the least disturbed run, as bench-scale */
    qsort(r_sac, (size_t)o->b.repeats, sizeof r_sac[0], bench_cmp_d);
    qsort(r_ouc, (size_t)o->b.repeats, sizeof r_ouc[0], bench_cmp_d);
    out->sampl_cpu = r_sac[0];
    out->out_cpu = r_ouc[0];
    out->coll = bench_median_d(r_coll, o->b.repeats);
    out->sampl = bench_median_d(r_sampl, o->b.repeats);
    out->out = bench_median_d(r_out, o->b.repeats);
    out->with_out = bench_median_d(r_with, o->b.repeats);
    out->with_min = r_with[0];
    out->with_max = r_with[o->b.repeats - 1];
    out->disp_mm = g_t.stats.max_disp_mm;
    out->hash = sc_tissue_state_hash(&g_t);
    return 0;
}

/* ---- Bullet --------------------------------------------------------------------------- */

static int bench_bullet(const uint32_t mesh[3], const opts *o, row *out, FILE *csv)
{
    /* our mesh (nodes, tets, fixed nodes) from a build of the scene: the MSDS build's mesh
     * phase is the same for every method */
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = mesh[0];
    p.ny = mesh[1];
    p.nz = mesh[2];
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def d = sc_test_scene_tissue_def(&g_scene, SC_TISSUE_MSDS);
    d.skin_enabled = 0u;
    sc_material_table mat;
    sc_material_table_default(&mat);
    int rc = sc_tissue_build_begin(&g_t, &d, &g_scene.vol, &mat, SC_LABEL_FAT);
    while (rc == SC_OK && g_t.build_phase <= (uint8_t)SC_TISSUE_BUILD_MESH) {
        rc = sc_tissue_build_step(&g_t);
    }
    if (rc != SC_OK && rc != 1) {
        return rc;
    }
    const sc_mesh *sm = &g_t.mesh;
    const bb_mesh bm = {sm->node_count,
                        sm->tet_count,
                        sm->rest_x,
                        sm->rest_y,
                        sm->rest_z,
                        (const uint32_t(*)[4])sm->tet,
                        sm->node_fixed,
                        {g_scene.p.size_mm[0], g_scene.p.size_mm[1], g_scene.p.size_mm[2]},
                        {g_scene.p.probe_x_mm, g_scene.p.probe_y_mm},
                        {g_scene.p.probe_half_mm[0], g_scene.p.probe_half_mm[1]}};
    char err[200] = "";
    bb_sim *s = bb_create(&bm, err, sizeof err);
    if (!s) {
        fprintf(stderr, "bench-paper: Bullet: %s\n", err);
        return SC_ERR_INVALID_ARG;
    }
    for (int f = 0; f < 30; f++) {
        bb_set_probe(s, -0.5f + 3.5f * (float)(f + 1) / 30.0f);
        bb_step(s);
    }
    bb_set_probe(s, 3.0f);
    static uint64_t st[BENCH_MAX_FRAMES], cp[BENCH_MAX_FRAMES];
    double r_step[BENCH_MAX_REPEATS], r_cpu[BENCH_MAX_REPEATS];
    for (int r = 0; r < o->b.repeats; r++) {
        for (int f = 0; f < o->b.frames; f++) {
            const uint64_t c0 = bench_cpu_ns();
            const uint64_t t0 = bench_now_ns();
            bb_step(s);
            st[f] = bench_now_ns() - t0;
            cp[f] = bench_cpu_ns() - c0;
        }
        r_step[r] = bench_median_ms(st, o->b.frames);
        r_cpu[r] = bench_median_ms(cp, o->b.frames);
        csv_row(csv, mesh, sm->node_count, sm->tet_count, M_BULLET, 1u, r, o->b.frames, r_step[r],
                r_cpu[r], 0.0, 0.0, 0.0, bb_max_disp_mm(s), 0.0, 0.0);
    }
    out->valid = 1;
    out->nodes = sm->node_count;
    out->tets = sm->tet_count;
    out->step = bench_median_d(r_step, o->b.repeats);
    out->step_min = r_step[0];
    out->step_max = r_step[o->b.repeats - 1];
    qsort(r_cpu, (size_t)o->b.repeats, sizeof r_cpu[0], bench_cmp_d);
    out->cpu = r_cpu[0];
    out->disp_mm = bb_max_disp_mm(s);
    out->coll = out->sampl = out->out = out->with_out = -1.0;
    printf("  bullet %ux%ux%u: %u nodes, %u tets, %u links, max displacement %.2f mm\n", mesh[0],
           mesh[1], mesh[2], sm->node_count, sm->tet_count, bb_links(s), out->disp_mm);
    bb_destroy(s);
    return 0;
}

/* ---- tables and figure ---------------------------------------------------------------- */

/* the paper's Table I and II (its 2013 laptop), for its four meshes; -1: not in the paper */
static void paper_figures(const uint32_t mesh[3], double *msds, double *fem, double *fps_no,
                          double *fps_vis, double *fps_no_fem, double *fps_vis_fem)
{
    static const uint32_t pm[4] = {20, 24, 28, 32};
    static const double ms[4] = {10, 17, 27, 40}, fe[4] = {30, 60, 100, 150};
    static const double no[4] = {20, 16, 15, 12}, nof[4] = {15, 10, 6.8, 5.0};
    static const double vi[4] = {12, 10, 8.6, 8.5}, vif[4] = {8.6, 7.4, 5.5, 4.3};
    *msds = *fem = *fps_no = *fps_vis = *fps_no_fem = *fps_vis_fem = -1.0;
    for (int i = 0; i < 4; i++) {
        if (mesh[0] == pm[i] && mesh[1] == pm[i] / 2u && mesh[2] == pm[i] / 2u) {
            *msds = ms[i];
            *fem = fe[i];
            *fps_no = no[i];
            *fps_vis = vi[i];
            *fps_no_fem = nof[i];
            *fps_vis_fem = vif[i];
        }
    }
}

static void print_tables(const opts *o)
{
    printf("\nTable I (ms per frame. wall: median over runs of the runs' medians, [min..max of "
           "them]; cpu: CPU time, least disturbed run's median: the step's process CPU (all "
           "workers), the B-scan's: sampling process CPU (all workers), output frame-thread CPU)\n");
    printf("%-9s %6s %7s %-6s %2s %9s %21s %8s %8s %9s %9s %8s %8s %7s | %s\n", "mesh", "nodes",
           "tets", "method", "w", "step wall", "spread", "step cpu", "coll", "sampl wal",
           "sampl cpu", "out wall", "out cpu", "disp mm", "paper ms");
    for (int mi = 0; mi < o->b.nmesh; mi++) {
        double pms, pfe, a, b, c, dd;
        paper_figures(o->b.mesh[mi], &pms, &pfe, &a, &b, &c, &dd);
        for (int m = 0; m <= M_COUNT; m++) {
            for (int wi = 0; wi < o->b.nworkers; wi++) {
                const row *r = &g_rows[mi][m][wi];
                if (!r->valid) {
                    continue;
                }
                const double paper = m == M_MSDS ? pms : (m == M_FEM ? pfe : -1.0);
                char pbuf[32] = "-";
                if (paper > 0.0) {
                    snprintf(pbuf, sizeof pbuf, "%.0f", paper);
                }
                if (m == M_BULLET) {
                    printf("%2ux%2ux%2u  %6u %7u %-6s %2u %9.3f %9.3f..%9.3f %8.3f %8s %9s %9s "
                           "%8s %8s %7.2f | %s\n",
                           o->b.mesh[mi][0], o->b.mesh[mi][1], o->b.mesh[mi][2], r->nodes, r->tets,
                           k_method_name[m], 1u, r->step, r->step_min, r->step_max, r->cpu, "-",
                           "-", "-", "-", "-", r->disp_mm, pbuf);
                } else {
                    printf("%2ux%2ux%2u  %6u %7u %-6s %2u %9.3f %9.3f..%9.3f %8.3f %8.3f %9.3f "
                           "%9.3f %8.3f %8.3f %7.2f | %s\n",
                           o->b.mesh[mi][0], o->b.mesh[mi][1], o->b.mesh[mi][2], r->nodes, r->tets,
                           k_method_name[m], (unsigned)o->b.workers[wi], r->step, r->step_min,
                           r->step_max, r->cpu, r->coll, r->sampl, r->sampl_cpu, r->out, r->out_cpu,
                           r->disp_mm, pbuf);
                }
            }
        }
    }
    printf("\nTable II (frames per second. without output = 1000 / step, with output = 1000 / "
           "(step + B-scan into the %s sink); wall: median [slowest .. fastest run]; cpu: from "
           "the CPU times of Table I)\n",
           o->sink);
    printf("%-9s %-6s %2s %9s %19s %9s %19s %9s %9s | %s\n", "mesh", "method", "w", "no out",
           "spread", "with out", "spread", "no out cpu", "out cpu", "paper no vis (vis)");
    for (int mi = 0; mi < o->b.nmesh; mi++) {
        double pms, pfe, no, vis, nof, visf;
        paper_figures(o->b.mesh[mi], &pms, &pfe, &no, &vis, &nof, &visf);
        for (int m = 0; m < M_COUNT; m++) {
            for (int wi = 0; wi < o->b.nworkers; wi++) {
                const row *r = &g_rows[mi][m][wi];
                if (!r->valid) {
                    continue;
                }
                char pbuf[48] = "-";
                if (m == M_MSDS && no > 0.0) {
                    snprintf(pbuf, sizeof pbuf, "%.3g (%.3g)", no, vis);
                } else if (m == M_FEM && nof > 0.0) {
                    snprintf(pbuf, sizeof pbuf, "%.3g (%.3g)", nof, visf);
                }
                printf("%2ux%2ux%2u  %-6s %2u %9.1f %8.1f..%8.1f %9.1f %8.1f..%8.1f %10.1f %9.1f "
                       "| %s\n",
                       o->b.mesh[mi][0], o->b.mesh[mi][1], o->b.mesh[mi][2], k_method_name[m],
                       (unsigned)o->b.workers[wi], 1000.0 / r->step, 1000.0 / r->step_max,
                       1000.0 / r->step_min, 1000.0 / r->with_out, 1000.0 / r->with_max,
                       1000.0 / r->with_min, 1000.0 / r->cpu, 1000.0 / (r->cpu + r->out_cpu), pbuf);
            }
        }
    }
}

/* cpu: the step's process CPU time (least disturbed run) instead of the wall median */
static int write_chart(const opts *o, int cpu, const char *path)
{
    static chart c;
    _Static_assert(BENCH_MAX_LIST <= CHART_MAX_GROUPS, "a chart group per mesh");
    static char gname[BENCH_MAX_LIST][16], sname[CHART_MAX_SERIES][24];
    memset(&c, 0, sizeof c);
    c.title = cpu ? "FIG. 9: SOFT-TISSUE STEP, CPU MS PER FRAME (ALL WORKERS), LOG SCALE"
                  : "FIG. 9: SOFT-TISSUE STEP, WALL MS PER FRAME (MEDIAN), LOG SCALE";
    c.y_label = "MS PER FRAME";
    c.y_min = 0.01;
    c.y_max = 1000.0;
    c.groups = o->b.nmesh;
    static const uint8_t pal[CHART_MAX_SERIES][3] = {
        {31, 119, 180},  {120, 170, 220}, {214, 39, 40}, {240, 140, 140},
        {148, 103, 189}, {44, 160, 44},   {90, 90, 90},  {180, 180, 180}};
    int ns = 0;
    int map_m[CHART_MAX_SERIES], map_w[CHART_MAX_SERIES];
    for (int m = 0; m < M_COUNT; m++) {
        for (int wi = 0; wi < o->b.nworkers && o->b.method_on[m]; wi++) {
            if (ns < CHART_MAX_SERIES - 3) {
                map_m[ns] = m;
                map_w[ns] = wi;
                snprintf(sname[ns], sizeof sname[ns], "%s %uW",
                         m == M_MSDS ? "MSDS" : (m == M_FEM ? "FEM" : "COROT FEM"),
                         (unsigned)o->b.workers[wi]);
                ns++;
            }
        }
    }
    int bullet_s = -1, paper_s = ns + (o->bullet && bb_available() ? 1 : 0);
    if (o->bullet && bb_available()) {
        bullet_s = ns;
        snprintf(sname[ns++], sizeof sname[0], "BULLET 1W");
    }
    snprintf(sname[ns++], sizeof sname[0], "PAPER MSDS");
    snprintf(sname[ns++], sizeof sname[0], "PAPER FEM");
    c.series = ns;
    for (int s = 0; s < ns; s++) {
        c.series_name[s] = sname[s];
        memcpy(c.series_rgb[s], pal[(s < paper_s) ? s : (CHART_MAX_SERIES - 2 + s - paper_s)], 3);
    }
    for (int mi = 0; mi < o->b.nmesh; mi++) {
        snprintf(gname[mi], sizeof gname[mi], "%ux%ux%u", o->b.mesh[mi][0], o->b.mesh[mi][1],
                 o->b.mesh[mi][2]);
        c.group_name[mi] = gname[mi];
        for (int s = 0; s < ns; s++) {
            c.value[mi][s] = -1.0;
        }
        for (int s = 0; s < paper_s - (bullet_s >= 0 ? 1 : 0); s++) {
            const row *r = &g_rows[mi][map_m[s]][map_w[s]];
            c.value[mi][s] = r->valid ? (cpu ? r->cpu : r->step) : -1.0;
        }
        if (bullet_s >= 0 && g_rows[mi][M_BULLET][0].valid) {
            c.value[mi][bullet_s] =
                cpu ? g_rows[mi][M_BULLET][0].cpu : g_rows[mi][M_BULLET][0].step;
        }
        double pms, pfe, a, b, cc, dd;
        paper_figures(o->b.mesh[mi], &pms, &pfe, &a, &b, &cc, &dd);
        c.value[mi][paper_s] = pms;
        c.value[mi][paper_s + 1] = pfe;
    }
    if (mkparent(path) != 0 || chart_write_png(&c, path) != 0) {
        fprintf(stderr, "bench-paper: cannot write %s\n", path);
        return -1;
    }
    printf("Fig. 9 (%s): %s\n", cpu ? "CPU time" : "wall clock", path);
    return 0;
}

int main(int argc, char **argv)
{
    static opts o;
    const int prc = parse_args(argc, argv, &o);
    if (prc != 0) {
        return prc;
    }
    bench_select_kernels("bench-paper"); /* the engine's variant, as sonocomp selects it */
    printf("pages: %s\n", bench_pages(&g_t, sizeof g_t));
    (void)bench_pages(&g_bscan, sizeof g_bscan);
    if (mkparent(o.csv) != 0) {
        fprintf(stderr, "bench-paper: cannot create the folder of %s\n", o.csv);
        return 1;
    }
    FILE *csv = fopen(o.csv, "w");
    if (!csv) {
        fprintf(stderr, "bench-paper: %s: %s\n", o.csv, strerror(errno));
        return 1;
    }
    fprintf(csv, "mesh,nodes,tets,method,workers,run,frames,step_ms,step_cpu_ms,collision_ms,"
                 "sampling_ms,output_ms,frame_with_output_ms,fps_without_output,"
                 "fps_with_output,max_disp_mm,sampling_cpu_ms,output_cpu_ms\n");
    if (sink_open(&o, &g_sink) != 0) {
        fclose(csv);
        return 1;
    }
    if (o.bullet && !bb_available()) {
        printf("bench-paper: Bullet was not found at configure time (libbullet-dev): its rows "
               "are left out\n");
    }
    printf("bench-paper: %d runs x %d frames per row, wall clock; sink %s\n", o.b.repeats,
           o.b.frames, o.sink);
    int status = 0;
    for (int mi = 0; mi < o.b.nmesh && status == 0; mi++) {
        for (int m = 0; m < M_COUNT; m++) {
            if (!o.b.method_on[m]) {
                continue;
            }
            uint64_t ref_hash = 0u;
            for (int wi = 0; wi < o.b.nworkers; wi++) {
                const uint32_t w = o.b.workers[wi];
                static sc_pool_linux lp;
                sc_pool_dev dev = {0};
                if (w > 1u && sc_pool_linux_start(&lp, w, 0, 200u, &dev) != 0) {
                    fprintf(stderr, "bench-paper: cannot start %u workers\n", (unsigned)w);
                    status = 1;
                    break;
                }
                row *r = &g_rows[mi][m][wi];
                const int rc =
                    bench_ours(o.b.mesh[mi], (method)m, w > 1u ? &dev : NULL, w, &o, r, csv);
                if (w > 1u) {
                    sc_pool_linux_stop(&lp);
                }
                if (rc != 0) {
                    fprintf(stderr, "bench-paper: %ux%ux%u %s: %s\n", o.b.mesh[mi][0],
                            o.b.mesh[mi][1], o.b.mesh[mi][2], k_method_name[m], sc_err_name(rc));
                    status = 1;
                    break;
                }
                if (wi == 0) {
                    ref_hash = r->hash;
                } else if (r->hash != ref_hash) {
                    fprintf(stderr,
                            "bench-paper: %ux%ux%u %s: %u workers end in another state "
                            "than %u\n",
                            o.b.mesh[mi][0], o.b.mesh[mi][1], o.b.mesh[mi][2], k_method_name[m],
                            (unsigned)w, (unsigned)o.b.workers[0]);
                    status = 1;
                }
                printf("  %ux%ux%u %s %uw: step %.3f ms (%.3f..%.3f), with output %.3f ms\n",
                       o.b.mesh[mi][0], o.b.mesh[mi][1], o.b.mesh[mi][2], k_method_name[m],
                       (unsigned)w, r->step, r->step_min, r->step_max, r->with_out);
                fflush(stdout);
            }
        }
        if (o.bullet && bb_available() && status == 0) {
            const int rc = bench_bullet(o.b.mesh[mi], &o, &g_rows[mi][M_BULLET][0], csv);
            if (rc != 0) {
                status = 1;
            }
            fflush(stdout);
        }
    }
    sink_close(&g_sink);
    if (fclose(csv) != 0) {
        fprintf(stderr, "bench-paper: %s: %s\n", o.csv, strerror(errno));
        status = 1;
    }
    print_tables(&o);
    if (write_chart(&o, 0, o.png) != 0 || write_chart(&o, 1, o.png_cpu) != 0) {
        status = 1;
    }
    printf("CSV: %s\n", o.csv);
    return status;
}
