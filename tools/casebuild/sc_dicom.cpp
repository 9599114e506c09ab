// sc_dicom.cpp: DICOM volume import through DCMTK, see sc_dicom.h.
#include "sc_dicom.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "dcmtk/config/osconfig.h"
#include "dcmtk/dcmdata/dcrledrg.h"
#include "dcmtk/dcmdata/dcrleerg.h"
#include "dcmtk/dcmdata/dctk.h"
#include "dcmtk/dcmjpeg/djdecode.h"
#include "dcmtk/dcmjpls/djdecode.h"

extern "C" {
#define _Static_assert static_assert // sc_config.h is C11
#include "sc_config.h"
#undef _Static_assert
#include "sc_err.h"
}

namespace
{

int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
{
    if (err != nullptr && errlen > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return rc;
}

void register_codecs()
{
    static bool done = false;
    if (!done) {
        DJDecoderRegistration::registerCodecs();
        DJLSDecoderRegistration::registerCodecs();
        DcmRLEDecoderRegistration::registerCodecs();
        DcmRLEEncoderRegistration::registerCodecs();
        done = true;
    }
}

struct frame_geom {
    bool has_pos = false;
    double pos[3] = {0, 0, 0};
};

struct dicom_file {
    DcmFileFormat ff;
    DcmDataset *ds = nullptr;
    Uint16 rows = 0, cols = 0, bits = 0, pixrep = 0, spp = 1, planar = 0;
    Sint32 frames = 1;
    std::string photometric, series;
    double slope = 1.0, intercept = 0.0;
    double spacing[2] = {0, 0}; // column spacing (x), row spacing (y)
    bool has_spacing = false;
    double orient[6] = {1, 0, 0, 0, 1, 0};
    bool has_orient = false;
    double slice_spacing = 0.0;
    std::vector<frame_geom> fg;
};

// Geometry items may sit in the dataset or in the shared / per-frame functional groups.
void read_plane(DcmItem *it, dicom_file &f, frame_geom *g)
{
    if (it == nullptr) {
        return;
    }
    double v;
    DcmItem *sub = nullptr;
    if (it->findAndGetSequenceItem(DCM_PixelMeasuresSequence, sub, 0).good() && sub) {
        read_plane(sub, f, g);
    }
    if (it->findAndGetSequenceItem(DCM_PlaneOrientationSequence, sub, 0).good() && sub) {
        read_plane(sub, f, g);
    }
    if (it->findAndGetSequenceItem(DCM_PlanePositionSequence, sub, 0).good() && sub) {
        read_plane(sub, f, g);
    }
    if (it->findAndGetFloat64(DCM_PixelSpacing, v, 0).good()) {
        f.spacing[1] = v; // row spacing: between rows, along the column direction
        if (it->findAndGetFloat64(DCM_PixelSpacing, v, 1).good()) {
            f.spacing[0] = v;
            f.has_spacing = true;
        }
    }
    if (it->findAndGetFloat64(DCM_SpacingBetweenSlices, v, 0).good()) {
        f.slice_spacing = v;
    }
    bool all = true;
    double o[6];
    for (unsigned i = 0; i < 6; i++) {
        all = all && it->findAndGetFloat64(DCM_ImageOrientationPatient, o[i], i).good();
    }
    if (all) {
        std::memcpy(f.orient, o, sizeof o);
        f.has_orient = true;
    }
    if (g != nullptr) {
        double p[3];
        bool ok = true;
        for (unsigned i = 0; i < 3; i++) {
            ok = ok && it->findAndGetFloat64(DCM_ImagePositionPatient, p[i], i).good();
        }
        if (ok) {
            std::memcpy(g->pos, p, sizeof p);
            g->has_pos = true;
        }
    }
}

int load_one(const std::string &path, dicom_file &f, uint64_t max_voxels, char *err,
             size_t errlen)
{
    OFCondition c = f.ff.loadFile(path.c_str());
    if (c.bad()) {
        return fail(err, errlen, SC_ERR_PARSE, "%s: %s", path.c_str(), c.text());
    }
    f.ds = f.ff.getDataset();
    if (!f.ds->tagExists(DCM_PixelData)) {
        return fail(err, errlen, SC_ERR_PARSE, "%s: no pixel data", path.c_str());
    }
    c = f.ds->chooseRepresentation(EXS_LittleEndianExplicit, nullptr);
    if (c.bad() || !f.ds->canWriteXfer(EXS_LittleEndianExplicit)) {
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: cannot decompress the pixel data",
                    path.c_str());
    }
    f.ds->findAndGetUint16(DCM_Rows, f.rows);
    f.ds->findAndGetUint16(DCM_Columns, f.cols);
    f.ds->findAndGetUint16(DCM_BitsAllocated, f.bits);
    f.ds->findAndGetUint16(DCM_PixelRepresentation, f.pixrep);
    f.ds->findAndGetUint16(DCM_SamplesPerPixel, f.spp);
    f.ds->findAndGetUint16(DCM_PlanarConfiguration, f.planar);
    if (f.ds->findAndGetSint32(DCM_NumberOfFrames, f.frames).bad() || f.frames < 1) {
        f.frames = 1;
    }
    OFString s;
    if (f.ds->findAndGetOFString(DCM_PhotometricInterpretation, s).good()) {
        f.photometric = s.c_str();
    }
    if (f.ds->findAndGetOFString(DCM_SeriesInstanceUID, s).good()) {
        f.series = s.c_str();
    }
    DcmItem *shared = nullptr;
    f.ds->findAndGetSequenceItem(DCM_SharedFunctionalGroupsSequence, shared, 0);
    /* Rescale Slope / Intercept are optional (ultrasound usually has neither): an absent tag
     * means 1 / 0 (PS3.3 C.11.1.1.2). DCMTK's findAndGet sets the value to 0 when the tag is
     * missing, which read as slope 0 made every voxel 0, so only a found value counts. An
     * enhanced (multi-frame) object keeps them in the Pixel Value Transformation functional
     * group. */
    {
        DcmItem *pvt = nullptr;
        DcmItem *src = f.ds;
        if (shared != nullptr &&
            shared->findAndGetSequenceItem(DCM_PixelValueTransformationSequence, pvt, 0).good() &&
            pvt != nullptr) {
            src = pvt;
        }
        double v = 0.0;
        if (src->findAndGetFloat64(DCM_RescaleSlope, v).good()) {
            if (!std::isfinite(v) || v == 0.0) {
                return fail(err, errlen, SC_ERR_PARSE, "%s: RescaleSlope %g is not usable",
                            path.c_str(), v);
            }
            f.slope = v;
        }
        if (src->findAndGetFloat64(DCM_RescaleIntercept, v).good()) {
            if (!std::isfinite(v)) {
                return fail(err, errlen, SC_ERR_PARSE, "%s: RescaleIntercept is not finite",
                            path.c_str());
            }
            f.intercept = v;
        }
    }
    // sizes from the file are checked before anything is sized by them (NumberOfFrames
    // 2147483647 must not size a vector)
    if (f.rows == 0 || f.cols == 0 || (f.bits != 8 && f.bits != 16)) {
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                    "%s: Rows %u, Columns %u, Bits Allocated %u (8 or 16 supported)", path.c_str(),
                    f.rows, f.cols, f.bits);
    }
    if ((uint64_t)f.frames > SC_MAX_VOLUME_DIM ||
        (uint64_t)f.rows * f.cols * (uint64_t)f.frames > max_voxels) {
        return fail(err, errlen, SC_ERR_NO_SPACE,
                    "%s: Number of Frames %ld x Rows %u x Columns %u is above the ceiling (%u "
                    "frames, %llu voxels; --max-voxels)",
                    path.c_str(), (long)f.frames, f.rows, f.cols, SC_MAX_VOLUME_DIM,
                    (unsigned long long)max_voxels);
    }
    f.fg.assign((size_t)f.frames, frame_geom());
    frame_geom top;
    read_plane(f.ds, f, &top);
    read_plane(shared, f, nullptr);
    for (Sint32 i = 0; i < f.frames; i++) {
        DcmItem *pf = nullptr;
        if (f.ds->findAndGetSequenceItem(DCM_PerFrameFunctionalGroupsSequence, pf, i).good()) {
            read_plane(pf, f, &f.fg[(size_t)i]);
        }
    }
    if (!f.fg[0].has_pos && top.has_pos) {
        f.fg[0] = top;
    }
    if (f.spp != 1 && f.spp != 3) {
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: %u samples per pixel", path.c_str(),
                    f.spp);
    }
    return SC_OK;
}

