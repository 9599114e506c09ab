#!/usr/bin/python3
"""Writes DICOM volumes with pydicom (an independent writer, not DCMTK) for
test_casebuild_dicom.c. Usage: write_dicom_pydicom.py OUTDIR

Each volume is DX x DY x DZ voxels whose stored value at (x, y, z) is
  8 bit:  (7 x + 13 y + 29 z) mod 256
  16 bit: (257 x + 1031 y + 4099 z) mod 65536 (signed: minus 32768)
with z the index along the slice normal. Written, as scanners and tools write them:
  series8/       8-bit single-frame slices, no Rescale Slope/Intercept, files in shuffled order
  series16/      16-bit unsigned slices, no rescale tags
  series16r/     16-bit signed slices, Rescale Slope 0.5, Intercept -20
  usmf.dcm       one US Multi-frame image: frames stacked along the normal by
                 SpacingBetweenSlices from one ImagePositionPatient, no rescale tags
  enh.dcm        an Enhanced US Volume: shared functional groups (Pixel Measures, Plane
                 Orientation rotated 90 degrees about z, Pixel Value Transformation with slope 2,
                 intercept -5) and per-frame Plane Position, frames stored in shuffled order
and inputs that must be refused by name (hostile/):
  frames.dcm     NumberOfFrames 2147483647 over one frame of pixels (must not size anything)
  single.dcm     one 2D frame (not a volume)
  gap/           a series with one slice missing (inconsistent spacing)
  mixed/         two series in one folder
"""
import os
import random
import sys

import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileDataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

DX, DY, DZ = 12, 10, 8
SPACING = (0.3, 0.5)  # column (x), row (y) spacing in mm
SLICE = 0.8           # mm between slices
ORIGIN = (-10.0, 5.0, 30.0)


def values(bits, signed):
    z, y, x = np.meshgrid(np.arange(DZ), np.arange(DY), np.arange(DX), indexing="ij")
    if bits == 8:
        v = (7 * x + 13 * y + 29 * z) % 256
        return v.astype(np.uint8)
    v = (257 * x + 1031 * y + 4099 * z) % 65536
    if signed:
        return (v - 32768).astype(np.int16)
    return v.astype(np.uint16)


def base(sop_class, series_uid):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = FileDataset(None, {}, file_meta=meta, preamble=b"\0" * 128)
    ds.SOPClassUID = sop_class
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.SeriesInstanceUID = series_uid
    ds.StudyInstanceUID = generate_uid()
    ds.Modality = "US"
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.SamplesPerPixel = 1
    ds.Rows, ds.Columns = DY, DX
    ds.PixelSpacing = [SPACING[1], SPACING[0]]  # row spacing, column spacing
    ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
    ds.is_little_endian = True
    ds.is_implicit_VR = False
    return ds


def pixel_format(ds, bits, signed):
    ds.BitsAllocated = bits
    ds.BitsStored = bits
    ds.HighBit = bits - 1
    ds.PixelRepresentation = 1 if signed else 0


def series(outdir, name, bits, signed, rescale):
    d = os.path.join(outdir, name)
    os.makedirs(d)
    vol = values(bits, signed)
    uid = generate_uid()
    order = list(range(DZ))
    random.Random(5).shuffle(order)  # the reader must sort by position, not by file name
    for k, z in enumerate(order):
        ds = base("1.2.840.10008.5.1.4.1.1.7", uid)  # Secondary Capture
        pixel_format(ds, bits, signed)
        ds.InstanceNumber = z + 1
        ds.ImagePositionPatient = [ORIGIN[0], ORIGIN[1], ORIGIN[2] + z * SLICE]
        if rescale:
            ds.RescaleSlope = rescale[0]
            ds.RescaleIntercept = rescale[1]
        ds.PixelData = vol[z].tobytes()
        ds.save_as(os.path.join(d, "img%03d.dcm" % k), write_like_original=False)


