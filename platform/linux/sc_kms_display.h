/*
 * sc_kms_display.h: display sinks for a panel attached to the appliance itself.
 *
 * DRM/KMS: dumb buffers, double-buffered with page flips: lines are collected into a frame,
 * and at frame_end the frame is scan-converted into the back buffer, which is flipped to the
 * screen at the next vblank. A flip still pending when the next frame ends is not waited for:
 * that frame is dropped and counted (the engine never blocks on the display).
 * fbdev: the fallback where no DRM device exists: one mapped buffer, drawn at frame_end.
 * Both are sc_display_devs (hal/sc_hal_display.h); opening allocates (start-up only), frames
 * never do. Raw kernel ioctls only (uapi headers of libdrm-dev), so the engine links
 * statically without libdrm.
 */
#ifndef SC_KMS_DISPLAY_H
#define SC_KMS_DISPLAY_H

#include <stdint.h>

#include "sc_hal_display.h"

typedef struct sc_kms_display sc_kms_display;

typedef struct sc_kms_stats {
    uint64_t frames_shown;  /* flipped (DRM) or drawn (fbdev) */
    uint64_t frames_dropped; /* previous flip still pending, or incomplete frame */
    uint64_t lines;
    uint64_t line_errors;   /* bad index/length, line outside a frame */
} sc_kms_stats;

/* Open a DRM card (path NULL: /dev/dri/card0) on its first connected connector at the
 * preferred mode. 0, or a negative sc_err (SC_ERR_IO with errno detail in *why). */
int sc_kms_open_drm(sc_kms_display **out, const char *path, const char **why);
/* Open a framebuffer device (path NULL: /dev/fb0), 32 bpp. */
int sc_kms_open_fbdev(sc_kms_display **out, const char *path, const char **why);
/* DRM first, then fbdev. */
int sc_kms_open_auto(sc_kms_display **out, const char **why);

sc_display_dev sc_kms_display_dev(sc_kms_display *d);
void sc_kms_get_mode(const sc_kms_display *d, uint32_t *width, uint32_t *height,
                     const char **kind);
void sc_kms_get_stats(const sc_kms_display *d, sc_kms_stats *st);
/* Wait (up to timeout_ms) for a pending page flip to complete. 0 when none is pending. */
int sc_kms_wait_flip(sc_kms_display *d, int timeout_ms);
void sc_kms_close(sc_kms_display *d);

#endif /* SC_KMS_DISPLAY_H */
