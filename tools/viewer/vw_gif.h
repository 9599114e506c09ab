/*
 * vw_gif.h: an animated GIF writer (GIF89a, one global 256-colour palette, LZW with 8-bit
 * codes, loops forever) for the viewer's session recordings.
 */
#ifndef VW_GIF_H
#define VW_GIF_H

#include <stdint.h>
#include <stdio.h>

typedef struct vw_gif {
    FILE *f;
    uint16_t width, height;
    uint32_t frames;
    uint16_t *dict;      /* 4096 x 256 trie: child code of (code, byte), 0 = none */
    uint32_t used[4096]; /* dict slots set since the last clear (cleared one by one) */
    uint32_t used_n;
    /* bit packer */
    uint32_t bits;
    uint32_t nbits;
    uint8_t block[255];
    uint32_t block_n;
    int err;
} vw_gif;

/* palette: 256 RGB triples. 0 or -1 (errno). */
int vw_gif_open(vw_gif *g, const char *path, uint16_t width, uint16_t height,
                const uint8_t palette[768]);
/* One frame of width*height palette indices, shown for delay_cs hundredths of a second. */
int vw_gif_add(vw_gif *g, const uint8_t *index, uint16_t delay_cs);
/* Trailer and close. 0 or -1 when any write failed. */
int vw_gif_close(vw_gif *g);

#endif /* VW_GIF_H */