// Values of frame `frame` of file f into out (cols*rows doubles), rescaled.
int frame_values(dicom_file &f, Sint32 frame, double *out, char *err, size_t errlen)
{
    const size_t npix = (size_t)f.rows * f.cols;
    const size_t per_frame = npix * f.spp;
    unsigned long count = 0;
    const bool mono1 = f.photometric == "MONOCHROME1";
    const bool rgb = f.photometric == "RGB";
    if (f.bits == 8) {
        const Uint8 *p = nullptr;
        if (f.ds->findAndGetUint8Array(DCM_PixelData, p, &count).bad() || p == nullptr ||
            count < per_frame * (size_t)(frame + 1)) {
            return fail(err, errlen, SC_ERR_PARSE, "pixel data shorter than %d frames", frame + 1);
        }
        p += per_frame * (size_t)frame;
        for (size_t i = 0; i < npix; i++) {
            double v;
            if (f.spp == 1) {
                v = f.pixrep ? (double)(Sint8)p[i] : (double)p[i];
            } else {
                size_t r = f.planar ? i : i * 3, g = f.planar ? npix + i : i * 3 + 1,
                       b = f.planar ? 2 * npix + i : i * 3 + 2;
                // RGB: Rec. 601 luma; YBR: the Y sample is the luminance
                v = rgb ? 0.299 * p[r] + 0.587 * p[g] + 0.114 * p[b] : (double)p[r];
            }
            out[i] = v;
        }
    } else {
        if (f.spp != 1) {
            return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "16-bit colour data");
        }
        const Uint16 *p = nullptr;
        if (f.ds->findAndGetUint16Array(DCM_PixelData, p, &count).bad() || p == nullptr ||
            count < npix * (size_t)(frame + 1)) {
            return fail(err, errlen, SC_ERR_PARSE, "pixel data shorter than %d frames", frame + 1);
        }
        p += npix * (size_t)frame;
        for (size_t i = 0; i < npix; i++) {
            out[i] = f.pixrep ? (double)(Sint16)p[i] : (double)p[i];
        }
    }
    double lo = 0.0, hi = 0.0;
    if (mono1) {
        // MONOCHROME1: high values are dark; invert within the stored range
        hi = f.bits == 8 ? 255.0 : 65535.0;
        if (f.pixrep) {
            lo = f.bits == 8 ? -128.0 : -32768.0;
            hi = f.bits == 8 ? 127.0 : 32767.0;
        }
    }
    for (size_t i = 0; i < npix; i++) {
        double v = mono1 ? lo + hi - out[i] : out[i];
        out[i] = v * f.slope + f.intercept;
    }
    return SC_OK;
}