def us_multiframe(outdir):
    vol = values(8, False)
    ds = base("1.2.840.10008.5.1.4.1.1.3.1", generate_uid())  # US Multi-frame Image
    pixel_format(ds, 8, False)
    ds.NumberOfFrames = DZ
    ds.ImagePositionPatient = list(ORIGIN)
    ds.SpacingBetweenSlices = SLICE
    ds.PixelData = vol.tobytes()
    ds.save_as(os.path.join(outdir, "usmf.dcm"), write_like_original=False)


def enhanced(outdir):
    vol = values(8, False)
    ds = base("1.2.840.10008.5.1.4.1.1.6.2", generate_uid())  # Enhanced US Volume
    del ds.PixelSpacing
    del ds.ImageOrientationPatient
    pixel_format(ds, 8, False)
    ds.NumberOfFrames = DZ
    shared = Dataset()
    pm = Dataset()
    pm.PixelSpacing = [SPACING[1], SPACING[0]]
    pm.SliceThickness = SLICE
    po = Dataset()
    po.ImageOrientationPatient = [0, 1, 0, -1, 0, 0]  # rows along +y, columns along -x
    pvt = Dataset()
    pvt.RescaleSlope = 2
    pvt.RescaleIntercept = -5
    pvt.RescaleType = "US"
    shared.PixelMeasuresSequence = [pm]
    shared.PlaneOrientationSequence = [po]
    shared.PixelValueTransformationSequence = [pvt]
    ds.SharedFunctionalGroupsSequence = [shared]
    order = list(range(DZ))
    random.Random(11).shuffle(order)
    frames = []
    for z in order:
        pp = Dataset()
        pp.ImagePositionPatient = [ORIGIN[0], ORIGIN[1], ORIGIN[2] + z * SLICE]
        fg = Dataset()
        fg.PlanePositionSequence = [pp]
        frames.append(fg)
    ds.PerFrameFunctionalGroupsSequence = frames
    ds.PixelData = np.ascontiguousarray(vol[order]).tobytes()
    ds.save_as(os.path.join(outdir, "enh.dcm"), write_like_original=False)


def hostile(outdir):
    d = os.path.join(outdir, "hostile")
    os.makedirs(d)
    vol = values(8, False)
    ds = base("1.2.840.10008.5.1.4.1.1.3.1", generate_uid())
    pixel_format(ds, 8, False)
    ds.NumberOfFrames = 2147483647
    ds.ImagePositionPatient = list(ORIGIN)
    ds.SpacingBetweenSlices = SLICE
    ds.PixelData = vol[0].tobytes()
    ds.save_as(os.path.join(d, "frames.dcm"), write_like_original=False)
    ds = base("1.2.840.10008.5.1.4.1.1.7", generate_uid())
    pixel_format(ds, 8, False)
    ds.ImagePositionPatient = list(ORIGIN)
    ds.PixelData = vol[0].tobytes()
    ds.save_as(os.path.join(d, "single.dcm"), write_like_original=False)
    for name, zs, uids in (("gap", [0, 1, 2, 4, 5], None), ("mixed", [0, 1, 2, 3], 2)):
        sd = os.path.join(d, name)
        os.makedirs(sd)
        series_uids = [generate_uid() for _ in range(uids or 1)]
        for k, z in enumerate(zs):
            ds = base("1.2.840.10008.5.1.4.1.1.7", series_uids[k % len(series_uids)])
            pixel_format(ds, 8, False)
            ds.ImagePositionPatient = [ORIGIN[0], ORIGIN[1], ORIGIN[2] + z * SLICE]
            ds.PixelData = vol[z].tobytes()
            ds.save_as(os.path.join(sd, "img%03d.dcm" % k), write_like_original=False)


def main():
    out = sys.argv[1]
    enhanced(out)
    hostile(out)
    series(out, "series8", 8, False, None)
    series(out, "series16", 16, False, None)
    series(out, "series16r", 16, True, (0.5, -20))
    us_multiframe(out)
    print("pydicom %s wrote 3 series, 2 multi-frame images and 4 hostile inputs in %s"
          % (pydicom.__version__, out))


if __name__ == "__main__":
    main()
