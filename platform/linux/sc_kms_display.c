/* sc_kms_display.c: DRM/KMS dumb-buffer and fbdev display sinks, see sc_kms_display.h. */
#include "sc_kms_display.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/fb.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <drm.h>
#include <drm_mode.h>

#include "sc_config.h"
#include "sc_err.h"
#include "sc_scan_overlay.h"
#include "sc_scanconv.h"

enum { KIND_DRM = 0, KIND_FBDEV = 1 };

typedef struct kms_buf {
    uint32_t handle, fb_id, pitch;
    uint64_t size;
    uint8_t *map;
} kms_buf;

struct sc_kms_display {
    int kind;
    int fd;
    uint32_t width, height, pitch, bpp;
    /* DRM */
    uint32_t crtc_id, conn_id;
    struct drm_mode_modeinfo mode;
    kms_buf buf[2];
    int front;          /* buffer on screen */
    int flip_pending;
    int crtc_set;
    /* fbdev */
    uint8_t *fb_map;
    size_t fb_size;
    /* frame assembly */
    sc_display_frame_info info;
    int in_frame;
    uint32_t lines_seen;
    uint8_t line_seen[SC_MAX_SCAN_LINES];
    uint8_t image[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
    uint8_t *grey; /* width*height */
    sc_scanconv conv;
    sc_kms_stats stats;
};

static int xioctl(int fd, unsigned long req, void *arg)
{
    int r;
    do {
        r = ioctl(fd, req, arg);
    } while (r == -1 && (errno == EINTR || errno == EAGAIN));
    return r;
}

static int fail(sc_kms_display *d, const char **why, const char *msg)
{
    if (why) {
        *why = msg;
    }
    sc_kms_close(d);
    return SC_ERR_IO;
}

static sc_kms_display *alloc_display(uint32_t w, uint32_t h)
{
    sc_kms_display *d = calloc(1, sizeof(*d));
    if (!d) {
        return NULL;
    }
    d->fd = -1;
    d->grey = malloc((size_t)w * h);
    if (!d->grey || sc_scanconv_init(&d->conv, w, h) != 0) {
        free(d->grey);
        free(d);
        return NULL;
    }
    d->width = w;
    d->height = h;
    return d;
}

/* ---- DRM ----------------------------------------------------------------------------------- */

static int create_buf(int fd, uint32_t w, uint32_t h, kms_buf *b)
{
    struct drm_mode_create_dumb cd = {.width = w, .height = h, .bpp = 32};
    if (xioctl(fd, DRM_IOCTL_MODE_CREATE_DUMB, &cd) < 0) {
        return -1;
    }
    b->handle = cd.handle;
    b->pitch = cd.pitch;
    b->size = cd.size;
    struct drm_mode_fb_cmd fb = {
        .width = w, .height = h, .pitch = cd.pitch, .bpp = 32, .depth = 24, .handle = cd.handle};
    if (xioctl(fd, DRM_IOCTL_MODE_ADDFB, &fb) < 0) {
        return -1;
    }
    b->fb_id = fb.fb_id;
    struct drm_mode_map_dumb md = {.handle = cd.handle};
    if (xioctl(fd, DRM_IOCTL_MODE_MAP_DUMB, &md) < 0) {
        return -1;
    }
    void *p = mmap(NULL, (size_t)cd.size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, (off_t)md.offset);
    if (p == MAP_FAILED) {
        return -1;
    }
    b->map = p;
    memset(b->map, 0, (size_t)cd.size);
    return 0;
}

static int pick_output(int fd, uint32_t *conn_id, uint32_t *crtc_id, struct drm_mode_modeinfo *mode)
{
    struct drm_mode_card_res res;
    memset(&res, 0, sizeof(res));
    if (xioctl(fd, DRM_IOCTL_MODE_GETRESOURCES, &res) < 0) {
        return -1;
    }
    uint32_t conns[16], crtcs[16], encs[16], fbs[16];
    if (res.count_connectors > 16u || res.count_crtcs > 16u || res.count_encoders > 16u) {
        return -1;
    }
    res.count_fbs = res.count_fbs > 16u ? 16u : res.count_fbs;
    res.connector_id_ptr = (uint64_t)(uintptr_t)conns;
    res.crtc_id_ptr = (uint64_t)(uintptr_t)crtcs;
    res.encoder_id_ptr = (uint64_t)(uintptr_t)encs;
    res.fb_id_ptr = (uint64_t)(uintptr_t)fbs;
    if (xioctl(fd, DRM_IOCTL_MODE_GETRESOURCES, &res) < 0) {
        return -1;
    }
    for (uint32_t i = 0; i < res.count_connectors; i++) {
        struct drm_mode_get_connector c;
        memset(&c, 0, sizeof(c));
        c.connector_id = conns[i];
        if (xioctl(fd, DRM_IOCTL_MODE_GETCONNECTOR, &c) < 0) {
            continue;
        }
        if (c.connection != 1u || c.count_modes == 0u) {
            continue;
        }
        struct drm_mode_modeinfo modes[64];
        uint32_t cenc[16];
        uint32_t props[64];
        uint64_t pvals[64];
        c.count_modes = c.count_modes > 64u ? 64u : c.count_modes;
        c.count_encoders = c.count_encoders > 16u ? 16u : c.count_encoders;
        c.count_props = c.count_props > 64u ? 64u : c.count_props;
        c.modes_ptr = (uint64_t)(uintptr_t)modes;
        c.encoders_ptr = (uint64_t)(uintptr_t)cenc;
        c.props_ptr = (uint64_t)(uintptr_t)props;
        c.prop_values_ptr = (uint64_t)(uintptr_t)pvals;
        if (xioctl(fd, DRM_IOCTL_MODE_GETCONNECTOR, &c) < 0) {
            continue;
        }
        uint32_t best = 0;
        for (uint32_t m = 0; m < c.count_modes; m++) {
            if (modes[m].type & DRM_MODE_TYPE_PREFERRED) {
                best = m;
                break;
            }
        }
        uint32_t enc_id = c.encoder_id ? c.encoder_id : (c.count_encoders ? cenc[0] : 0u);
        if (!enc_id) {
            continue;
        }
        struct drm_mode_get_encoder e;
        memset(&e, 0, sizeof(e));
        e.encoder_id = enc_id;
        if (xioctl(fd, DRM_IOCTL_MODE_GETENCODER, &e) < 0) {
            continue;
        }
        uint32_t crtc = e.crtc_id;
        for (uint32_t k = 0; !crtc && k < res.count_crtcs; k++) {
            if (e.possible_crtcs & (1u << k)) {
                crtc = crtcs[k];
            }
        }
        if (!crtc) {
            continue;
        }
        *conn_id = conns[i];
        *crtc_id = crtc;
        *mode = modes[best];
        return 0;
    }
    return -1;
}

int sc_kms_open_drm(sc_kms_display **out, const char *path, const char **why)
{
    *out = NULL;
    int fd = open(path ? path : "/dev/dri/card0", O_RDWR | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        if (why) {
            *why = "cannot open the DRM card";
        }
        return SC_ERR_NOT_FOUND;
    }
    uint32_t conn = 0, crtc = 0;
    struct drm_mode_modeinfo mode;
    if (pick_output(fd, &conn, &crtc, &mode) != 0) {
        close(fd);
        if (why) {
            *why = "no connected connector with a mode and a CRTC";
        }
        return SC_ERR_NOT_FOUND;
    }
    sc_kms_display *d = alloc_display(mode.hdisplay, mode.vdisplay);
    if (!d) {
        close(fd);
        return SC_ERR_NO_SPACE;
    }
    d->kind = KIND_DRM;
    d->fd = fd;
    d->conn_id = conn;
    d->crtc_id = crtc;
    d->mode = mode;
    d->bpp = 32;
    for (int i = 0; i < 2; i++) {
        if (create_buf(fd, d->width, d->height, &d->buf[i]) != 0) {
            return fail(d, why, "cannot create, add or map a dumb buffer");
        }
    }
    struct drm_mode_crtc sc;
    memset(&sc, 0, sizeof(sc));
    sc.crtc_id = crtc;
    sc.fb_id = d->buf[0].fb_id;
    sc.set_connectors_ptr = (uint64_t)(uintptr_t)&d->conn_id;
    sc.count_connectors = 1;
    sc.mode = mode;
    sc.mode_valid = 1;
    if (xioctl(fd, DRM_IOCTL_MODE_SETCRTC, &sc) < 0) {
        return fail(d, why, "SETCRTC refused (is another program DRM master?)");
    }
    d->crtc_set = 1;
    d->front = 0;
    *out = d;
    return SC_OK;
}

static void drain_events(sc_kms_display *d, int timeout_ms)
{
    struct pollfd p = {.fd = d->fd, .events = POLLIN};
    while (d->flip_pending && poll(&p, 1, timeout_ms) > 0) {
        uint8_t buf[1024];
        ssize_t n = read(d->fd, buf, sizeof(buf));
        if (n <= 0) {
            break;
        }
        for (ssize_t off = 0; off + (ssize_t)sizeof(struct drm_event) <= n;) {
            struct drm_event ev;
            memcpy(&ev, buf + off, sizeof(ev));
            if (ev.type == DRM_EVENT_FLIP_COMPLETE) {
                d->flip_pending = 0;
            }
            if (ev.length == 0u) {
                break;
            }
            off += ev.length;
        }
    }
}

int sc_kms_wait_flip(sc_kms_display *d, int timeout_ms)
{
    if (d->kind != KIND_DRM) {
        return 0;
    }
    drain_events(d, timeout_ms);
    return d->flip_pending ? SC_ERR_TIMEOUT : SC_OK;
}

/* ---- fbdev --------------------------------------------------------------------------------- */

int sc_kms_open_fbdev(sc_kms_display **out, const char *path, const char **why)
{
    *out = NULL;
    int fd = open(path ? path : "/dev/fb0", O_RDWR | O_CLOEXEC);
    if (fd < 0) {
        if (why) {
            *why = "cannot open the framebuffer device";
        }
        return SC_ERR_NOT_FOUND;
    }
    struct fb_var_screeninfo var;
    struct fb_fix_screeninfo fix;
    if (ioctl(fd, FBIOGET_VSCREENINFO, &var) < 0 || ioctl(fd, FBIOGET_FSCREENINFO, &fix) < 0 ||
        (var.bits_per_pixel != 32u && var.bits_per_pixel != 16u)) {
        close(fd);
        if (why) {
            *why = "framebuffer is not 16 or 32 bits per pixel";
        }
        return SC_ERR_NOT_SUPPORTED;
    }
    sc_kms_display *d = alloc_display(var.xres, var.yres);
    if (!d) {
        close(fd);
        return SC_ERR_NO_SPACE;
    }
    d->kind = KIND_FBDEV;
    d->fd = fd;
    d->pitch = fix.line_length;
    d->bpp = var.bits_per_pixel;
    d->fb_size = fix.smem_len;
    void *p = mmap(NULL, d->fb_size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
        return fail(d, why, "cannot map the framebuffer");
    }
    d->fb_map = p;
    *out = d;
    return SC_OK;
}

int sc_kms_open_auto(sc_kms_display **out, const char **why)
{
    if (sc_kms_open_drm(out, NULL, why) == SC_OK) {
        return SC_OK;
    }
    return sc_kms_open_fbdev(out, NULL, why);
}

/* ---- sc_display_dev ------------------------------------------------------------------------ */

static void blit(const sc_kms_display *d, uint8_t *dst, uint32_t pitch, uint32_t bpp)
{
    for (uint32_t y = 0; y < d->height; y++) {
        const uint8_t *src = d->grey + (size_t)y * d->width;
        if (bpp == 32u) {
            uint32_t *row = (uint32_t *)(void *)(dst + (size_t)y * pitch);
            for (uint32_t x = 0; x < d->width; x++) {
                uint32_t v = src[x];
                row[x] = 0xFF000000u | (v << 16) | (v << 8) | v;
            }
        } else {
            uint16_t *row = (uint16_t *)(void *)(dst + (size_t)y * pitch);
            for (uint32_t x = 0; x < d->width; x++) {
                uint32_t v = src[x];
                row[x] = (uint16_t)(((v >> 3) << 11) | ((v >> 2) << 5) | (v >> 3));
            }
        }
    }
}

static int kms_begin(void *ctx, const sc_display_frame_info *info)
{
    sc_kms_display *d = ctx;
    if (d->in_frame) {
        d->stats.frames_dropped++;
    }
    if (info->lines == 0u || info->lines > SC_MAX_SCAN_LINES || info->samples == 0u ||
        info->samples > SC_MAX_SCAN_SAMPLES) {
        d->in_frame = 0;
        d->stats.line_errors++;
        return SC_ERR_IMG_GEOMETRY;
    }
    d->info = *info;
    d->in_frame = 1;
    d->lines_seen = 0;
    memset(d->line_seen, 0, sizeof(d->line_seen));
    return SC_OK;
}

static int kms_line(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                    uint16_t count)
{
    sc_kms_display *d = ctx;
    d->stats.lines++;
    if (!d->in_frame || frame_no != d->info.frame_no || line_index >= d->info.lines ||
        count != d->info.samples || d->line_seen[line_index]) {
        d->stats.line_errors++;
        return SC_ERR_INVALID_ARG;
    }
    d->line_seen[line_index] = 1;
    d->lines_seen++;
    memcpy(&d->image[(size_t)line_index * SC_MAX_SCAN_SAMPLES], samples, count);
    return SC_OK;
}

static int kms_end(void *ctx, const sc_display_end_info *end)
{
    sc_kms_display *d = ctx;
    if (!end || !d->in_frame || end->frame_no != d->info.frame_no) {
        d->stats.line_errors++;
        return SC_ERR_STATE;
    }
    d->in_frame = 0;
    if (d->lines_seen != d->info.lines) {
        d->stats.frames_dropped++;
        return SC_OK;
    }
    if (d->kind == KIND_DRM) {
        drain_events(d, 0);
        if (d->flip_pending) {
            d->stats.frames_dropped++; /* the screen has not taken the last one yet */
            return SC_OK;
        }
    }
    sc_scanconv_render(&d->conv, &d->info, d->image, SC_MAX_SCAN_SAMPLES, d->grey);
    sc_overlay_draw(d->grey, d->conv.width, d->conv.height, &d->info); /* a scanner's display */
    if (d->kind == KIND_FBDEV) {
        blit(d, d->fb_map, d->pitch, d->bpp);
        d->stats.frames_shown++;
        return SC_OK;
    }
    const int back = 1 - d->front;
    blit(d, d->buf[back].map, d->buf[back].pitch, 32u);
    struct drm_mode_crtc_page_flip flip;
    memset(&flip, 0, sizeof(flip));
    flip.crtc_id = d->crtc_id;
    flip.fb_id = d->buf[back].fb_id;
    flip.flags = DRM_MODE_PAGE_FLIP_EVENT;
    if (ioctl(d->fd, DRM_IOCTL_MODE_PAGE_FLIP, &flip) < 0) {
        d->stats.frames_dropped++;
        return errno == EBUSY ? SC_OK : SC_ERR_IO;
    }
    d->flip_pending = 1;
    d->front = back;
    d->stats.frames_shown++;
    return SC_OK;
}

static int kms_link_state(void *ctx, sc_display_link_state *st)
{
    sc_kms_display *d = ctx;
    *st = (sc_display_link_state){.up = 1,
                                  .lines_sent = (uint32_t)d->stats.lines,
                                  .lines_dropped = (uint32_t)d->stats.line_errors};
    return SC_OK;
}

static const sc_display_ops kms_ops = {
    .frame_begin = kms_begin,
    .line = kms_line,
    .frame_end = kms_end,
    .link_state = kms_link_state,
};

sc_display_dev sc_kms_display_dev(sc_kms_display *d)
{
    return (sc_display_dev){.ops = &kms_ops, .ctx = d};
}

void sc_kms_get_mode(const sc_kms_display *d, uint32_t *width, uint32_t *height,
                     const char **kind)
{
    *width = d->width;
    *height = d->height;
    *kind = d->kind == KIND_DRM ? "drm" : "fbdev";
}

void sc_kms_get_stats(const sc_kms_display *d, sc_kms_stats *st)
{
    *st = d->stats;
}

void sc_kms_close(sc_kms_display *d)
{
    if (!d) {
        return;
    }
    if (d->kind == KIND_DRM && d->fd >= 0) {
        drain_events(d, 100);
        for (int i = 0; i < 2; i++) {
            if (d->buf[i].map) {
                munmap(d->buf[i].map, (size_t)d->buf[i].size);
            }
            if (d->buf[i].fb_id) {
                uint32_t id = d->buf[i].fb_id;
                ioctl(d->fd, DRM_IOCTL_MODE_RMFB, &id);
            }
            if (d->buf[i].handle) {
                struct drm_mode_destroy_dumb dd = {.handle = d->buf[i].handle};
                ioctl(d->fd, DRM_IOCTL_MODE_DESTROY_DUMB, &dd);
            }
        }
    }
    if (d->fb_map) {
        munmap(d->fb_map, d->fb_size);
    }
    if (d->fd >= 0) {
        close(d->fd);
    }
    sc_scanconv_free(&d->conv);
    free(d->grey);
    free(d);
}