double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

} // namespace

namespace
{
int dicom_read(const char *path, uint64_t max_voxels, sc_image *img, char *err, size_t errlen)
{
    register_codecs();
    struct stat st;
    if (stat(path, &st) != 0) {
        return fail(err, errlen, SC_ERR_NOT_FOUND, "%s: no such file or directory", path);
    }
    std::vector<std::string> files;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        if (d == nullptr) {
            return fail(err, errlen, SC_ERR_IO, "%s: cannot list", path);
        }
        while (dirent *e = readdir(d)) {
            if (e->d_name[0] == '.') {
                continue;
            }
            files.push_back(std::string(path) + "/" + e->d_name);
        }
        closedir(d);
        std::sort(files.begin(), files.end());
    } else {
        files.push_back(path);
    }
    // load every file that is an image; a directory must hold exactly one series
    std::vector<std::unique_ptr<dicom_file>> owned; // freed on every return and exception
    std::vector<dicom_file *> imgs;
    auto cleanup = [&]() {};
    char first_err[256] = "";
    for (const std::string &fp : files) {
        owned.push_back(std::make_unique<dicom_file>());
        dicom_file *f = owned.back().get();
        int rc =
            load_one(fp, *f, max_voxels, first_err[0] ? nullptr : first_err, sizeof first_err);
        if (rc != SC_OK) {
            owned.pop_back();
            if (files.size() == 1 || rc == SC_ERR_NOT_SUPPORTED) {
                cleanup();
                return fail(err, errlen, rc, "%s", first_err);
            }
            continue; // non-DICOM or non-image file in the directory (DICOMDIR, notes...)
        }
        imgs.push_back(f);
    }
    if (imgs.empty()) {
        return fail(err, errlen, SC_ERR_PARSE, "%s: no DICOM image (%s)", path, first_err);
    }
    dicom_file &f0 = *imgs[0];
    for (dicom_file *f : imgs) {
        if (f->series != f0.series || f->rows != f0.rows || f->cols != f0.cols ||
            f->bits != f0.bits) {
            cleanup();
            return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                        "%s: several series or image sizes; point at one series", path);
        }
    }
    if (!f0.has_orient || !f0.has_spacing) {
        cleanup();
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                    "%s: no Image Orientation / Pixel Spacing (not a spatial volume)", path);
    }
    const double *rowdir = f0.orient, *coldir = f0.orient + 3;
    double normal[3] = {rowdir[1] * coldir[2] - rowdir[2] * coldir[1],
                        rowdir[2] * coldir[0] - rowdir[0] * coldir[2],
                        rowdir[0] * coldir[1] - rowdir[1] * coldir[0]};
    // every slice: (file, frame, position along the normal)
    struct slice {
        dicom_file *f;
        Sint32 frame;
        double pos[3];
        double d;
    };
    std::vector<slice> sl;
    for (dicom_file *f : imgs) {
        for (Sint32 k = 0; k < f->frames; k++) {
            frame_geom g = f->fg[(size_t)k];
            if (!g.has_pos) {
                if (k > 0 && f->fg[0].has_pos && f->slice_spacing > 0.0) {
                    for (int a = 0; a < 3; a++) {
                        g.pos[a] = f->fg[0].pos[a] + normal[a] * f->slice_spacing * k;
                    }
                } else {
                    cleanup();
                    return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                                "%s: frame %d has no spatial position (a 2D cine loop or a "
                                "vendor-private 3D format, not a volume)",
                                path, k + 1);
                }
            }
            sl.push_back({f, k, {g.pos[0], g.pos[1], g.pos[2]}, dot3(g.pos, normal)});
        }
    }
    if (sl.size() < 2) {
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                    "%s: a single 2D frame, not a volume (a volume is a series of 2 or more "
                    "slices, or a multi-frame object with frame positions)",
                    path);
    }
    std::sort(sl.begin(), sl.end(), [](const slice &a, const slice &b) { return a.d < b.d; });
    double dz = 1.0;
    if (sl.size() > 1) {
        dz = (sl.back().d - sl.front().d) / (double)(sl.size() - 1);
        for (size_t i = 1; i < sl.size(); i++) {
            double step = sl[i].d - sl[i - 1].d;
            if (!(dz > 0.0) || std::fabs(step - dz) > 0.01 * dz + 1e-4) {
                cleanup();
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                            "%s: slice spacing not uniform (%.4g vs %.4g mm) or repeated", path,
                            step, dz);
            }
        }
    }
    const size_t npix = (size_t)f0.rows * f0.cols, n = npix * sl.size();
    if (sl.size() > SC_MAX_VOLUME_DIM || (uint64_t)n > max_voxels) {
        cleanup();
        return fail(err, errlen, SC_ERR_NO_SPACE,
                    "%s: %zu slices of %u x %u: above the ceiling (%u slices, %llu voxels)", path,
                    sl.size(), f0.cols, f0.rows, SC_MAX_VOLUME_DIM,
                    (unsigned long long)max_voxels);
    }
    std::memset(img, 0, sizeof *img);
    // DICOM patient coordinates are LPS (PS3.3 C.7.6.2.1.1)
    img->anatomical = 1;
    img->lps[0] = img->lps[4] = img->lps[8] = 1.0;
    img->data = (double *)std::malloc(n * sizeof(double));
    if (img->data == nullptr) {
        cleanup();
        return fail(err, errlen, SC_ERR_NO_SPACE, "out of memory");
    }
    for (size_t k = 0; k < sl.size(); k++) {
        int rc = frame_values(*sl[k].f, sl[k].frame, img->data + k * npix, err, errlen);
        if (rc != SC_OK) {
            std::free(img->data);
            img->data = nullptr;
            cleanup();
            return rc;
        }
    }
    img->dim[0] = f0.cols;
    img->dim[1] = f0.rows;
    img->dim[2] = (uint32_t)sl.size();
    img->spacing[0] = f0.spacing[0];
    img->spacing[1] = f0.spacing[1];
    img->spacing[2] = dz;
    for (int r = 0; r < 3; r++) {
        img->origin[r] = sl[0].pos[r];
        img->dir[r * 3 + 0] = rowdir[r];
        img->dir[r * 3 + 1] = coldir[r];
        img->dir[r * 3 + 2] = normal[r];
    }
    img->type = f0.bits == 8 ? (f0.pixrep ? SC_ELEM_I8 : SC_ELEM_U8)
                             : (f0.pixrep ? SC_ELEM_I16 : SC_ELEM_U16);
    if (f0.spp != 1 || f0.slope != 1.0 || f0.intercept != 0.0) {
        img->type = SC_ELEM_F64; // derived values: window them like float data
    }
    cleanup();
    return SC_OK;
}

} // namespace

