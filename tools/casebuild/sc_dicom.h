/*
 * sc_dicom.h: DICOM volume import through DCMTK (C++ behind a C API), built only when the
 * DCMTK development package is found (SC_HAVE_DCMTK). Host tool code; allocates.
 *
 * Input: a directory holding one series of single-frame slices (sorted along the slice normal
 * by Image Position), or one multi-frame file with per-frame positions (enhanced functional
 * groups: Plane Position / Plane Orientation / Pixel Measures) or a first position plus
 * Spacing Between Slices. Compressed transfer syntaxes that DCMTK decodes (JPEG, JPEG-LS,
 * RLE) are decompressed. Samples: MONOCHROME1/2 (8/16-bit, signed or not, rescale slope and
 * intercept applied) and RGB / YBR (luminance). Only pixel data and geometry tags are read:
 * no patient, study or institution attribute is looked at, so none can reach a case.
 * 2D cine loops (frames without spatial positions) and non-uniform slice spacing are refused.
 */
#ifndef SC_DICOM_H
#define SC_DICOM_H

#include <stddef.h>
#include <stdint.h>

#include "sc_image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Errors: SC_ERR_NOT_FOUND, SC_ERR_IO, SC_ERR_PARSE, SC_ERR_NOT_SUPPORTED, SC_ERR_NO_SPACE;
 * a message in err. Frame counts and rows x columns x frames are checked against max_voxels
 * before anything is sized by them; DCMTK's and the C++ library's exceptions are caught and
 * reported (SC_ERR_NO_SPACE for std::bad_alloc, SC_ERR_PARSE otherwise). */
int sc_dicom_read(const char *path, uint64_t max_voxels, sc_image *img, char *err, size_t errlen);

/* Test fixture writer: writes vol (values must fit the type) as DICOM: a series of slices
 * into directory dir (multiframe = 0) or one enhanced multi-frame file dir/volume.dcm
 * (multiframe = 1); bits 8 or 16, signed for 16 only, with the given rescale; compress = 1
 * stores it RLE-compressed. Geometry from vol (origin, spacing, dir). */
int sc_dicom_write_fixture(const char *dir, const sc_image *vol, int bits, int is_signed,
                           double slope, double intercept, int multiframe, int compress);

#ifdef __cplusplus
}
#endif

#endif /* SC_DICOM_H */
