/*
 * sc_volume.h: a read-only view of a case's voxel grids.
 *
 * The voxels live in case storage (mmap'd file, flash, or a test's array); this struct only
 * points at them and never owns or copies them. Coordinates: the volume frame, in mm, with
 * axes along the grid: x lateral, y along the body (cranio-caudal), z depth into the body
 * (skin near z = origin_mm[2], increasing downward). Voxel (i, j, k) has its centre at
 * origin_mm + (i, j, k) * spacing_mm and is stored at index i + dim[0] * (j + dim[1] * k).
 */
#ifndef SC_VOLUME_H
#define SC_VOLUME_H

#include <stdint.h>

typedef struct sc_volume {
    uint32_t dim[3];      /* voxels per axis, each 1..SC_MAX_VOLUME_DIM */
    float spacing_mm[3];  /* > 0, finite */
    float origin_mm[3];   /* centre of voxel (0,0,0) */
    const uint8_t *voxels; /* 8-bit B-mode intensities, dim[0]*dim[1]*dim[2] bytes */
    const uint8_t *labels; /* label map on the same grid (SC_LABEL_*), same size; may be NULL */
} sc_volume;

#endif /* SC_VOLUME_H */
