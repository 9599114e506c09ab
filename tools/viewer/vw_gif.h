/*
 * vw_gif.h: the viewer's animated GIF recordings (GIF89a, one global 256-colour palette, loops
 * forever), written through giflib (Debian's libgif-dev).
 *
 * Deterministic for a given giflib: the same frames and delays give the same bytes.
 * Allocation: giflib's (its encoder state, one palette) and one row buffer, from open to close.
 */
#ifndef VW_GIF_H
#define VW_GIF_H

#include <stdint.h>

typedef struct vw_gif {
    void *gif; /* giflib's GifFileType */
    uint16_t width, height;
    uint32_t frames;
    uint8_t *row; /* one row of indices: giflib's writer takes a non-const line */
    int err;      /* giflib's error code of the first failure, 0 while none */
} vw_gif;

/* palette: 256 RGB triples. 0 or -1 (g->err holds giflib's code, errno set on an I/O
 * failure). */
int vw_gif_open(vw_gif *g, const char *path, uint16_t width, uint16_t height,
                const uint8_t palette[768]);
/* One frame of width*height palette indices, shown for delay_cs hundredths of a second.
 * 0 or -1 (then every later add fails too; close still releases everything). */
int vw_gif_add(vw_gif *g, const uint8_t *index, uint16_t delay_cs);
/* Trailer and close; releases everything. 0, or -1 when any write failed. */
int vw_gif_close(vw_gif *g);

#endif /* VW_GIF_H */
