/* bench_bscan: B-scan synthesis time per frame, walker vs the paper's region path (R = 32),
 * for the four mesh sizes of the paper's Table I at 256x512 and 512x512 pixels, under a deep
 * compression (a 10 mm dent of the generated scene); and PNGs of compression sweeps.
 *
 * Usage: bench_bscan [png_dir] [frames]     (defaults: bscan_png, 40)
 *        bench_bscan contact [cases_dir] [case] [frames] [msds|fem] [workers]
 *                    the engine's contact case (bench_contact.c): a host-simulated engine
 *                    presses a built case (default neck-ijv from the build's cases folder) and
 *                    the deformed mesh at the deepest point of the press script is imaged
 *        bench_bscan contact-walker [cases_dir] [case] [frames] [acoustics|no-acoustics]
 *        bench_bscan contact-hold [cases_dir] [case] [frames]
 *                    for callgrind: walker frames / whole engine frames (bench_contact.h)
 * Prints a table; run it from a Release build (build/release).
 */
#define _POSIX_C_SOURCE 200809L
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "bench_machine.h"
#include "bench_contact.h"
#include "sc_cpu.h"
#include "sc_simd.h"
#include "bscan_scene.h"
#include "sc_bscan.h"
#include "sc_doppler.h"
#include "sc_needle.h"
#include "sc_err.h"

static scn_volume g_vol;
static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_bscan g_b;
static uint8_t g_img[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];

/* A display that keeps the frame (line-major), as the display controller would. */
typedef struct keep_display {
    uint16_t samples;
    uint32_t lines;
} keep_display;

static int kd_begin(void *ctx, const sc_display_frame_info *info)
{
    keep_display *k = ctx;
    k->samples = info->samples;
    k->lines = 0;
    return SC_OK;
}

static int kd_line(void *ctx, uint32_t frame_no, uint16_t line, const uint8_t *s, uint16_t n)
{
    keep_display *k = ctx;
    (void)frame_no;
    memcpy(&g_img[(size_t)line * k->samples], s, n);
    k->lines++;
    return SC_OK;
}

static int kd_end(void *ctx, const sc_display_end_info *end)
{
    (void)ctx;
    (void)end;
    return SC_OK;
}

static const sc_display_ops kd_ops = {kd_begin, kd_line, kd_end, NULL, NULL, NULL};
static keep_display g_kd;
static const sc_display_dev g_dev = {&kd_ops, &g_kd};

/* Thread CPU time: the machine is shared, wall time would count other people's work. */
static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void build_mesh(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = nx;
    md.ny = ny;
    md.nz = nz;
    if (sc_mesh_build(&g_mesh, &md) != SC_OK) {
        fprintf(stderr, "mesh build failed\n");
        exit(1);
    }
}

static int write_gray_png(const char *path, const uint8_t *out, uint32_t w, uint32_t h);

/* Write the current image: rows are depth samples. Linear images are resampled to square
 * pixels (nearest) so they look right; curvilinear ones are scan-converted (nearest). */
