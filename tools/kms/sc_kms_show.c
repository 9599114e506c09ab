/*
 * sc_kms_show.c: puts one B-scan frame on a directly attached panel through the engine's
 * DRM/KMS (or fbdev) sink, and checks on the host what a screendump of that panel shows.
 *
 *   sc-kms-show show FRAME [--fbdev] [--hold-s S]
 *       open the panel, send FRAME through the sink (begin, every line, end), wait for the
 *       page flip, print "SC_KMS_READY kind=K mode=WxH", keep the picture for S seconds.
 *   sc-kms-show compare FRAME SCREENDUMP.ppm
 *       render FRAME with the same scan conversion at the screendump's size and compare pixel
 *       by pixel; prints the figures; exit 0 when every pixel is within 1 grey level.
 *   sc-kms-show pattern FRAME
 *       write a synthetic test frame (bands and a disc) to FRAME.
 * FRAME file: "SCFRAME1" magic, u16 lines, u16 samples, u16 geometry_id,
 * u16 probe-face radius in 1/100 mm (curvilinear; 0 for linear and in older files), f32 depth_mm,
 * f32 width_mm, then lines*samples bytes, line-major (little-endian, as the host runner writes).
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sc_config.h"
#include "sc_err.h"
#include "sc_kms_display.h"
#include "sc_scan_overlay.h"
#include "sc_scanconv.h"

typedef struct frame {
    sc_display_frame_info info;
    uint8_t *data; /* lines * samples */
} frame;

static int read_frame(const char *path, frame *f)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        fprintf(stderr, "sc-kms-show: cannot open %s: %s\n", path, strerror(errno));
        return -1;
    }
    uint8_t h[24];
    if (fread(h, 1, sizeof(h), fp) != sizeof(h) || memcmp(h, "SCFRAME1", 8) != 0) {
        fprintf(stderr, "sc-kms-show: %s is not a frame file\n", path);
        fclose(fp);
        return -1;
    }
    memset(f, 0, sizeof(*f));
    f->info.lines = (uint16_t)(h[8] | h[9] << 8);
    f->info.samples = (uint16_t)(h[10] | h[11] << 8);
    f->info.geometry_id = (uint16_t)(h[12] | h[13] << 8);
    f->info.radius_mm = f->info.geometry_id == 1u ? (float)(h[14] | h[15] << 8) / 100.0f : 0.0f;
    memcpy(&f->info.depth_mm, h + 16, 4);
    memcpy(&f->info.width_mm, h + 20, 4);
    if (f->info.lines == 0u || f->info.lines > SC_MAX_SCAN_LINES || f->info.samples == 0u ||
        f->info.samples > SC_MAX_SCAN_SAMPLES || f->info.geometry_id > 1u ||
        !isfinite(f->info.depth_mm) || !isfinite(f->info.width_mm)) {
        fprintf(stderr, "sc-kms-show: %s: geometry outside the limits\n", path);
        fclose(fp);
        return -1;
    }
    size_t n = (size_t)f->info.lines * f->info.samples;
    f->data = malloc(n);
    if (!f->data || fread(f->data, 1, n, fp) != n) {
        fprintf(stderr, "sc-kms-show: %s truncated\n", path);
        fclose(fp);
        free(f->data);
        return -1;
    }
    fclose(fp);
    return 0;
}

static int write_pattern(const char *path)
{
    const uint16_t lines = 256, samples = 512;
    FILE *fp = fopen(path, "wb");
    if (!fp) {
        fprintf(stderr, "sc-kms-show: cannot write %s\n", path);
        return 1;
    }
    uint8_t h[24] = "SCFRAME1";
    h[8] = (uint8_t)lines;
    h[9] = (uint8_t)(lines >> 8);
    h[10] = (uint8_t)samples;
    h[11] = (uint8_t)(samples >> 8);
    float depth = 60.0f, width = 38.0f;
    memcpy(h + 16, &depth, 4);
    memcpy(h + 20, &width, 4);
    fwrite(h, 1, sizeof(h), fp);
    for (uint32_t l = 0; l < lines; l++) {
        for (uint32_t k = 0; k < samples; k++) {
            double x = (l + 0.5) / lines * 38.0 - 19.0, z = (k + 0.5) / samples * 60.0;
            uint8_t v = (uint8_t)(40u + ((l / 16u + k / 32u) % 2u) * 80u);
            if ((x - 5.0) * (x - 5.0) + (z - 25.0) * (z - 25.0) < 64.0) {
                v = 8; /* an anechoic "vessel" */
            }
            if (k % 128u == 0u) {
                v = 250;
            }
            fputc(v, fp);
        }
    }
    fclose(fp);
    return 0;
}

