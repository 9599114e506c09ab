#!/usr/bin/python3
"""Write one neck-like labelled volume in every format sc-casebuild imports, each by a writer
independent of sonocomp, into OUTDIR (the end-to-end import test, tests/casebuild/e2e_import_press.sh):

  nrrd/vol.nrrd, nrrd/lab.nrrd   teem's `unu make` (teem-apps), space right-anterior-superior,
                                 grid i -> right, j -> anterior (depth is -j), k -> superior;
                                 uint16 volume gzip-encoded; labels numbered by a foreign
                                 scheme (LABEL_MAP below)
  mha/vol.mhd + vol.raw          a MetaImage header written here (ITK's keys), LPS world with
  mha/lab.mha                    AnatomicalOrientation RAI: i -> left, j -> posterior (depth
                                 +j), k -> superior; float32 volume; labels in the project's
                                 own numbering (0 outside ... 8 bone)
  dicom/IM*.dcm                  pydicom: an axial series (ImageOrientationPatient 1\\0\\0\\0\\1\\0,
                                 rows down = posterior = depth), 8-bit MONOCHROME2 without
                                 Rescale Slope/Intercept, files named out of position order;
                                 on the MetaImage grid, so mha/lab.mha labels it

The anatomy (mm; x toward the patient's right from the centre line, s along the body, d depth
below the skin; 2 mm of gel above the skin): skin 1.5 mm, fat to 5 mm, a muscle lens, the
internal jugular vein (7 x 4.5 mm semi-axes) at x -5.5, depth 14, the carotid (3.8 mm radius)
at x +5.5, depth 15, fat around them, deep muscle from 24 mm, bone from 32 mm. Depth is along
a different grid axis (and sign) in each file: the importer must find it from the file.

Needs /usr/bin/python3 with Debian's python3-numpy and python3-pydicom, and teem-apps.
"""
import os
import subprocess
import sys

import numpy as np
import pydicom
from pydicom.dataset import FileDataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, UltrasoundImageStorage, generate_uid

SP = 0.5  # mm, isotropic
NX, NS, ND = 72, 48, 80  # lateral 36 mm, along the body 24 mm, depth 40 mm (2 mm gel)
OUTSIDE, SKIN, FAT, MUSCLE, VEIN, ARTERY, NERVE, THROMBUS, BONE = range(9)
# the NRRD label map's foreign numbering, and the --label-map that undoes it
FOREIGN = {OUTSIDE: 0, SKIN: 11, FAT: 14, MUSCLE: 15, VEIN: 2, ARTERY: 3, BONE: 16}
LABEL_MAP = "0=outside,11=skin,14=fat,15=muscle,2=vein,3=artery,16=bone"


def anatomy():
    """labels[x_index, s_index, d_index] with x toward the right, d deeper"""
    x = (np.arange(NX) - (NX - 1) / 2.0) * SP
    d = np.arange(ND) * SP - 2.0
    X, D = np.meshgrid(x, d, indexing="ij")  # (NX, ND)
    lab = np.full((NX, ND), FAT, dtype=np.uint8)
    lens = 5.0 + 6.0 * np.sqrt(np.clip(1.0 - ((X + 2.0) / 16.0) ** 2, 0.0, 1.0))
    lab[(D >= 5.0) & (D < lens)] = MUSCLE
    lab[D >= 24.0] = MUSCLE
    vein = ((X + 5.5) / 7.0) ** 2 + ((D - 14.0) / 4.5) ** 2 <= 1.0
    artery = ((X - 5.5) / 3.8) ** 2 + ((D - 15.0) / 3.8) ** 2 <= 1.0
    lab[vein] = VEIN
    lab[artery] = ARTERY
    lab[D >= 32.0] = BONE
    lab[D < 1.5] = SKIN
    lab[D < 0.0] = OUTSIDE
    return np.repeat(lab[:, None, :], NS, axis=1)  # (NX, NS, ND)


def echo(lab):
    base = np.array([5, 160, 70, 110, 12, 12, 140, 150, 230], dtype=np.float64)
    rng = np.random.default_rng(1)
    return base[lab] * (0.6 + 0.8 * rng.random(lab.shape))


