/*
 * sc_caseimport.h: volume and label-map import for the case builder (host tool library,
 * allocates with malloc).
 *
 * Readers: MetaImage (.mha with the data inline, .mhd + a raw data file; raw or zlib/gzip
 * compressed: CompressedData = True) and NRRD (.nrrd attached, .nhdr + detached data file;
 * encodings raw, gzip, ascii; endian little or big). Element types: 8/16/32-bit signed and
 * unsigned integers, float32, float64. 2D images load as a one-slice volume. Only voxels and
 * geometry are kept (dimensions, spacing, origin, direction cosines); every other header
 * field, including any patient metadata, is ignored and never reaches a case file.
 *
 * Geometry: world point of voxel (i, j, k) = origin + D * (i*sx, j*sy, k*sz) where D's columns
 * are the directions of the grid axes (MetaImage TransformMatrix, NRRD space directions).
 */
#ifndef SC_CASEIMPORT_H
#define SC_CASEIMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "sc_case.h"
#include "sc_image.h"
#include "sc_lumen.h"

/* Ceilings of the readers, checked before anything is allocated or inflated: a header that
 * declares more voxels than max_voxels is refused (the reader holds 8 bytes per voxel, plus
 * the raw or compressed bytes), so a small compressed file cannot claim gigabytes. */
#ifndef SC_IMPORT_DEFAULT_MAX_VOXELS
#define SC_IMPORT_DEFAULT_MAX_VOXELS (64u * 1024u * 1024u) /* 512 MiB of doubles */
#endif
#define SC_IMPORT_MIN_SPACING_MM 1e-3 /* 1 um */
#define SC_IMPORT_MAX_SPACING_MM 100.0
#define SC_IMPORT_MAX_ORIGIN_MM  1e5 /* 100 m: anything beyond is a broken header */

typedef struct sc_read_limits {
    uint64_t max_voxels; /* per image, 1..SC_MAX_VOLUME_VOXELS; also bounds the case grid */
    int allow_data_path; /* 1: a header may name its data file by an absolute path or through
                          * '..'; 0 (default): only beside the header (or below it) */
    int allow_sequence;  /* 1: read a PLUS sequence's frames as a W x H x frames image (the
                          * reconstruction reader); 0: refuse it, pointing to `reconstruct` */
} sc_read_limits;

sc_read_limits sc_read_default_limits(void);

/* Read a MetaImage or NRRD file (by extension; .mha .mhd .nrrd .nhdr), or DICOM (.dcm or a
 * folder) when built with DCMTK. Every header number is range-checked before use (whole
 * numbers for sizes and skips; spacing SC_IMPORT_MIN..MAX_SPACING_MM, origin within
 * SC_IMPORT_MAX_ORIGIN_MM, orthonormal directions); non-finite voxels are refused (the first
 * one named). On error returns a negative sc_err (SC_ERR_NOT_FOUND, SC_ERR_IO, SC_ERR_PARSE,
 * SC_ERR_NOT_SUPPORTED, SC_ERR_NO_SPACE, SC_ERR_CASE_DIMS, SC_ERR_CASE_SPACING,
 * SC_ERR_CASE_TRANSFORM, SC_ERR_NOT_FINITE, SC_ERR_INVALID_ARG for a data file path) and a
 * message naming the file and the field in err. sc_image_read uses the default limits. */
int sc_image_read(const char *path, sc_image *img, char *err, size_t errlen);
int sc_image_read_ex(const char *path, const sc_read_limits *lim, sc_image *img, char *err,
                     size_t errlen);
void sc_image_free(sc_image *img);

typedef struct sc_import_opts {
    const char *volume_path;
    const char *labels_path; /* NULL: every voxel inside the body becomes SC_LABEL_MUSCLE */
    const char *name;        /* default "imported" (never the file name: it may identify) */
    const char *description; /* default: "Imported volume" and the grid */
    float spacing_mm;        /* > 0: resample to this isotropic spacing; 0: keep the source's */
    int has_window;
    float window_lo, window_hi; /* intensity window mapped to 0..255; default: 8-bit data as
                                 * is, other types their 0.1 .. 99.9 percentiles */
    uint32_t mesh_nodes[3];     /* default 24 x 12 x 12 */
    int has_mesh_box;
    float mesh_box_mm[6]; /* origin xyz, size xyz in the case frame; default: derived from the
                           * labels (sc_import_case) */
    /* Case frame (x lateral, y along the body, z depth: the engine presses along z). Each a
     * grid axis of the source, "+i" "-i" "+j" "-j" "+k" "-k", or a patient direction the
     * axis points toward, "L" "R" "A" "P" "S" "I" (or the words left, right, anterior,
     * posterior, superior, inferior; only for files that state a patient frame), snapped to
     * the grid axis closest to it. NULL: depth "P" and lateral "R" when the file states a
     * patient frame (a supine patient scanned from the front: neck, groin), else depth "+k"
     * and lateral "+i" (or "+j" when depth lies along i). */
    const char *depth_axis;
    const char *lateral_axis;
    /* "V=NAME,V=NAME,...[,*=NAME]": which label of the project each source label value is
     * (names of config/sc_labels.h); "*" covers values not listed. NULL: the values are the
     * project's own (0..SC_LABEL_COUNT-1). */
    const char *label_map;
    sc_read_limits limits;       /* default sc_read_default_limits() */
    sc_xform image_to_probe;     /* probe calibration; default identity */
    int has_registration;        /* 0: the default registration below */
    sc_xform tracker_to_patient; /* mannequin registration (tracker -> the file's world frame);
                                  * default: the tracker emulator's frame (Z up out of the body,
                                  * a half turn about x from the case frame, as the phantoms)
                                  * with its origin at the top centre of the mesh box */
    /* The patient's vessel drive, written as the case's DRIV section (sc_case_drive.h) when
     * has_drive: sc-casebuild's drive options start from sc_lumen_drive_default() and change
     * what they name. 0: no DRIV (the engine keeps the drive it has). sc_import_case ignores
     * both; the writer takes them. */
    int has_drive;
    sc_lumen_drive drive;
} sc_import_opts;

typedef struct sc_import_result {
    sc_case_def def; /* ready for sc_case_write() */
    uint8_t *voxels;
    uint8_t *labels;
    char name[SC_CASE_NAME_LEN];
    char description[SC_CASE_DESCRIPTION_LEN];
    int frame_axis[3];      /* source grid axis of case x, y, z */
    int frame_sign[3];      /* +1 / -1 */
    uint64_t label_voxels[SC_MAX_LABELS]; /* voxels of each project label in the case */
    int mesh_box_derived;   /* 1: the mesh box came from the labels */
} sc_import_result;

sc_import_opts sc_import_default_opts(void);

/* Read, choose the case frame (depth axis), resample to the case grid (trilinear for
 * intensities, nearest for labels, through world coordinates so the label map may have its
 * own grid), window to 8 bits, map labels, derive the mesh box when none is given, and fill a
 * case definition with the default material table. O(case voxels).
 *
 * Derived mesh box: x and y span the columns holding tissue (any label but outside); its top
 * is the highest skin/tissue voxel (the smallest z with a label other than outside); its
 * bottom the top of the shallowest bone when that lies below every vessel (bone is the fixed
 * structure the tissue rests on), else the volume's bottom. */
int sc_import_case(const sc_import_opts *o, sc_import_result *r, char *err, size_t errlen);
void sc_import_result_free(sc_import_result *r);

#endif /* SC_CASEIMPORT_H */