static int write_png(const char *path, const sc_bscan_def *d)
{
    const uint32_t L = d->scan.lines_n, S = d->scan.samples_n;
    uint32_t w, h;
    static uint8_t out[1024 * 1024];
    const float px_mm = d->scan.depth_mm / (float)S;
    if (d->scan.kind == SC_SCAN_GEOM_LINEAR) {
        w = (uint32_t)(d->scan.width_mm / px_mm + 0.5f);
        h = S;
        if (w > 1024u) {
            w = 1024u;
        }
        for (uint32_t y = 0; y < h; y++) {
            for (uint32_t x = 0; x < w; x++) {
                uint32_t l = (uint32_t)(((float)x + 0.5f) / (float)w * (float)L);
                out[y * w + x] = g_img[(size_t)(l < L ? l : L - 1u) * S + y];
            }
        }
    } else {
        const float r0 = d->scan.radius_mm, depth = d->scan.depth_mm;
        const float half = d->scan.sector_deg * 3.14159265f / 360.0f;
        const float xmax = (r0 + depth) * sinf(half);
        const float ztop = r0 * cosf(half) - r0;
        w = (uint32_t)(2.0f * xmax / px_mm);
        h = (uint32_t)((depth - ztop) / px_mm);
        if (w > 1024u)
            w = 1024u;
        if (h > 1024u)
            h = 1024u;
        for (uint32_t y = 0; y < h; y++) {
            for (uint32_t x = 0; x < w; x++) {
                const float X = -xmax + ((float)x + 0.5f) * px_mm;
                const float Z = ztop + ((float)y + 0.5f) * px_mm + r0;
                const float r = sqrtf(X * X + Z * Z), th = atan2f(X, Z);
                const float fl = (th + 2.0f * half / 2.0f) / (2.0f * half) * (float)L;
                const float fk = (r - r0) / px_mm;
                uint8_t v = 0;
                if (fl >= 0.0f && fl < (float)L && fk >= 0.0f && fk < (float)S) {
                    v = g_img[(size_t)fl * S + (size_t)fk];
                }
                out[y * w + x] = v;
            }
        }
    }
    return write_gray_png(path, out, w, h);
}

static int write_gray_png(const char *path, const uint8_t *out, uint32_t w, uint32_t h)
{
    FILE *f = fopen(path, "wb");
    if (f == NULL) {
        return -1;
    }
    png_structp p = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(p);
    if (setjmp(png_jmpbuf(p))) {
        png_destroy_write_struct(&p, &info);
        fclose(f);
        return -1;
    }
    png_init_io(p, f);
    png_set_IHDR(p, info, w, h, 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(p, info);
    for (uint32_t y = 0; y < h; y++) {
        png_write_row(p, (png_const_bytep)&out[y * w]);
    }
    png_write_end(p, NULL);
    png_destroy_write_struct(&p, &info);
    fclose(f);
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median and worst ms per frame over `frames` frames. */
static double g_last_min;

static void time_frames(const sc_xform *probe, int frames, double *median, double *worst)
{
    static double t[1000];
    if (frames > 1000) {
        frames = 1000;
    }
    for (int i = 0; i < frames; i++) {
        const double t0 = now_ms();
        const int rc =
            sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, probe, 1, &g_dev, (uint32_t)i);
        t[i] = now_ms() - t0;
        if (rc != SC_OK) {
            fprintf(stderr, "frame failed: %s\n", sc_err_str(rc));
            exit(1);
        }
    }
    qsort(t, (size_t)frames, sizeof t[0], cmp_double);
    *median = t[frames / 2];
    *worst = t[frames - 1];
    g_last_min = t[0];
}

/* The target case (32x16x16, 256x512, walker, 10 mm dent) with the beam-dependent acoustics
 * on and off, so that their cost is its own line. */
static void print_acoustics_row(const sc_xform *probe, int frames)
{
    double med[2], worst[2], mn[2];
    for (int on = 0; on < 2; on++) {
        build_mesh(32, 16, 16);
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 10.0f);
        sc_bscan_def d = sc_bscan_default_def();
        d.acoustics = (uint32_t)on;
        sc_bscan_init(&g_b, &d);
        sc_bscan_attach_mesh(&g_b, &g_mesh);
        time_frames(probe, frames, &med[on], &worst[on]);
        mn[on] = g_last_min;
    }
    printf("acoustics (32x16x16 256x512 walk): off min %.3f / median %.3f ms, on min %.3f / "
           "median %.3f ms (+%.3f ms min)\n",
           mn[0], med[0], mn[1], med[1], mn[1] - mn[0]);
}

/* The speckle pass (sc_psf.h) on the target case: its cost is the frame with it minus the
 * frame without it (min of N). */
