/*
 * sc_reconstruct.h: freehand 3D reconstruction from a tracked 2D ultrasound sequence, as the
 * paper's database does for volumes "reconstructed from 2D ultrasound B-scans" (host tool
 * library; allocates with malloc).
 *
 * Input: a PLUS toolkit sequence file (.igs.mha / .seq.mha, or .mhd with its data): a
 * MetaImage of W x H x N 8-bit frames whose header holds, per frame,
 *   Seq_FrameNNNN_<Name>Transform = 16 numbers (a 4x4 matrix, row-major, mm)
 *   Seq_FrameNNNN_<Name>TransformStatus = OK | INVALID   (absent: OK)
 * with <Name> "ProbeToTracker" by default (PLUS's ProbeToReference and others by option),
 * and UltrasoundImageOrientation (PLUS's MF, UF, MN, UN; absent: MF): frames stored in
 * another orientation are read as MF (U: columns mirrored, N: rows mirrored), as PLUS does.
 * A pixel (u, v) of an MF frame (u along a row, v down the rows, away from the transducer)
 * is the image point
 * (u * sx, v * sy, 0) mm (sx, sy: the file's ElementSpacing), carried to the probe by the
 * image-to-probe calibration (an affine 3x4 map, PLUS's ImageToProbe; default identity) and
 * to the tracker by the frame's transform.
 *
 * Reconstruction (as PLUS's volume reconstructor): every pixel of every valid frame is
 * splatted into an axis-aligned grid in the tracker frame that bounds all frames, either into
 * the nearest voxel or trilinearly into the 8 around it, accumulating value x weight and
 * weight; then voxels without data are filled from the weighted mean of the filled voxels in
 * their 3x3x3 neighbourhood, pass after pass (fill_passes), so that gaps between frames up to
 * about 2 x passes voxels close; what stays empty (outside the sweep) is 0.
 */
#ifndef SC_RECONSTRUCT_H
#define SC_RECONSTRUCT_H

#include <stddef.h>
#include <stdint.h>

#include "sc_caseimport.h"
#include "sc_image.h"

typedef struct sc_plus_seq {
    sc_image frames;   /* dim = W, H, N; spacing[0..1] = pixel size (mm) */
    double *transform; /* N x 16, row-major 4x4 per frame */
    uint8_t *valid;    /* N: 1 when the frame's transform status is OK */
    uint32_t valid_count;
    char name[64]; /* the transform used, e.g. "ProbeToTracker" */
    int flip_u;    /* UltrasoundImageOrientation U?: the marked side is on the right */
    int flip_v;    /* ?N: the transducer (near) at the bottom of the image */
} sc_plus_seq;

/* Read a PLUS sequence. transform: the <Name> of the per-frame transform (NULL:
 * "ProbeToTracker"). Every frame must have it (a malformed or missing matrix, a
 * non-rigid rotation part, or a translation beyond SC_IMPORT_MAX_ORIGIN_MM is refused naming
 * the frame); at least 2 valid frames. Errors: those of sc_image_read_ex, SC_ERR_PARSE,
 * SC_ERR_NOT_SUPPORTED (not a sequence, not 8-bit), SC_ERR_NO_SPACE. O(file size). */
int sc_plusseq_read(const char *path, const sc_read_limits *lim, const char *transform,
                    sc_plus_seq *seq, char *err, size_t errlen);
void sc_plusseq_free(sc_plus_seq *seq);

typedef struct sc_recon_opts {
    double spacing_mm;         /* output voxel size, 0.05 .. 10 mm (default 0.5) */
    int trilinear;             /* 0: pixel-nearest splatting, 1: trilinear (default) */
    uint32_t fill_passes;      /* hole-filling passes, 0 .. 64 (default 3) */
    double image_to_probe[12]; /* affine: 3x3 row-major then translation (mm) */
    uint64_t max_voxels;       /* ceiling of the output grid (checked before allocating) */
} sc_recon_opts;

sc_recon_opts sc_recon_default_opts(void);

typedef struct sc_recon_stats {
    uint64_t pixels;      /* splatted */
    uint64_t voxels;      /* of the output grid */
    uint64_t filled;      /* with data from the frames */
    uint64_t hole_filled; /* filled by the hole filling */
    uint64_t empty;       /* still empty (0) */
    double beam_dir[3];   /* mean image +v (depth) direction in the tracker frame, unit */
} sc_recon_stats;

/* Reconstruct seq into vol (F64 data, identity directions, tracker frame, malloc'd: free with
 * sc_image_free). O(valid frames x pixels + voxels x fill_passes). Errors:
 * SC_ERR_INVALID_ARG (options), SC_ERR_CASE_DIMS (grid above max_voxels or
 * SC_MAX_VOLUME_DIM per axis), SC_ERR_NO_SPACE. */
int sc_reconstruct(const sc_plus_seq *seq, const sc_recon_opts *o, sc_image *vol,
                   sc_recon_stats *st, char *err, size_t errlen);

/* Write img as an uncompressed MetaImage (.mha, data inline, MET_FLOAT); SC_ERR_IO. */
int sc_image_write_mha(const sc_image *img, const char *path);

#endif /* SC_RECONSTRUCT_H */