extern "C" int sc_dicom_read(const char *path, uint64_t max_voxels, sc_image *img, char *err,
                             size_t errlen)
{
    // DCMTK and the standard library may throw (std::bad_alloc above all): nothing escapes
    // into the C caller
    img->data = nullptr;
    try {
        return dicom_read(path, max_voxels, img, err, errlen);
    } catch (const std::bad_alloc &) {
        std::free(img->data);
        img->data = nullptr;
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: out of memory while decoding", path);
    } catch (const std::exception &e) {
        std::free(img->data);
        img->data = nullptr;
        return fail(err, errlen, SC_ERR_PARSE, "%s: %s", path, e.what());
    } catch (...) {
        std::free(img->data);
        img->data = nullptr;
        return fail(err, errlen, SC_ERR_PARSE, "%s: unreadable (exception)", path);
    }
}

extern "C" int sc_dicom_write_fixture(const char *dir, const sc_image *vol, int bits, int is_signed,
                                      double slope, double intercept, int multiframe, int compress)
{
    register_codecs();
    char series[128], study[128], uid[128];
    dcmGenerateUniqueIdentifier(series, SITE_SERIES_UID_ROOT);
    dcmGenerateUniqueIdentifier(study, SITE_STUDY_UID_ROOT);
    const size_t npix = (size_t)vol->dim[0] * vol->dim[1];
    auto stored = [&](double v) { return std::llround((v - intercept) / slope); };
    auto fill = [&](DcmDataset *ds, uint32_t k0, uint32_t nk) -> bool {
        char b[256];
        ds->putAndInsertString(DCM_SOPClassUID, multiframe ? UID_EnhancedUSVolumeStorage
                                                           : UID_UltrasoundImageStorage);
        ds->putAndInsertString(DCM_SOPInstanceUID,
                               dcmGenerateUniqueIdentifier(uid, SITE_INSTANCE_UID_ROOT));
        ds->putAndInsertString(DCM_StudyInstanceUID, study);
        ds->putAndInsertString(DCM_SeriesInstanceUID, series);
        ds->putAndInsertString(DCM_Modality, "US");
        ds->putAndInsertUint16(DCM_Rows, (Uint16)vol->dim[1]);
        ds->putAndInsertUint16(DCM_Columns, (Uint16)vol->dim[0]);
        ds->putAndInsertUint16(DCM_SamplesPerPixel, 1);
        ds->putAndInsertString(DCM_PhotometricInterpretation, "MONOCHROME2");
        ds->putAndInsertUint16(DCM_BitsAllocated, (Uint16)bits);
        ds->putAndInsertUint16(DCM_BitsStored, (Uint16)bits);
        ds->putAndInsertUint16(DCM_HighBit, (Uint16)(bits - 1));
        ds->putAndInsertUint16(DCM_PixelRepresentation, (Uint16)(is_signed ? 1 : 0));
        snprintf(b, sizeof b, "%.10g", slope);
        ds->putAndInsertString(DCM_RescaleSlope, b);
        snprintf(b, sizeof b, "%.10g", intercept);
        ds->putAndInsertString(DCM_RescaleIntercept, b);
        char orient[256], spacing[128];
        snprintf(orient, sizeof orient, "%.10g\\%.10g\\%.10g\\%.10g\\%.10g\\%.10g", vol->dir[0],
                 vol->dir[3], vol->dir[6], vol->dir[1], vol->dir[4], vol->dir[7]);
        snprintf(spacing, sizeof spacing, "%.10g\\%.10g", vol->spacing[1], vol->spacing[0]);
        auto pos_of = [&](uint32_t k, char *out, size_t n) {
            double p[3];
            for (int r = 0; r < 3; r++) {
                p[r] = vol->origin[r] + vol->dir[r * 3 + 2] * vol->spacing[2] * k;
            }
            snprintf(out, n, "%.10g\\%.10g\\%.10g", p[0], p[1], p[2]);
        };
        if (!multiframe) {
            ds->putAndInsertString(DCM_ImageOrientationPatient, orient);
            ds->putAndInsertString(DCM_PixelSpacing, spacing);
            pos_of(k0, b, sizeof b);
            ds->putAndInsertString(DCM_ImagePositionPatient, b);
        } else {
            snprintf(b, sizeof b, "%u", nk);
            ds->putAndInsertString(DCM_NumberOfFrames, b);
            DcmItem *sh = nullptr, *it = nullptr;
            ds->findOrCreateSequenceItem(DCM_SharedFunctionalGroupsSequence, sh, 0);
            sh->findOrCreateSequenceItem(DCM_PixelMeasuresSequence, it, 0);
            it->putAndInsertString(DCM_PixelSpacing, spacing);
            sh->findOrCreateSequenceItem(DCM_PlaneOrientationSequence, it, 0);
            it->putAndInsertString(DCM_ImageOrientationPatient, orient);
            // frames written in reverse order: the reader must sort by position
            for (uint32_t k = 0; k < nk; k++) {
                DcmItem *pf = nullptr, *pp = nullptr;
                ds->findOrCreateSequenceItem(DCM_PerFrameFunctionalGroupsSequence, pf,
                                             (signed long)k);
                pf->findOrCreateSequenceItem(DCM_PlanePositionSequence, pp, 0);
                pos_of(nk - 1 - k, b, sizeof b);
                pp->putAndInsertString(DCM_ImagePositionPatient, b);
            }
        }
        const size_t count = npix * nk;
        if (bits == 8) {
            std::vector<Uint8> px(count);
            for (uint32_t kk = 0; kk < nk; kk++) {
                uint32_t k = multiframe ? nk - 1 - kk : k0 + kk;
                for (size_t i = 0; i < npix; i++) {
                    px[kk * npix + i] = (Uint8)stored(vol->data[k * npix + i]);
                }
            }
            return ds->putAndInsertUint8Array(DCM_PixelData, px.data(), (unsigned long)count)
                .good();
        }
        std::vector<Uint16> px(count);
        for (uint32_t kk = 0; kk < nk; kk++) {
            uint32_t k = multiframe ? nk - 1 - kk : k0 + kk;
            for (size_t i = 0; i < npix; i++) {
                long long sv = stored(vol->data[k * npix + i]);
                px[kk * npix + i] = is_signed ? (Uint16)(Sint16)sv : (Uint16)sv;
            }
        }
        return ds->putAndInsertUint16Array(DCM_PixelData, px.data(), (unsigned long)count).good();
    };
    const E_TransferSyntax xfer = compress ? EXS_RLELossless : EXS_LittleEndianExplicit;
    auto save = [&](DcmFileFormat &ff, const std::string &p) -> int {
        if (compress && ff.getDataset()->chooseRepresentation(EXS_RLELossless, nullptr).bad()) {
            return SC_ERR_IO;
        }
        return ff.saveFile(p.c_str(), xfer).good() ? SC_OK : SC_ERR_IO;
    };
    if (multiframe) {
        DcmFileFormat ff;
        if (!fill(ff.getDataset(), 0, vol->dim[2])) {
            return SC_ERR_IO;
        }
        return save(ff, std::string(dir) + "/volume.dcm");
    }
    for (uint32_t k = 0; k < vol->dim[2]; k++) {
        DcmFileFormat ff;
        if (!fill(ff.getDataset(), k, 1)) {
            return SC_ERR_IO;
        }
        // file names in an order unrelated to position: the reader must sort
        char name[64];
        snprintf(name, sizeof name, "/IM%04u.dcm", (k * 7u + 3u) % 1000u);
        int rc = save(ff, std::string(dir) + name);
        if (rc != SC_OK) {
            return rc;
        }
    }
    return SC_OK;
}
