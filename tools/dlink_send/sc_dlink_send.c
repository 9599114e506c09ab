/*
 * sc_dlink_send.c: `sc-dlink-send`, a synthetic display-link source.
 *
 * Sends N frames of a B-scan-like test pattern (speckle, a bright fascia line, an artery that
 * stays round and a vein that is compressed and released once per 2 s) through the Linux UDP
 * display sink (platform/linux/sc_udp_display.c) to HOST:PORT at a fixed rate, with absolute-time
 * pacing; optionally drops a share of the lines as an injected network loss. Prints one line of
 * key=value statistics on stdout, including the time spent per line in the sink (the bounded
 * per-line cost), so it doubles as a benchmark of the sender.
 */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_dlink.h"
#include "sc_rt.h"
#include "sc_udp_display.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: sc-dlink-send [--target HOST:PORT] [--frames N] [--rate HZ]\n"
               "                     [--lines N] [--samples N] [--geometry linear|curvilinear]\n"
               "                     [--drop-permille P] [--seed S]\n"
               "Defaults: 127.0.0.1:5600, 300 frames, 60 Hz, 256 lines, 384 samples, linear.\n");
}

static uint32_t hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7FEB352Du;
    x ^= x >> 15;
    x *= 0x846CA68Bu;
    x ^= x >> 16;
    return x;
}

/* One scan line of the pattern: frame f, line l of n, s samples; compression c in 0..1. */
static void make_line(uint8_t *out, uint32_t f, uint32_t l, uint32_t n, uint32_t s, float c)
{
    const float x = ((float)l + 0.5f) / (float)n * 2.0f - 1.0f; /* -1 .. 1 across */
    for (uint32_t k = 0; k < s; k++) {
        const float z = ((float)k + 0.5f) / (float)s; /* 0 .. 1 down */
        float v = 70.0f + 40.0f * (float)(hash32(l * 7919u + k * 104729u) & 0xFFu) / 255.0f;
        v *= 1.0f - 0.4f * z; /* attenuation */
        if (fabsf(z - 0.18f) < 0.01f) {
            v = 200.0f; /* fascia */
        }
        /* vein: ellipse centred (-0.3, 0.45), height shrinking with c */
        const float vx = (x + 0.3f) / 0.25f, vz = (z - 0.45f) / (0.12f * (1.0f - 0.9f * c));
        if (vx * vx + vz * vz < 1.0f) {
            v = 8.0f;
        }
        const float ax = (x - 0.35f) / 0.15f, az = (z - 0.5f) / 0.09f; /* artery */
        const float ar = ax * ax + az * az;
        if (ar < 1.0f) {
            v = 5.0f;
        } else if (ar < 1.3f) {
            v = 230.0f; /* bright wall */
        }
        (void)f;
        out[k] = (uint8_t)(v > 255.0f ? 255.0f : v);
    }
}