static void print_psf_row(const sc_xform *probe, int frames)
{
    double med[2], worst[2], mn[2];
    for (int on = 0; on < 2; on++) {
        build_mesh(32, 16, 16);
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 10.0f);
        sc_bscan_def d = sc_bscan_default_def();
        d.psf = (uint32_t)on;
        if (sc_bscan_init(&g_b, &d) != SC_OK) {
            printf("psf: not built (SC_BSCAN_PSF 0)\n");
            return;
        }
        sc_bscan_attach_mesh(&g_b, &g_mesh);
        time_frames(probe, frames, &med[on], &worst[on]);
        mn[on] = g_last_min;
    }
    printf("psf speckle (32x16x16 256x512 walk): off min %.3f / median %.3f ms, on min %.3f / "
           "median %.3f ms (+%.3f ms min)\n",
           mn[0], med[0], mn[1], med[1], mn[1] - mn[0]);
}

/* Colour + pulsed-wave Doppler (sc_doppler.h) on the target case: its cost is the frame with the
 * line hook minus the frame without it, default box (half the lines, 65 % of the depth) and the
 * whole image as box; the probe rolled 20 degrees about x so the vessels (along y) carry colour. */
static sc_doppler g_dop;
static void print_doppler_row(int frames)
{
    const float a = 20.0f * 3.14159265f / 180.0f;
    const sc_xform probe = {.r = {1.0f, 0.0f, 0.0f, 0.0f, cosf(a), -sinf(a), 0.0f, sinf(a), cosf(a)},
                            .t_mm = {20.0f, 10.0f, 10.0f}};
    double mn[3];
    uint32_t colour_px[3] = {0, 0, 0};
    for (int mode = 0; mode < 3; mode++) {
        build_mesh(32, 16, 16);
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 10.0f);
        sc_bscan_def d = sc_bscan_default_def();
        sc_bscan_init(&g_b, &d);
        sc_bscan_attach_mesh(&g_b, &g_mesh);
        sc_doppler_def dd = sc_doppler_default_def();
        if (mode == 2) {
            dd.box_u0 = dd.box_v0 = 0.0f;
            dd.box_u1 = dd.box_v1 = 1.0f;
        }
        sc_doppler_init(&g_dop, &dd);
        sc_doppler_attach_volume(&g_dop, &g_vol.v);
        static double t[1000];
        const int nf = frames > 1000 ? 1000 : frames;
        for (int i = 0; i < nf; i++) {
            const double t0 = now_ms();
            if (mode > 0) {
                sc_doppler_advance(&g_dop, 1.0f / 60.0f);
                sc_doppler_frame_begin(&g_dop, &g_b, &g_dev, (uint32_t)i);
            }
            sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &probe, 1, &g_dev, (uint32_t)i);
            t[i] = now_ms() - t0;
        }
        qsort(t, (size_t)nf, sizeof t[0], cmp_double);
        mn[mode] = t[0];
        colour_px[mode] = g_dop.status.colour_pixels;
    }
    printf("doppler (32x16x16 256x512 walk, probe rolled 20 deg): off min %.3f ms; default box "
           "min %.3f ms (+%.3f, %u colour px); whole-image box min %.3f ms (+%.3f, %u colour px)\n",
           mn[0], mn[1], mn[1] - mn[0], colour_px[1], mn[2], mn[2] - mn[0], colour_px[2]);
}

/* The tracked needle (sc_needle.h) on the target case: an in-plane needle drawn in the line
 * hook (20 mm at 30 degrees through the dent), its cost = with minus without. */