static int show(const char *path, int use_fbdev, int hold_s)
{
    frame f;
    if (read_frame(path, &f) != 0) {
        return 2;
    }
    sc_kms_display *d = NULL;
    const char *why = "";
    int rc = use_fbdev ? sc_kms_open_fbdev(&d, NULL, &why) : sc_kms_open_drm(&d, NULL, &why);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-kms-show: cannot open the %s display: %s (%s)\n",
                use_fbdev ? "fbdev" : "DRM", why, sc_err_str(rc));
        return 3;
    }
    sc_display_dev dev = sc_kms_display_dev(d);
    f.info.frame_no = 1;
    rc = sc_display_frame_begin(&dev, &f.info);
    for (uint16_t l = 0; rc == SC_OK && l < f.info.lines; l++) {
        rc = sc_display_line(&dev, 1, l, f.data + (size_t)l * f.info.samples, f.info.samples);
    }
    if (rc == SC_OK) {
        rc = sc_display_frame_end(&dev, SC_DISPLAY_END_PLAIN(1));
    }
    if (rc == SC_OK) {
        rc = sc_kms_wait_flip(d, 2000);
    }
    uint32_t w, h;
    const char *kind;
    sc_kms_get_mode(d, &w, &h, &kind);
    sc_kms_stats st;
    sc_kms_get_stats(d, &st);
    if (rc != SC_OK || st.frames_shown != 1u) {
        fprintf(stderr, "sc-kms-show: frame not shown: %s (shown %llu, dropped %llu)\n",
                sc_err_str(rc), (unsigned long long)st.frames_shown,
                (unsigned long long)st.frames_dropped);
        sc_kms_close(d);
        return 4;
    }
    printf("SC_KMS_READY kind=%s mode=%ux%u\n", kind, w, h);
    fflush(stdout);
    sleep((unsigned)hold_s);
    sc_kms_close(d);
    free(f.data);
    return 0;
}

static uint8_t *read_ppm(const char *path, uint32_t *w, uint32_t *h)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        fprintf(stderr, "sc-kms-show: cannot open %s\n", path);
        return NULL;
    }
    unsigned maxv = 0;
    if (fscanf(fp, "P6 %u %u %u", w, h, &maxv) != 3 || maxv != 255u || *w == 0u || *h == 0u ||
        *w > 8192u || *h > 8192u) {
        fprintf(stderr, "sc-kms-show: %s is not an 8-bit P6 PPM\n", path);
        fclose(fp);
        return NULL;
    }
    fgetc(fp);
    size_t n = (size_t)*w * *h * 3u;
    uint8_t *rgb = malloc(n);
    if (!rgb || fread(rgb, 1, n, fp) != n) {
        fprintf(stderr, "sc-kms-show: %s truncated\n", path);
        free(rgb);
        fclose(fp);
        return NULL;
    }
    fclose(fp);
    return rgb;
}

static int compare(const char *frame_path, const char *ppm_path)
{
    frame f;
    if (read_frame(frame_path, &f) != 0) {
        return 2;
    }
    uint32_t w, h;
    uint8_t *rgb = read_ppm(ppm_path, &w, &h);
    if (!rgb) {
        return 2;
    }
    sc_scanconv c;
    uint8_t *want = malloc((size_t)w * h);
    if (!want || sc_scanconv_init(&c, w, h) != 0) {
        return 2;
    }
    sc_scanconv_render(&c, &f.info, f.data, f.info.samples, want);
    sc_overlay_draw(want, w, h, &f.info); /* the sink draws the scanner's display items too */
    uint64_t off = 0, nonzero = 0;
    int maxd = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        for (int ch = 0; ch < 3; ch++) {
            int d = abs((int)rgb[i * 3u + (size_t)ch] - (int)want[i]);
            maxd = d > maxd ? d : maxd;
            off += d > 1;
        }
        nonzero += want[i] != 0u;
    }
    printf("compare: screendump %ux%u, image pixels %llu, channel values off by >1: %llu, "
           "max difference %d\n",
           w, h, (unsigned long long)nonzero, (unsigned long long)off, maxd);
    sc_scanconv_free(&c);
    free(want);
    free(rgb);
    free(f.data);
    return (off == 0u && nonzero > 0u) ? 0 : 1;
}

static void usage(void)
{
    fprintf(stderr, "usage: sc-kms-show show FRAME [--fbdev] [--hold-s S]\n"
                    "       sc-kms-show compare FRAME SCREENDUMP.ppm\n"
                    "       sc-kms-show pattern FRAME\n");
}

int main(int argc, char **argv)
{
    if (argc >= 3 && strcmp(argv[1], "show") == 0) {
        int fbdev = 0, hold = 5;
        for (int i = 3; i < argc; i++) {
            if (strcmp(argv[i], "--fbdev") == 0) {
                fbdev = 1;
            } else if (strcmp(argv[i], "--hold-s") == 0 && i + 1 < argc) {
                char *end;
                long v = strtol(argv[++i], &end, 10);
                if (*end || v < 0 || v > 3600) {
                    fprintf(stderr, "sc-kms-show: --hold-s wants 0..3600\n");
                    return 2;
                }
                hold = (int)v;
            } else {
                usage();
                return 2;
            }
        }
        return show(argv[2], fbdev, hold);
    }
    if (argc == 4 && strcmp(argv[1], "compare") == 0) {
        return compare(argv[2], argv[3]);
    }
    if (argc == 3 && strcmp(argv[1], "pattern") == 0) {
        return write_pattern(argv[2]);
    }
    usage();
    return 2;
}