int main(int argc, char **argv)
{
    char host[256] = "127.0.0.1";
    unsigned port = 5600u, lines = 256u, samples = 384u, drop = 0u, seed = 1u;
    unsigned long long frames = 300u;
    double rate = 60.0;
    int curvilinear = 0;
    static const struct option lo[] = {{"target", required_argument, NULL, 'T'},
                                       {"frames", required_argument, NULL, 'n'},
                                       {"rate", required_argument, NULL, 'r'},
                                       {"lines", required_argument, NULL, 'l'},
                                       {"samples", required_argument, NULL, 's'},
                                       {"geometry", required_argument, NULL, 'g'},
                                       {"drop-permille", required_argument, NULL, 'd'},
                                       {"seed", required_argument, NULL, 'S'},
                                       {"help", no_argument, NULL, 'h'},
                                       {NULL, 0, NULL, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "T:n:r:l:s:g:d:S:h", lo, NULL)) != -1) {
        int ok = 1;
        char extra;
        switch (c) {
        case 'T': {
            const char *colon = strrchr(optarg, ':');
            ok = colon && colon != optarg && (size_t)(colon - optarg) < sizeof host &&
                 sscanf(colon + 1, "%u%c", &port, &extra) == 1 && port >= 1u && port <= 65535u;
            if (ok) {
                memcpy(host, optarg, (size_t)(colon - optarg));
                host[colon - optarg] = '\0';
            }
            break;
        }
        case 'n':
            ok = sscanf(optarg, "%llu%c", &frames, &extra) == 1;
            break;
        case 'r':
            ok = sscanf(optarg, "%lf%c", &rate, &extra) == 1 && rate >= 1.0 && rate <= 1000.0;
            break;
        case 'l':
            ok = sscanf(optarg, "%u%c", &lines, &extra) == 1 && lines >= 1u &&
                 lines <= SC_MAX_SCAN_LINES;
            break;
        case 's':
            ok = sscanf(optarg, "%u%c", &samples, &extra) == 1 && samples >= 1u &&
                 samples <= SC_MAX_SCAN_SAMPLES;
            break;
        case 'g':
            ok = strcmp(optarg, "linear") == 0 || strcmp(optarg, "curvilinear") == 0;
            curvilinear = ok && optarg[0] == 'c';
            break;
        case 'd':
            ok = sscanf(optarg, "%u%c", &drop, &extra) == 1 && drop <= 1000u;
            break;
        case 'S':
            ok = sscanf(optarg, "%u%c", &seed, &extra) == 1 && seed != 0u;
            break;
        case 'h':
            usage(stdout);
            return 0;
        default:
            ok = 0;
        }
        if (!ok) {
            fprintf(stderr, "sc-dlink-send: bad value for option -%c: %s\n", c,
                    optarg ? optarg : "");
            usage(stderr);
            return 2;
        }
    }
    static sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.host = host;
    def.port = (uint16_t)port;
    def.inject_drop_permille = drop;
    def.inject_seed = seed;
    int rc = sc_udp_display_open(&u, &def);
    if (rc != 0) {
        fprintf(stderr, "sc-dlink-send: cannot open %s:%u: %s (%s)\n", host, port, sc_err_str(rc),
                strerror(u.last_errno));
        return 1;
    }
    sc_display_dev dev = sc_udp_display_dev(&u);
    sc_clock_dev clk = sc_rt_clock_dev();
    const uint64_t period = (uint64_t)(1e9 / rate);
    uint64_t release = sc_clock_now_ns(&clk);
    uint64_t line_ns = 0, worst_line_ns = 0, late_frames = 0;
    static uint8_t buf[SC_MAX_SCAN_SAMPLES];
    for (unsigned long long f = 0; f < frames; f++) {
        sc_clock_sleep_until_ns(&clk, release);
        /* compression: 0 .. 1 .. 0 over 2 s */
        const double t = (double)f / rate;
        const float comp = (float)(0.5 - 0.5 * cos(t * M_PI));
        const sc_display_frame_info info = {.frame_no = (uint32_t)f,
                                            .lines = (uint16_t)lines,
                                            .samples = (uint16_t)samples,
                                            .geometry_id = (uint16_t)curvilinear,
                                            .flags = (uint16_t)(comp > 0.05f ? 1u : 0u),
                                            .depth_mm = curvilinear ? 80.0f : 40.0f,
                                            .width_mm = curvilinear ? 60.0f : 38.0f,
                                            .radius_mm = curvilinear ? 40.0f : 0.0f};
        sc_display_frame_begin(&dev, &info);
        for (unsigned l = 0; l < lines; l++) {
            make_line(buf, (uint32_t)f, l, lines, samples, comp);
            const uint64_t t0 = sc_rt_now_ns();
            sc_display_line(&dev, (uint32_t)f, (uint16_t)l, buf, (uint16_t)samples);
            const uint64_t dt = sc_rt_now_ns() - t0;
            line_ns += dt;
            if (dt > worst_line_ns) {
                worst_line_ns = dt;
            }
        }
        /* the frame's measure closes it, as the engine's does */
        const sc_display_end_info end = {(uint32_t)f, 1.0f - comp, 1.0f};
        sc_display_frame_end(&dev, &end);
        release += period;
        if (sc_clock_now_ns(&clk) > release) {
            late_frames++;
            release = sc_clock_now_ns(&clk);
        }
    }
    const double n_lines = (double)frames * lines;
    printf("frames=%llu lines_sent=%llu lines_injected=%llu lines_dropped=%llu send_errors=%llu "
           "late_frames=%llu mean_line_us=%.2f worst_line_us=%.1f\n",
           frames, (unsigned long long)u.lines_sent, (unsigned long long)u.lines_injected,
           (unsigned long long)u.lines_dropped, (unsigned long long)u.send_errors,
           (unsigned long long)late_frames, n_lines > 0 ? (double)line_ns / n_lines / 1e3 : 0.0,
           (double)worst_line_ns / 1e3);
    sc_udp_display_close(&u);
    return 0;
}