static sc_needle g_needle;
static void needle_hook(void *ctx, const sc_bscan_line_view *v)
{
    sc_needle_line(ctx, v);
}
static void print_needle_row(const sc_xform *probe, int frames)
{
    double mn[2];
    uint32_t drawn = 0;
    for (int on = 0; on < 2; on++) {
        build_mesh(32, 16, 16);
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 10.0f);
        sc_bscan_def d = sc_bscan_default_def();
        sc_bscan_init(&g_b, &d);
        sc_bscan_attach_mesh(&g_b, &g_mesh);
        const sc_needle_def nd = sc_needle_default_def();
        sc_needle_init(&g_needle, &nd);
        const float dir[3] = {0.866f, 0.0f, 0.5f};
        const float tip[3] = {probe->t_mm[0] + 2.0f, probe->t_mm[1], probe->t_mm[2] + 12.0f};
        sc_needle_set(&g_needle, 1, tip, dir, 20.0f);
        const sc_xform img2vol = sc_xform_compose(probe, &d.scan.image_to_probe);
        static double t[1000];
        const int nf = frames > 1000 ? 1000 : frames;
        for (int i = 0; i < nf; i++) {
            const double t0 = now_ms();
            if (on) {
                sc_needle_frame_begin(&g_needle, &img2vol);
                sc_bscan_set_line_hook(&g_b, needle_hook, &g_needle);
            }
            sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, probe, 1, &g_dev, (uint32_t)i);
            if (on) {
                (void)sc_needle_frame_end(&g_needle, &g_vol.v);
            }
            t[i] = now_ms() - t0;
        }
        qsort(t, (size_t)nf, sizeof t[0], cmp_double);
        mn[on] = t[0];
        drawn = g_needle.status.drawn_pixels;
    }
    printf("needle (32x16x16 256x512 walk, in plane, 20 mm): off min %.3f ms, on min %.3f ms "
           "(+%.3f, %u px drawn)\n",
           mn[0], mn[1], mn[1] - mn[0], drawn);
}

static void usage(FILE *f)
{
    fprintf(f, "usage: bench_bscan [png_dir] [frames]\n"
               "       bench_bscan contact [cases_dir] [case] [frames] [msds|fem] [workers]\n"
               "       bench_bscan contact-walker [cases_dir] [case] [frames] "
               "[acoustics|no-acoustics]\n"
               "       bench_bscan contact-hold [cases_dir] [case] [frames]\n");
}