def write_nrrd(out, lab, img):
    os.makedirs(out, exist_ok=True)
    # grid (i right, j anterior, k superior): i = x, j = (ND-1) - d, k = s
    vol = img[:, :, ::-1].astype(np.uint16) * 200  # (x, s, depth reversed)
    vol = np.transpose(vol, (0, 2, 1))  # (i = x, j = depth reversed, k = s)
    lut = np.zeros(256, dtype=np.uint8)
    for ours, theirs in FOREIGN.items():
        lut[ours] = theirs
    fl = np.transpose(lut[lab][:, :, ::-1], (0, 2, 1))
    # files are x fastest: C order of (k, j, i)
    raw_v = np.ascontiguousarray(np.transpose(vol, (2, 1, 0))).astype("<u2").tobytes()
    raw_l = np.ascontiguousarray(np.transpose(fl, (2, 1, 0))).tobytes()
    # RAS world: x right, y anterior = -depth (the skin at y = 0), j = 0 the deepest row
    x0 = -(NX - 1) / 2.0 * SP
    y0 = -((ND - 1) * SP - 2.0)  # j = 0 is the deepest row: anterior coordinate -d
    orig = "(%g,%g,%g)" % (x0, y0, -30.0)
    dirs = "(%g,0,0) (0,%g,0) (0,0,%g)" % (SP, SP, SP)
    for name, raw, typ, enc in (("vol", raw_v, "ushort", "gzip"), ("lab", raw_l, "uchar", "raw")):
        path = os.path.join(out, name + ".nrrd")
        # `unu make` wraps the raw bytes from stdin; `unu save` writes the encoding asked for
        made = subprocess.run(["teem-unu", "make", "-i", "-", "-t", typ, "-s", str(NX), str(ND),
                               str(NS), "-en", "little", "-spc", "RAS", "-orig", orig, "-dirs",
                               dirs, "-o", "-"], input=raw, check=True, capture_output=True)
        subprocess.run(["teem-unu", "save", "-f", "nrrd", "-e", enc, "-i", "-", "-o", path],
                       input=made.stdout, check=True, capture_output=True)


def mha_grid(lab, img):
    """(i left, j posterior = depth, k superior): i = (NX-1) - x"""
    return lab[::-1, :, :], img[::-1, :, :]


def write_mha(out, lab, img):
    os.makedirs(out, exist_ok=True)
    lab_g, img_g = mha_grid(lab, img)
    # (i, k = s, j = d) -> file order x fastest: C order (k, j, i)
    def fileorder(a):
        return np.ascontiguousarray(np.transpose(a, (1, 2, 0)))
    x0 = -(NX - 1) / 2.0 * SP  # LPS x (toward the left) of i = 0, the rightmost column
    head = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
            "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\n"
            "Offset = %g %g %g\nCenterOfRotation = 0 0 0\nAnatomicalOrientation = RAI\n"
            "ElementSpacing = %g %g %g\nDimSize = %d %d %d\n"
            % (x0, -2.0, -30.0, SP, SP, SP, NX, ND, NS))
    with open(os.path.join(out, "vol.mhd"), "w") as f:
        f.write(head + "ElementType = MET_FLOAT\nElementDataFile = vol.raw\n")
    with open(os.path.join(out, "vol.raw"), "wb") as f:
        f.write(fileorder(img_g).astype("<f4").tobytes())
    with open(os.path.join(out, "lab.mha"), "wb") as f:
        f.write((head + "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n").encode())
        f.write(fileorder(lab_g).astype(np.uint8).tobytes())


def write_dicom(out, img):
    os.makedirs(out, exist_ok=True)
    _, img_g = mha_grid(np.zeros_like(img, dtype=np.uint8), img)
    x0 = -(NX - 1) / 2.0 * SP
    series, study, frame = generate_uid(), generate_uid(), generate_uid()
    for k in range(NS):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = UltrasoundImageStorage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = FileDataset(None, {}, file_meta=meta, preamble=b"\0" * 128)
        ds.SOPClassUID = UltrasoundImageStorage
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.StudyInstanceUID, ds.SeriesInstanceUID = study, series
        ds.FrameOfReferenceUID = frame
        ds.Modality = "US"
        ds.Rows, ds.Columns = ND, NX
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
        ds.PixelSpacing = [SP, SP]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.ImagePositionPatient = [x0, -2.0, -30.0 + k * SP]
        ds.InstanceNumber = k + 1
        # rows = depth (j), columns = i: (ND, NX)
        px = np.clip(img_g[:, k, :].T, 0, 255).astype(np.uint8)
        ds.PixelData = np.ascontiguousarray(px).tobytes()
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.save_as(os.path.join(out, "IM%04d.dcm" % ((k * 17 + 5) % 1000)), write_like_original=False)


def main():
    out = sys.argv[1]
    lab = anatomy()
    img = echo(lab)
    write_nrrd(os.path.join(out, "nrrd"), lab, img)
    write_mha(os.path.join(out, "mha"), lab, img)
    write_dicom(os.path.join(out, "dicom"), img)
    print(LABEL_MAP)


if __name__ == "__main__":
    main()