int main(int argc, char **argv)
{
    if (argc > 1 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
        usage(stdout);
        return 0;
    }
    if (argc > 1 && argv[1][0] == '-') {
        /* an option it does not have, not a folder for the PNGs */
        fprintf(stderr, "bench_bscan: unknown option %s\n", argv[1]);
        usage(stderr);
        return 2;
    }
    /* the engine programs' kernel variant (sonocomp, sc-hostsim select it at start) */
    if (sc_cpu_select_simd() != SC_OK) {
        fprintf(stderr, "bench_bscan: SONOCOMP_SIMD names no variant of this CPU\n");
    }
    printf("kernels: %s\n", sc_simd_name(sc_simd_selected()));
    bench_print_machine();
    if (argc > 1 && strcmp(argv[1], "contact") == 0) {
        const char *cases = argc > 2 ? argv[2] : SC_DEFAULT_CASES_DIR;
        const char *name = argc > 3 ? argv[3] : "neck-ijv";
        const int n = argc > 4 ? atoi(argv[4]) : 40;
        const int method =
            argc > 5 ? (strcmp(argv[5], "fem") == 0 ? (int)SC_TISSUE_FEM : (int)SC_TISSUE_MSDS)
                     : -1;
        if (argc > 6) {
            const int w = atoi(argv[6]);
            if (w < 1 || w > 16) {
                fprintf(stderr, "bench_bscan: contact: workers 1..16, not %s\n", argv[6]);
                return 2;
            }
            bench_contact_set_workers((uint32_t)w);
        }
        return bench_contact_run(cases, name, method, n > 0 ? n : 40);
    }
    if (argc > 1 && strcmp(argv[1], "contact-walker") == 0) {
        const int n = argc > 4 ? atoi(argv[4]) : 10;
        const int acou = argc > 5 ? (strcmp(argv[5], "acoustics") == 0
                                         ? 1
                                         : (strcmp(argv[5], "no-acoustics") == 0 ? 0 : -2))
                                  : -1;
        if (acou == -2) {
            fprintf(stderr, "bench_bscan: contact-walker: acoustics or no-acoustics, not %s\n",
                    argv[5]);
            return 2;
        }
        return bench_contact_walker(argc > 2 ? argv[2] : SC_DEFAULT_CASES_DIR,
                                    argc > 3 ? argv[3] : "neck-ijv", n > 0 ? n : 10, acou);
    }
    if (argc > 1 && strcmp(argv[1], "contact-hold") == 0) {
        const int n = argc > 4 ? atoi(argv[4]) : 10;
        return bench_contact_hold(argc > 2 ? argv[2] : SC_DEFAULT_CASES_DIR,
                                  argc > 3 ? argv[3] : "neck-ijv", n > 0 ? n : 10);
    }
    const char *dir = argc > 1 ? argv[1] : "bscan_png";
    const int frames = argc > 2 ? atoi(argv[2]) : 40;
    scn_make_volume(&g_vol);
    mkdir(dir, 0755);

    static const uint32_t sizes[4][3] = {{20, 10, 10}, {24, 12, 12}, {28, 14, 14}, {32, 16, 16}};
    static const double paper_ms[4] = {14.0, 16.0, 20.0, 23.0};
    static const uint32_t lines_opt[2] = {256, 512};
    const float dent_mm = 10.0f;
    const sc_xform probe = scn_probe(20.0f, 10.0f, dent_mm, 0.0f);

    if (argc > 3 && strcmp(argv[3], "target") == 0) {
        /* the target case alone (for profiling): 32x16x16, 256x512, walker, 10 mm dent */
        build_mesh(32, 16, 16);
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, dent_mm);
        sc_bscan_def d = sc_bscan_default_def();
        sc_bscan_init(&g_b, &d);
        sc_bscan_attach_mesh(&g_b, &g_mesh);
        double med, worst;
        time_frames(&probe, frames, &med, &worst);
        printf("target: 32x16x16 256x512 walk: min %.3f, median %.3f ms, worst %.3f ms, steps %u, "
               "segments %u\n",
               g_last_min, med, worst, g_b.status.walk_steps, g_b.status.plane_hull_segments);
        /* the same without the mesh (sampling, display, areas only) */
        static double t[1000];
        const int nf = frames > 1000 ? 1000 : frames;
        for (int i = 0; i < nf; i++) {
            const double t0 = now_ms();
            sc_bscan_frame(&g_b, NULL, NULL, &g_vol.v, &probe, 1, &g_dev, (uint32_t)i);
            t[i] = now_ms() - t0;
        }
        qsort(t, (size_t)nf, sizeof t[0], cmp_double);
        printf("        same pose, no mesh (rigid): min %.3f, median %.3f ms\n", t[0], t[nf / 2]);
        print_acoustics_row(&probe, frames);
        print_psf_row(&probe, frames);
        print_doppler_row(frames);
        print_needle_row(&probe, frames);
        return 0;
    }
    printf("B-scan synthesis, CPU ms per frame (median / worst of %d), deep compression "
           "(%.0f mm dent), linear 38 x 60 mm probe, one core\n",
           frames, (double)dent_mm);
    printf("%-10s %6s %-9s %8s %8s %8s %8s %8s %8s %8s\n", "mesh", "tets", "image", "walk", "worst",
           "regions", "worst", "rigid", "in-mesh", "paper");
    for (int s = 0; s < 4; s++) {
        build_mesh(sizes[s][0], sizes[s][1], sizes[s][2]);
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, dent_mm);
        for (int li = 0; li < 2; li++) {
            sc_bscan_def d = sc_bscan_default_def();
            d.scan.lines_n = lines_opt[li];
            double med[3], worst[3];
            uint32_t in_mesh = 0;
            for (uint32_t mp = 0; mp < 2u; mp++) {
                d.mapper = mp;
                if (sc_bscan_init(&g_b, &d) != SC_OK ||
                    sc_bscan_attach_mesh(&g_b, &g_mesh) != SC_OK) {
                    fprintf(stderr, "init failed\n");
                    return 1;
                }
                time_frames(&probe, frames, &med[mp], &worst[mp]);
                if (mp == 0u) {
                    in_mesh = g_b.status.pixels_in_mesh;
                }
                if (g_b.status.walk_aborts || g_b.status.event_overflows ||
                    g_b.status.region_overflows) {
                    printf("  (degraded: aborts %u, event overflows %u, region overflows %u)\n",
                           g_b.status.walk_aborts, g_b.status.event_overflows,
                           g_b.status.region_overflows);
                }
            }
            /* baseline: the same frame with every pixel rigid (sampling + display only) */
            {
                double t0 = now_ms();
                for (int i = 0; i < frames; i++) {
                    sc_bscan_frame(&g_b, NULL, NULL, &g_vol.v, &probe, 1, &g_dev, (uint32_t)i);
                }
                med[2] = (now_ms() - t0) / frames;
                worst[2] = 0.0;
            }
            char msz[32], isz[32];
            snprintf(msz, sizeof msz, "%ux%ux%u", sizes[s][0], sizes[s][1], sizes[s][2]);
            snprintf(isz, sizeof isz, "%ux%u", d.scan.lines_n, d.scan.samples_n);
            printf("%-10s %6u %-9s %8.3f %8.3f %8.3f %8.3f %8.3f %8u %8.0f\n", msz,
                   g_mesh.tet_count, isz, med[0], worst[0], med[1], worst[1], med[2], in_mesh,
                   paper_ms[s]);
        }
    }
    printf("walk/regions: this engine's mappers (walk = default); rigid: sampling and display "
           "processing alone (mean); paper: Table I volume sampling, quad-core laptop 2012\n");
    print_acoustics_row(&probe, frames);
    print_psf_row(&probe, frames);
    print_doppler_row(frames);
    print_needle_row(&probe, frames);

    /* compression sweeps, 32x16x16, written as PNGs */
    build_mesh(32, 16, 16);
    sc_bscan_def d = sc_bscan_default_def();
    sc_bscan_init(&g_b, &d);
    sc_bscan_attach_mesh(&g_b, &g_mesh);
    char path[512];
    printf("\ncompression sweeps (32x16x16, walker): vein / artery area now vs rest\n");
    printf("%-6s %8s %8s %8s\n", "sweep", "amount", "vein", "artery");
    for (int i = 0; i <= 5; i++) {
        const float a = 2.0f * (float)i;
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, a);
        const sc_xform p = scn_probe(20.0f, 10.0f, a, 0.0f);
        sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &p, 1, &g_dev, (uint32_t)i);
        snprintf(path, sizeof path, "%s/dent_%02dmm.png", dir, (int)a);
        write_png(path, &d);
        printf("%-6s %8.1f %8.3f %8.3f\n", "dent", (double)a,
               (double)g_b.status.area_ratio[SC_LABEL_VEIN],
               (double)g_b.status.area_ratio[SC_LABEL_ARTERY]);
    }
    for (int i = 0; i <= 4; i++) {
        const float a = 0.2f * (float)i;
        scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_SQUASH_VEIN, a);
        const sc_xform p = scn_probe(20.0f, 10.0f, 0.0f, 0.0f);
        sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &p, 1, &g_dev, (uint32_t)i);
        snprintf(path, sizeof path, "%s/squash_%02d.png", dir, (int)(a * 100.0f + 0.5f));
        write_png(path, &d);
        printf("%-6s %8.2f %8.3f %8.3f\n", "squash", (double)a,
               (double)g_b.status.area_ratio[SC_LABEL_VEIN],
               (double)g_b.status.area_ratio[SC_LABEL_ARTERY]);
    }
    /* curvilinear probe under the dent, and a tilted linear view over the mesh side */
    d.scan = sc_scan_curvilinear_default_def();
    sc_bscan_set_def(&g_b, &d);
    scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_DENT, 6.0f);
    {
        const sc_xform p = scn_probe(20.0f, 10.0f, 6.0f, 0.0f);
        sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &p, 1, &g_dev, 100u);
        snprintf(path, sizeof path, "%s/curvilinear_dent_06mm.png", dir);
        write_png(path, &d);
    }
    d = sc_bscan_default_def();
    sc_bscan_set_def(&g_b, &d);
    {
        const sc_xform p = scn_probe(4.0f, 9.3f, -2.0f, 14.0f);
        sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol.v, &p, 1, &g_dev, 101u);
        snprintf(path, sizeof path, "%s/tilted_side_dent_06mm.png", dir);
        write_png(path, &d);
    }
    printf("PNGs in %s/\n", dir);
    return 0;
}
