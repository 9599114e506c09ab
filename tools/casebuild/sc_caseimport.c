/* sc_caseimport.c: MetaImage and NRRD readers, resampling to a case, see sc_caseimport.h. */
#include "sc_caseimport.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <zlib.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_materials.h"
#ifdef SC_HAVE_DCMTK
#include "sc_dicom.h"
#endif
#include <sys/stat.h>

static int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
{
    if (err != NULL && errlen > 0u) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return rc;
}

/* ---- file helpers ----------------------------------------------------------------------- */
static int read_file(const char *path, uint64_t max_bytes, uint8_t **data, size_t *size, char *err,
                     size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(err, errlen, errno == ENOENT ? SC_ERR_NOT_FOUND : SC_ERR_IO, "%s: %s", path,
                    strerror(errno));
    }
    if (fseek(f, 0, SEEK_END) != 0) {
        fclose(f);
        return fail(err, errlen, SC_ERR_IO, "%s: cannot seek", path);
    }
    long len = ftell(f);
    if (len < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return fail(err, errlen, SC_ERR_IO, "%s: cannot size (not a regular file?)", path);
    }
    if ((uint64_t)len > max_bytes) {
        fclose(f);
        return fail(err, errlen, SC_ERR_NO_SPACE,
                    "%s: %ld bytes, above the ceiling of %llu bytes for the voxel limit "
                    "(--max-voxels)",
                    path, len, (unsigned long long)max_bytes);
    }
    uint8_t *buf = malloc((size_t)len + 1u);
    if (buf == NULL) {
        fclose(f);
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: out of memory", path);
    }
    if (fread(buf, 1, (size_t)len, f) != (size_t)len) {
        free(buf);
        fclose(f);
        return fail(err, errlen, SC_ERR_IO, "%s: short read", path);
    }
    fclose(f);
    buf[len] = 0;
    *data = buf;
    *size = (size_t)len;
    return SC_OK;
}

/* Path of a data file named in a header: relative to the header's directory. Unless allowed,
 * only beside the header (or below it): no absolute path, no ".." component, so a header
 * cannot make the importer read an unrelated file as voxels. */
static int sibling_path(char *out, size_t n, const char *header_path, const char *field,
                        const char *name, int allow_any, char *err, size_t errlen)
{
    if (!allow_any) {
        int dotdot = 0;
        for (const char *p = name; *p;) {
            const char *e = strchr(p, '/');
            size_t len = e ? (size_t)(e - p) : strlen(p);
            dotdot |= len == 2u && p[0] == '.' && p[1] == '.';
            p += len + (e ? 1u : 0u);
        }
        if (name[0] == '/' || dotdot || name[0] == 0) {
            return fail(err, errlen, SC_ERR_INVALID_ARG,
                        "%s: %s '%s': data files must lie beside the header (no absolute path, no "
                        "'..'; --allow-data-path permits it)",
                        header_path, field, name);
        }
    }
    const char *slash = strrchr(header_path, '/');
    int w;
    if (name[0] == '/' || slash == NULL) {
        w = snprintf(out, n, "%s", name);
    } else {
        w = snprintf(out, n, "%.*s/%s", (int)(slash - header_path), header_path, name);
    }
    if (w < 0 || (size_t)w >= n) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "%s: %s: path too long", header_path, field);
    }
    return SC_OK;
}

static size_t elem_size(sc_elem_type t)
{
    switch (t) {
    case SC_ELEM_U8:
    case SC_ELEM_I8:
        return 1;
    case SC_ELEM_U16:
    case SC_ELEM_I16:
        return 2;
    case SC_ELEM_U32:
    case SC_ELEM_I32:
    case SC_ELEM_F32:
        return 4;
    case SC_ELEM_F64:
    default:
        return 8;
    }
}

/* Decode n elements of binary data (either byte order) into doubles. */
static void decode_binary(const uint8_t *src, size_t n, sc_elem_type t, int big_endian, double *dst)
{
    const size_t es = elem_size(t);
    uint8_t b[8];
    for (size_t i = 0; i < n; i++) {
        const uint8_t *p = src + i * es;
        for (size_t k = 0; k < es; k++) {
            b[k] = big_endian ? p[es - 1u - k] : p[k]; /* b is little-endian */
        }
        uint64_t u = 0;
        for (size_t k = es; k-- > 0;) {
            u = (u << 8) | b[k];
        }
        switch (t) {
        case SC_ELEM_U8:
            dst[i] = (double)(uint8_t)u;
            break;
        case SC_ELEM_I8:
            dst[i] = (double)(int8_t)(uint8_t)u;
            break;
        case SC_ELEM_U16:
            dst[i] = (double)(uint16_t)u;
            break;
        case SC_ELEM_I16:
            dst[i] = (double)(int16_t)(uint16_t)u;
            break;
        case SC_ELEM_U32:
            dst[i] = (double)(uint32_t)u;
            break;
        case SC_ELEM_I32:
            dst[i] = (double)(int32_t)(uint32_t)u;
            break;
        case SC_ELEM_F32: {
            uint32_t w = (uint32_t)u;
            float f;
            memcpy(&f, &w, sizeof f);
            dst[i] = (double)f;
            break;
        }
        case SC_ELEM_F64:
        default: {
            double d;
            memcpy(&d, &u, sizeof d);
            dst[i] = d;
            break;
        }
        }
    }
}

/* Inflate a zlib or gzip stream (auto-detected) into exactly want bytes. */
static int inflate_exact(const uint8_t *src, size_t srclen, uint8_t *dst, size_t want, char *err,
                         size_t errlen)
{
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (inflateInit2(&zs, 15 + 32) != Z_OK) {
        return fail(err, errlen, SC_ERR_IO, "zlib init failed");
    }
    zs.next_in = (Bytef *)(uintptr_t)src;
    zs.next_out = dst;
    size_t in_left = srclen, out_left = want;
    int zr = Z_OK;
    while (out_left > 0u && zr != Z_STREAM_END) {
        uInt in_chunk = in_left > 0x40000000u ? 0x40000000u : (uInt)in_left;
        uInt out_chunk = out_left > 0x40000000u ? 0x40000000u : (uInt)out_left;
        zs.avail_in = in_chunk;
        zs.avail_out = out_chunk;
        zr = inflate(&zs, Z_NO_FLUSH);
        in_left -= in_chunk - zs.avail_in;
        out_left -= out_chunk - zs.avail_out;
        if (zr == Z_STREAM_END && out_left > 0u && in_left > 0u) {
            /* concatenated gzip members (e.g. from pigz): continue */
            if (inflateReset(&zs) != Z_OK) {
                break;
            }
            zr = Z_OK;
            continue;
        }
        if (zr != Z_OK && zr != Z_STREAM_END) {
            break;
        }
        if (in_chunk == 0u && zr != Z_STREAM_END) {
            break;
        }
    }
    inflateEnd(&zs);
    if (out_left != 0u) {
        return fail(err, errlen, SC_ERR_PARSE,
                    "compressed data inflates to %zu of %zu bytes (zlib %d)", want - out_left, want,
                    zr);
    }
    return SC_OK;
}

static int parse_numbers(const char *s, double *v, int max);

static int set_dims(sc_image *img, const long long d[3], int nd, uint64_t max_voxels,
                    const char *what, char *err, size_t errlen)
{
    for (int a = 0; a < 3; a++) {
        long long v = a < nd ? d[a] : 1;
        if (v < 1 || v > (long long)SC_MAX_VOLUME_DIM) {
            return fail(err, errlen, SC_ERR_CASE_DIMS, "%s: axis %d = %lld outside 1..%u", what, a,
                        v, SC_MAX_VOLUME_DIM);
        }
        img->dim[a] = (uint32_t)v;
    }
    const uint64_t n = (uint64_t)img->dim[0] * img->dim[1] * img->dim[2]; /* < 2^30 */
    const uint64_t cap = max_voxels < SC_MAX_VOLUME_VOXELS ? max_voxels : SC_MAX_VOLUME_VOXELS;
    if (n > cap) {
        return fail(err, errlen, SC_ERR_CASE_DIMS,
                    "%s: %llu voxels, above the ceiling of %llu (--max-voxels, at most %u)", what,
                    (unsigned long long)n, (unsigned long long)cap, SC_MAX_VOLUME_VOXELS);
    }
    return SC_OK;
}

/* Dimensions from a header field: each a whole number 1..SC_MAX_VOLUME_DIM, checked as a
 * double before any conversion (DimSize = 1e300 must not reach an integer cast). */
static int parse_dims(const char *path, const char *field, const char *val, long long d[3],
                      char *err, size_t errlen)
{
    double v[4];
    const int n = parse_numbers(val, v, 4);
    if (n < 1 || n > 3) {
        return fail(err, errlen, SC_ERR_PARSE, "%s: %s '%s': 1 to 3 sizes", path, field, val);
    }
    for (int a = 0; a < n; a++) {
        if (!(v[a] >= 1.0 && v[a] <= (double)SC_MAX_VOLUME_DIM) || v[a] > floor(v[a])) {
            return fail(err, errlen, SC_ERR_CASE_DIMS, "%s: %s: size %.6g is not a whole number "
                        "in 1..%u", path, field, v[a], SC_MAX_VOLUME_DIM);
        }
        d[a] = (long long)v[a];
    }
    return SC_OK;
}

/* A whole header number in [lo, hi]. */
static int parse_int_field(const char *path, const char *field, const char *val, long long lo,
                           long long hi, long long *out, char *err, size_t errlen)
{
    char *end;
    errno = 0;
    const long long v = strtoll(val, &end, 10);
    if (errno || end == val || *end || v < lo || v > hi) {
        return fail(err, errlen, SC_ERR_PARSE, "%s: %s '%s': a whole number in %lld..%lld", path,
                    field, val, lo, hi);
    }
    *out = v;
    return SC_OK;
}

static void image_init(sc_image *img)
{
    memset(img, 0, sizeof *img);
    for (int a = 0; a < 3; a++) {
        img->spacing[a] = 1.0;
        img->dir[a * 3 + a] = 1.0;
        img->lps[a * 3 + a] = 1.0;
    }
}

#ifndef SC_HAVE_TEEM
/* NRRD "space": anatomical worlds are converted to LPS (DICOM's and ITK's), so that a volume
 * and a label map from different tools meet in one patient frame: to_lps holds the sign of
 * each world axis. 1 anatomical, 0 a non-anatomical space, -1 unknown or not a 3D space. */
static int nrrd_space(const char *v, sc_image *img, double to_lps[3])
{
    static const struct {
        const char *name, *abbr;
        double sx, sy;
    } m[] = {{"right-anterior-superior", "RAS", -1.0, -1.0},
             {"left-anterior-superior", "LAS", 1.0, -1.0},
             {"left-posterior-superior", "LPS", 1.0, 1.0}};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) {
        if (strcasecmp(v, m[i].name) == 0 || strcasecmp(v, m[i].abbr) == 0) {
            to_lps[0] = m[i].sx;
            to_lps[1] = m[i].sy;
            to_lps[2] = 1.0;
            img->anatomical = 1;
            return 1;
        }
    }
    if (strcasecmp(v, "scanner-xyz") == 0 || strcasecmp(v, "3D-right-handed") == 0 ||
        strcasecmp(v, "3D-left-handed") == 0) {
        return 0;
    }
    return -1;
}
#endif

/* MetaImage AnatomicalOrientation (ITK's convention: each letter names the side grid axis a
 * comes from, "RAI" = x toward Left, y toward Posterior, z toward Superior, the identity in
 * ITK's LPS world). Fills dir (columns) from it; 0 ok, -1 malformed. */
static int met_orientation(const char *v, double dir[9])
{
    if (strlen(v) != 3u) {
        return -1;
    }
    int used = 0;
    for (int a = 0; a < 3; a++) {
        static const char from[] = "RLAPIS"; /* from R: toward +x (L), from L: toward -x ... */
        const char *hit = strchr(from, toupper((unsigned char)v[a]));
        if (hit == NULL || v[a] == 0) {
            return -1;
        }
        int k = (int)(hit - from), world = k / 2;
        if (used & (1 << world)) {
            return -1;
        }
        used |= 1 << world;
        for (int r = 0; r < 3; r++) {
            dir[r * 3 + a] = r == world ? (k % 2 == 0 ? 1.0 : -1.0) : 0.0;
        }
    }
    return 0;
}

static size_t image_count(const sc_image *img)
{
    return (size_t)img->dim[0] * img->dim[1] * img->dim[2];
}

static char *trim(char *s)
{
    while (*s && isspace((unsigned char)*s)) {
        s++;
    }
    char *e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1])) {
        *--e = 0;
    }
    return s;
}

/* parse up to max doubles separated by spaces, commas or parentheses; returns the count */
static int parse_numbers(const char *s, double *v, int max)
{
    int n = 0;
    while (*s && n < max) {
        while (*s && (isspace((unsigned char)*s) || *s == ',' || *s == '(' || *s == ')')) {
            s++;
        }
        if (!*s) {
            break;
        }
        char *end;
        double d = strtod(s, &end);
        if (end == s) {
            return -1;
        }
        v[n++] = d;
        s = end;
    }
    while (*s && (isspace((unsigned char)*s) || *s == ',' || *s == '(' || *s == ')')) {
        s++;
    }
    return *s ? -1 : n;
}

/* ---- MetaImage ---------------------------------------------------------------------------- */
static int met_type(const char *s, sc_elem_type *t)
{
    static const struct {
        const char *name;
        sc_elem_type t;
    } m[] = {{"MET_UCHAR", SC_ELEM_U8},  {"MET_CHAR", SC_ELEM_I8},   {"MET_USHORT", SC_ELEM_U16},
             {"MET_SHORT", SC_ELEM_I16}, {"MET_UINT", SC_ELEM_U32},  {"MET_INT", SC_ELEM_I32},
             {"MET_FLOAT", SC_ELEM_F32}, {"MET_DOUBLE", SC_ELEM_F64}};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) {
        if (strcasecmp(s, m[i].name) == 0) {
            *t = m[i].t;
            return 0;
        }
    }
    return -1;
}

static int is_true(const char *s)
{
    return strcasecmp(s, "true") == 0 || strcmp(s, "1") == 0;
}

static int read_metaimage(const char *path, const sc_read_limits *lim, sc_image *img, char *err,
                          size_t errlen)
{
    uint8_t *file;
    size_t fsize;
    const uint64_t max_bytes = lim->max_voxels * 8u + (1u << 20);
    int rc = read_file(path, max_bytes, &file, &fsize, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    int ndims = 0, have_type = 0, compressed = 0, big = 0, channels = 1, have_spacing = 0;
    int have_matrix = 0, have_anat = 0, is_sequence = 0;
    double anat_dir[9];
    long long dsz[3] = {1, 1, 1};
    long long header_size = 0, comp_size = -1;
    char datafile[1024] = "";
    size_t pos = 0, data_off = 0;
    int found_data = 0;
    while (pos < fsize && !found_data) {
        size_t eol = pos;
        while (eol < fsize && file[eol] != '\n') {
            eol++;
        }
        size_t len = eol - pos;
        char line[2048];
        if (len >= sizeof line) {
            free(file);
            return fail(err, errlen, SC_ERR_PARSE, "%s: header line too long", path);
        }
        memcpy(line, file + pos, len);
        line[len] = 0;
        pos = eol < fsize ? eol + 1u : eol;
        char *eq = strchr(line, '=');
        if (eq == NULL) {
            if (trim(line)[0] == 0) {
                continue;
            }
            free(file);
            return fail(err, errlen, SC_ERR_PARSE, "%s: not a MetaImage header line: %s", path,
                        line);
        }
        *eq = 0;
        char *key = trim(line), *val = trim(eq + 1);
        double v[9];
        long long iv = 0;
        if (strcasecmp(key, "NDims") == 0) {
            rc = parse_int_field(path, "NDims", val, 2, 3, &iv, err, errlen);
            ndims = (int)iv;
        } else if (strcasecmp(key, "DimSize") == 0) {
            rc = parse_dims(path, "DimSize", val, dsz, err, errlen);
        } else if (strcasecmp(key, "ElementSpacing") == 0 ||
                   (strcasecmp(key, "ElementSize") == 0 && !have_spacing)) {
            /* ElementSpacing wins over ElementSize (voxel extent) when both are given */
            have_spacing = strcasecmp(key, "ElementSpacing") == 0;
            int n = parse_numbers(val, v, 3);
            if (n < 1) {
                rc = fail(err, errlen, SC_ERR_PARSE, "%s: %s '%s': 1 to 3 numbers", path, key, val);
            }
            for (int a = 0; a < n; a++) {
                img->spacing[a] = v[a];
            }
        } else if (strcasecmp(key, "Offset") == 0 || strcasecmp(key, "Origin") == 0 ||
                   strcasecmp(key, "Position") == 0) {
            int n = parse_numbers(val, v, 3);
            if (n < 1) {
                rc = fail(err, errlen, SC_ERR_PARSE, "%s: %s '%s': 1 to 3 numbers", path, key, val);
            }
            for (int a = 0; a < n; a++) {
                img->origin[a] = v[a];
            }
        } else if (strcasecmp(key, "TransformMatrix") == 0 || strcasecmp(key, "Rotation") == 0 ||
                   strcasecmp(key, "Orientation") == 0) {
            /* MetaIO stores the matrix column by column: the first 3 values are the
             * direction of the first axis */
            int n = parse_numbers(val, v, 9);
            have_matrix = 1;
            if (n == 9) {
                for (int a = 0; a < 3; a++) {
                    for (int r = 0; r < 3; r++) {
                        img->dir[r * 3 + a] = v[a * 3 + r];
                    }
                }
            } else if (n == 4 && ndims == 2) {
                img->dir[0] = v[0];
                img->dir[3] = v[1];
                img->dir[1] = v[2];
                img->dir[4] = v[3];
            } else {
                rc = fail(err, errlen, SC_ERR_PARSE, "%s: %s: 9 numbers (4 for NDims = 2)", path,
                          key);
            }
        } else if (strcasecmp(key, "ElementType") == 0) {
            if (met_type(val, &img->type) != 0) {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: element type %s", path, val);
            }
            have_type = 1;
        } else if (strcasecmp(key, "ElementNumberOfChannels") == 0) {
            rc = parse_int_field(path, "ElementNumberOfChannels", val, 1, 1, &iv, err, errlen);
            channels = (int)iv;
        } else if (strcasecmp(key, "BinaryDataByteOrderMSB") == 0 ||
                   strcasecmp(key, "ElementByteOrderMSB") == 0) {
            big = is_true(val);
        } else if (strcasecmp(key, "CompressedData") == 0) {
            compressed = is_true(val);
        } else if (strcasecmp(key, "CompressedDataSize") == 0) {
            rc = parse_int_field(path, "CompressedDataSize", val, 0, 1LL << 40, &comp_size, err,
                                 errlen);
        } else if (strcasecmp(key, "HeaderSize") == 0) {
            rc = parse_int_field(path, "HeaderSize", val, -1, 1LL << 40, &header_size, err, errlen);
        } else if (strcasecmp(key, "BinaryData") == 0) {
            if (!is_true(val)) {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: ASCII MetaImage data", path);
            }
        } else if (strncasecmp(key, "Seq_Frame", 9) == 0 ||
                   strcasecmp(key, "UltrasoundImageOrientation") == 0) {
            is_sequence = 1;
        } else if (strcasecmp(key, "ElementDataFile") == 0) {
            snprintf(datafile, sizeof datafile, "%s", val);
            data_off = pos;
            found_data = 1;
        } else if (strcasecmp(key, "AnatomicalOrientation") == 0) {
            /* "???" (unknown) is what ITK writes for a non-anatomical image */
            if (strcmp(val, "???") != 0) {
                if (met_orientation(val, anat_dir) != 0) {
                    free(file);
                    return fail(err, errlen, SC_ERR_PARSE,
                                "%s: AnatomicalOrientation '%s' is not three of R/L, A/P, I/S",
                                path, val);
                }
                have_anat = 1;
            }
        } /* other keys (ObjectType, patient fields...): ignored */
        if (rc != SC_OK) {
            free(file);
            return rc;
        }
    }
    if (!found_data || !have_type || (ndims != 2 && ndims != 3)) {
        free(file);
        return fail(err, errlen, SC_ERR_PARSE,
                    "%s: MetaImage needs NDims 2 or 3, ElementType, ElementDataFile", path);
    }
    if (is_sequence && !lim->allow_sequence) {
        free(file);
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                    "%s: a tracked 2D sequence (PLUS Seq_Frame fields: frames with per-frame "
                    "transforms), not a volume; build the volume with `sc-casebuild reconstruct "
                    "--sequence %s ...`",
                    path, path);
    }
    if (have_anat) {
        /* ITK's world is LPS; the matrix, when given, is the geometry (as ITK reads it) */
        img->anatomical = 1;
        if (!have_matrix && ndims == 3) {
            memcpy(img->dir, anat_dir, sizeof anat_dir);
        }
    }
    if (channels != 1) {
        free(file);
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: %d channels (1 supported)", path,
                    channels);
    }
    char what[1100];
    snprintf(what, sizeof what, "%s: DimSize", path);
    rc = set_dims(img, dsz, ndims, lim->max_voxels, what, err, errlen);
    if (rc != SC_OK) {
        free(file);
        return rc;
    }
    const size_t n = image_count(img), raw_bytes = n * elem_size(img->type);
    const uint8_t *src;
    size_t srclen;
    uint8_t *other = NULL;
    if (strcasecmp(datafile, "LOCAL") == 0) {
        src = file + data_off;
        srclen = fsize - data_off;
    } else if (strcasecmp(datafile, "LIST") == 0 || strchr(datafile, '%') != NULL) {
        free(file);
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: slice-list data files", path);
    } else {
        char dp[2048];
        size_t olen;
        rc = sibling_path(dp, sizeof dp, path, "ElementDataFile", datafile, lim->allow_data_path,
                          err, errlen);
        if (rc == SC_OK) {
            rc = read_file(dp, max_bytes, &other, &olen, err, errlen);
        }
        if (rc != SC_OK) {
            free(file);
            return rc;
        }
        src = other;
        srclen = olen;
        if (!compressed) {
            if (header_size == -1) {
                header_size = olen >= raw_bytes ? (long long)(olen - raw_bytes) : 0;
            }
            if (header_size < 0 || (size_t)header_size > olen) {
                free(file);
                free(other);
                return fail(err, errlen, SC_ERR_PARSE, "%s: HeaderSize beyond the data", path);
            }
            src += header_size;
            srclen -= (size_t)header_size;
        }
    }
    img->data = malloc(n * sizeof(double));
    uint8_t *raw = compressed ? malloc(raw_bytes) : NULL;
    if (img->data == NULL || (compressed && raw == NULL)) {
        free(file);
        free(other);
        free(raw);
        free(img->data);
        img->data = NULL;
        return fail(err, errlen, SC_ERR_NO_SPACE, "out of memory");
    }
    if (compressed) {
        size_t clen = comp_size > 0 && (size_t)comp_size <= srclen ? (size_t)comp_size : srclen;
        rc = inflate_exact(src, clen, raw, raw_bytes, err, errlen);
        src = raw;
        srclen = raw_bytes;
    } else if (srclen < raw_bytes) {
        rc = fail(err, errlen, SC_ERR_PARSE, "%s: %zu data bytes, %zu expected", path, srclen,
                  raw_bytes);
    }
    if (rc == SC_OK) {
        decode_binary(src, n, img->type, big, img->data);
    } else {
        free(img->data);
        img->data = NULL;
    }
    free(raw);
    free(other);
    free(file);
    return rc;
}

#ifndef SC_HAVE_TEEM /* the built-in NRRD reader, when libteem-dev is absent */
/* ---- NRRD --------------------------------------------------------------------------------- */
static int nrrd_type(const char *s, sc_elem_type *t)
{
    static const struct {
        const char *name;
        sc_elem_type t;
    } m[] = {{"signed char", SC_ELEM_I8},
             {"int8", SC_ELEM_I8},
             {"int8_t", SC_ELEM_I8},
             {"uchar", SC_ELEM_U8},
             {"unsigned char", SC_ELEM_U8},
             {"uint8", SC_ELEM_U8},
             {"uint8_t", SC_ELEM_U8},
             {"short", SC_ELEM_I16},
             {"short int", SC_ELEM_I16},
             {"signed short", SC_ELEM_I16},
             {"signed short int", SC_ELEM_I16},
             {"int16", SC_ELEM_I16},
             {"int16_t", SC_ELEM_I16},
             {"ushort", SC_ELEM_U16},
             {"unsigned short", SC_ELEM_U16},
             {"unsigned short int", SC_ELEM_U16},
             {"uint16", SC_ELEM_U16},
             {"uint16_t", SC_ELEM_U16},
             {"int", SC_ELEM_I32},
             {"signed int", SC_ELEM_I32},
             {"int32", SC_ELEM_I32},
             {"int32_t", SC_ELEM_I32},
             {"uint", SC_ELEM_U32},
             {"unsigned int", SC_ELEM_U32},
             {"uint32", SC_ELEM_U32},
             {"uint32_t", SC_ELEM_U32},
             {"float", SC_ELEM_F32},
             {"double", SC_ELEM_F64}};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) {
        if (strcasecmp(s, m[i].name) == 0) {
            *t = m[i].t;
            return 0;
        }
    }
    return -1;
}

enum { ENC_RAW, ENC_GZIP, ENC_ASCII };

static int read_nrrd_own(const char *path, const sc_read_limits *lim, sc_image *img, char *err,
                         size_t errlen)
{
    uint8_t *file;
    size_t fsize;
    const uint64_t max_bytes = lim->max_voxels * 8u + (1u << 20);
    int rc = read_file(path, max_bytes, &file, &fsize, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    if (fsize < 8u || memcmp(file, "NRRD000", 7) != 0) {
        free(file);
        return fail(err, errlen, SC_ERR_PARSE, "%s: no NRRD magic", path);
    }
    int ndims = 0, have_type = 0, enc = ENC_RAW, big = 0, have_dirs = 0;
    double to_lps[3] = {1.0, 1.0, 1.0};
    long long dsz[3] = {1, 1, 1};
    long long byte_skip = 0, line_skip = 0;
    char datafile[1024] = "";
    size_t pos = 0;
    int first = 1, header_done = 0;
    while (pos < fsize) {
        size_t eol = pos;
        while (eol < fsize && file[eol] != '\n') {
            eol++;
        }
        size_t len = eol - pos;
        char line[2048];
        if (len >= sizeof line) {
            free(file);
            return fail(err, errlen, SC_ERR_PARSE, "%s: header line too long", path);
        }
        memcpy(line, file + pos, len);
        line[len] = 0;
        pos = eol < fsize ? eol + 1u : eol;
        if (len > 0u && line[len - 1u] == '\r') {
            line[len - 1u] = 0;
        }
        if (first) {
            first = 0;
            continue;
        }
        if (line[0] == 0) {
            header_done = 1;
            break; /* blank line: data follows (attached) */
        }
        if (line[0] == '#' || strstr(line, ":=") != NULL) {
            continue; /* comment or key/value pair: ignored by design */
        }
        char *colon = strstr(line, ": ");
        if (colon == NULL) {
            free(file);
            return fail(err, errlen, SC_ERR_PARSE, "%s: bad NRRD field line: %s", path, line);
        }
        *colon = 0;
        char *key = trim(line), *val = trim(colon + 2);
        double v[9];
        long long iv = 0;
        if (strcasecmp(key, "type") == 0) {
            if (nrrd_type(val, &img->type) != 0) {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: type %s", path, val);
            }
            have_type = 1;
        } else if (strcasecmp(key, "dimension") == 0) {
            rc = parse_int_field(path, "dimension", val, 2, 3, &iv, err, errlen);
            ndims = (int)iv;
        } else if (strcasecmp(key, "sizes") == 0) {
            rc = parse_dims(path, "sizes", val, dsz, err, errlen);
        } else if (strcasecmp(key, "spacings") == 0 && !have_dirs) {
            int n = parse_numbers(val, v, 3);
            if (n < 1) {
                rc = fail(err, errlen, SC_ERR_PARSE, "%s: spacings '%s': 1 to 3 numbers", path,
                          val);
            }
            for (int a = 0; a < n; a++) {
                img->spacing[a] = v[a];
            }
        } else if (strcasecmp(key, "space directions") == 0) {
            if (strstr(val, "none") != NULL) {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                            "%s: non-spatial axes (multi-component data)", path);
            }
            int n = parse_numbers(val, v, 9);
            if (n != 9) {
                free(file);
                return fail(err, errlen, SC_ERR_PARSE, "%s: space directions need 3 vectors", path);
            }
            for (int a = 0; a < 3; a++) {
                double nrm = sqrt(v[a * 3] * v[a * 3] + v[a * 3 + 1] * v[a * 3 + 1] +
                                  v[a * 3 + 2] * v[a * 3 + 2]);
                img->spacing[a] = nrm;
                for (int r = 0; r < 3; r++) {
                    img->dir[r * 3 + a] = nrm > 0.0 ? v[a * 3 + r] / nrm : 0.0;
                }
            }
            have_dirs = 1;
        } else if (strcasecmp(key, "space") == 0) {
            if (nrrd_space(val, img, to_lps) < 0) {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                            "%s: space '%s' (RAS, LAS, LPS, scanner-xyz, 3D-right-handed, "
                            "3D-left-handed)",
                            path, val);
            }
        } else if (strcasecmp(key, "space origin") == 0) {
            int n = parse_numbers(val, v, 3);
            if (n != 3) {
                rc = fail(err, errlen, SC_ERR_PARSE, "%s: space origin '%s': a 3-vector", path,
                          val);
            }
            for (int a = 0; a < n; a++) {
                img->origin[a] = v[a];
            }
        } else if (strcasecmp(key, "encoding") == 0) {
            if (strcasecmp(val, "raw") == 0) {
                enc = ENC_RAW;
            } else if (strcasecmp(val, "gzip") == 0 || strcasecmp(val, "gz") == 0) {
                enc = ENC_GZIP;
            } else if (strcasecmp(val, "ascii") == 0 || strcasecmp(val, "text") == 0 ||
                       strcasecmp(val, "txt") == 0) {
                enc = ENC_ASCII;
            } else {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: encoding %s", path, val);
            }
        } else if (strcasecmp(key, "endian") == 0) {
            big = strcasecmp(val, "big") == 0;
        } else if (strcasecmp(key, "byte skip") == 0 || strcasecmp(key, "byteskip") == 0) {
            rc = parse_int_field(path, "byte skip", val, -1, 1LL << 40, &byte_skip, err, errlen);
        } else if (strcasecmp(key, "line skip") == 0 || strcasecmp(key, "lineskip") == 0) {
            rc = parse_int_field(path, "line skip", val, 0, 1LL << 31, &line_skip, err, errlen);
        } else if (strcasecmp(key, "data file") == 0 || strcasecmp(key, "datafile") == 0) {
            if (strncasecmp(val, "LIST", 4) == 0 || strchr(val, ' ') != NULL) {
                free(file);
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: multi-file data", path);
            }
            snprintf(datafile, sizeof datafile, "%s", val);
        } /* space, kinds, centerings, units, content...: geometry already covered */
        if (rc != SC_OK) {
            free(file);
            return rc;
        }
    }
    if (!have_type || (ndims != 2 && ndims != 3)) {
        free(file);
        return fail(err, errlen, SC_ERR_PARSE, "%s: NRRD needs type and dimension 2 or 3", path);
    }
    for (int r = 0; r < 3; r++) {
        img->origin[r] *= to_lps[r];
        for (int a = 0; a < 3; a++) {
            img->dir[r * 3 + a] *= to_lps[r];
        }
    }
    char what[1100];
    snprintf(what, sizeof what, "%s: sizes", path);
    rc = set_dims(img, dsz, ndims, lim->max_voxels, what, err, errlen);
    if (rc != SC_OK) {
        free(file);
        return rc;
    }
    const uint8_t *src;
    size_t srclen;
    uint8_t *other = NULL;
    if (datafile[0] != 0) {
        char dp[2048];
        rc = sibling_path(dp, sizeof dp, path, "data file", datafile, lim->allow_data_path, err,
                          errlen);
        if (rc == SC_OK) {
            rc = read_file(dp, max_bytes, &other, &srclen, err, errlen);
        }
        if (rc != SC_OK) {
            free(file);
            return rc;
        }
        src = other;
    } else {
        if (!header_done) {
            free(file);
            return fail(err, errlen, SC_ERR_PARSE, "%s: no data after the header", path);
        }
        src = file + pos;
        srclen = fsize - pos;
    }
    for (long long l = 0; l < line_skip; l++) {
        const uint8_t *nl = memchr(src, '\n', srclen);
        if (nl == NULL) {
            srclen = 0;
            break;
        }
        srclen -= (size_t)(nl + 1 - src);
        src = nl + 1;
    }
    const size_t n = image_count(img), raw_bytes = n * elem_size(img->type);
    if (enc == ENC_RAW) {
        if (byte_skip == -1) {
            byte_skip = srclen >= raw_bytes ? (long long)(srclen - raw_bytes) : 0;
        }
    }
    if (byte_skip < 0 || (size_t)byte_skip > srclen) {
        free(file);
        free(other);
        return fail(err, errlen, SC_ERR_PARSE, "%s: byte skip beyond the data", path);
    }
    if (enc != ENC_GZIP) {
        src += byte_skip;
        srclen -= (size_t)byte_skip;
    }
    img->data = malloc(n * sizeof(double));
    uint8_t *raw = enc == ENC_GZIP ? malloc(raw_bytes) : NULL;
    if (img->data == NULL || (enc == ENC_GZIP && raw == NULL)) {
        free(file);
        free(other);
        free(raw);
        free(img->data);
        img->data = NULL;
        return fail(err, errlen, SC_ERR_NO_SPACE, "out of memory");
    }
    if (enc == ENC_GZIP && (uint64_t)byte_skip > max_bytes) {
        free(file);
        free(other);
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: byte skip %lld above the ceiling", path,
                    byte_skip);
    }
    if (enc == ENC_GZIP) {
        /* byte skip applies to the decompressed data (NRRD spec) */
        size_t skip = (size_t)byte_skip;
        uint8_t *tmp = malloc(raw_bytes + skip);
        rc = tmp == NULL ? SC_ERR_NO_SPACE
                         : inflate_exact(src, srclen, tmp, raw_bytes + skip, err, errlen);
        if (rc == SC_OK) {
            memcpy(raw, tmp + skip, raw_bytes);
            decode_binary(raw, n, img->type, big, img->data);
        }
        free(tmp);
    } else if (enc == ENC_RAW) {
        if (srclen < raw_bytes) {
            rc = fail(err, errlen, SC_ERR_PARSE, "%s: %zu data bytes, %zu expected", path, srclen,
                      raw_bytes);
        } else {
            decode_binary(src, n, img->type, big, img->data);
        }
    } else {
        /* ascii: whitespace-separated numbers; src may not be NUL-terminated (detached) */
        char *txt = malloc(srclen + 1u);
        if (txt == NULL) {
            rc = SC_ERR_NO_SPACE;
        } else {
            memcpy(txt, src, srclen);
            txt[srclen] = 0;
            char *p = txt;
            for (size_t i = 0; i < n && rc == SC_OK; i++) {
                char *end;
                img->data[i] = strtod(p, &end);
                if (end == p) {
                    rc = fail(err, errlen, SC_ERR_PARSE, "%s: %zu ascii values, %zu expected", path,
                              i, n);
                }
                p = end;
                while (*p == ',' || isspace((unsigned char)*p)) {
                    p++;
                }
            }
            free(txt);
        }
    }
    if (rc != SC_OK) {
        free(img->data);
        img->data = NULL;
    }
    free(raw);
    free(other);
    free(file);
    return rc;
}

#endif /* !SC_HAVE_TEEM */

#ifdef SC_HAVE_TEEM
/* ---- NRRD through teem's libnrrd (the format's reference implementation) ------------------ */
#include <teem/biff.h>
#include <teem/nrrd.h>

/* libnrrd's error stack as one line (the innermost reason last), freed */
static int teem_fail(char *err, size_t errlen, int rc, const char *path)
{
    char *e = biffGetDone(NRRD);
    if (e != NULL) {
        for (char *p = e; *p; p++) {
            if (*p == '\n') {
                *p = ' ';
            }
        }
    }
    rc = fail(err, errlen, rc, "%s: libnrrd: %s", path, e ? e : "unreadable");
    free(e);
    return rc;
}

/* Before libnrrd opens anything: the magic, and each data file the header names obeys the
 * "beside the header" rule (libnrrd would open it even when asked for the header only). */
static int nrrd_precheck(const char *path, const sc_read_limits *lim, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(err, errlen, errno == ENOENT ? SC_ERR_NOT_FOUND : SC_ERR_IO, "%s: %s", path,
                    strerror(errno));
    }
    char line[2048], gz_file[2048] = "";
    int rc = SC_OK, first = 1, in_list = 0, gzip = 0, ended = 0;
    size_t total = 0;
    while (rc == SC_OK && fgets(line, sizeof line, f) != NULL) {
        total += strlen(line);
        if (total > (1u << 20)) {
            rc = fail(err, errlen, SC_ERR_PARSE, "%s: header longer than 1 MiB", path);
            break;
        }
        char *e = line + strlen(line);
        while (e > line && (e[-1] == '\n' || e[-1] == '\r')) {
            *--e = 0;
        }
        if (first) {
            first = 0;
            if (strncmp(line, "NRRD000", 7) != 0) {
                rc = fail(err, errlen, SC_ERR_PARSE, "%s: no NRRD magic", path);
            }
            continue;
        }
        if (line[0] == 0) {
            ended = 1;
            break; /* end of the header */
        }
        if (in_list) {
            rc = sibling_path(line, sizeof line, path, "data file LIST", trim(line),
                              lim->allow_data_path, err, errlen);
            continue;
        }
        char *colon = strstr(line, ": ");
        if (colon == NULL || line[0] == '#') {
            continue;
        }
        *colon = 0;
        const char *key = trim(line);
        if (strcasecmp(key, "encoding") == 0) {
            const char *v = trim(colon + 2);
            gzip = strcasecmp(v, "gzip") == 0 || strcasecmp(v, "gz") == 0;
            /* bzip2 is left out: libnrrd 1.12 leaks its decoder on a corrupt stream */
            if (!gzip && strcasecmp(v, "raw") != 0 && strcasecmp(v, "ascii") != 0 &&
                strcasecmp(v, "text") != 0 && strcasecmp(v, "txt") != 0 &&
                strcasecmp(v, "hex") != 0) {
                rc = fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                          "%s: encoding '%s' (raw, gzip, ascii, hex)", path, v);
            }
            continue;
        }
        if (strcasecmp(key, "sizes") == 0 || strcasecmp(key, "dimension") == 0 ||
            strcasecmp(key, "byte skip") == 0 || strcasecmp(key, "byteskip") == 0 ||
            strcasecmp(key, "line skip") == 0 || strcasecmp(key, "lineskip") == 0) {
            /* libnrrd reads "1e300" as 1 and "2.5" as 2: whole decimal numbers only (and the
             * byte skip -1), at most 12 digits, so nothing is silently misread */
            const char *v = trim(colon + 2);
            int digits = 0, ok = *v != 0;
            for (const char *q = v; *q && ok; q++) {
                if (isdigit((unsigned char)*q)) {
                    ok = ++digits <= 12;
                } else if (*q == ' ' || *q == '\t') {
                    digits = 0;
                } else {
                    ok = *q == '-' && q == v && strcmp(v, "-1") == 0;
                }
            }
            if (!ok) {
                rc = fail(err, errlen, *key == 's' ? SC_ERR_CASE_DIMS : SC_ERR_PARSE,
                          "%s: %s '%s': whole numbers", path, key, v);
            }
            continue;
        }
        if (strcasecmp(key, "data file") != 0 && strcasecmp(key, "datafile") != 0) {
            continue;
        }
        char *val = trim(colon + 2), dp[2048];
        if (strncasecmp(val, "LIST", 4) == 0) {
            in_list = 1;
        } else if (strchr(val, ' ') != NULL) {
            rc = fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                      "%s: data file '%s': numbered multi-file data", path, val);
        } else {
            rc = sibling_path(dp, sizeof dp, path, "data file", val, lim->allow_data_path, err,
                              errlen);
            snprintf(gz_file, sizeof gz_file, "%s", dp);
        }
    }
    /* zlib reads data that is not gzip "transparently" as raw bytes: a gzip encoding must be
     * a gzip stream (attached data right after the header; a single data file; any byte skip
     * applies to the decompressed data) */
    if (rc == SC_OK && gzip && !in_list && (ended || gz_file[0] != 0)) {
        FILE *g = gz_file[0] != 0 ? fopen(gz_file, "rb") : f;
        uint8_t m[2] = {0, 0};
        const int got = g != NULL && fread(m, 1, 2, g) == 2u;
        if (g != NULL && g != f) {
            fclose(g);
        }
        if (g != NULL && (!got || m[0] != 0x1fu || m[1] != 0x8bu)) {
            rc = fail(err, errlen, SC_ERR_PARSE,
                      "%s: encoding gzip, but the data is not a gzip stream", path);
        }
    }
    fclose(f);
    return rc;
}

static int teem_type(int t, sc_elem_type *out)
{
    switch (t) {
    case nrrdTypeChar:
        *out = SC_ELEM_I8;
        return 0;
    case nrrdTypeUChar:
        *out = SC_ELEM_U8;
        return 0;
    case nrrdTypeShort:
        *out = SC_ELEM_I16;
        return 0;
    case nrrdTypeUShort:
        *out = SC_ELEM_U16;
        return 0;
    case nrrdTypeInt:
        *out = SC_ELEM_I32;
        return 0;
    case nrrdTypeUInt:
        *out = SC_ELEM_U32;
        return 0;
    case nrrdTypeFloat:
        *out = SC_ELEM_F32;
        return 0;
    case nrrdTypeDouble:
        *out = SC_ELEM_F64;
        return 0;
    default:
        return -1;
    }
}

/* geometry of a header-only nrrd into img; SC_OK or a refusal */
static int teem_geometry(const Nrrd *n, const char *path, sc_image *img, char *err, size_t errlen)
{
    double to_lps[3] = {1.0, 1.0, 1.0};
    switch (n->space) {
    case nrrdSpaceRightAnteriorSuperior:
        to_lps[0] = to_lps[1] = -1.0;
        img->anatomical = 1;
        break;
    case nrrdSpaceLeftAnteriorSuperior:
        to_lps[1] = -1.0;
        img->anatomical = 1;
        break;
    case nrrdSpaceLeftPosteriorSuperior:
        img->anatomical = 1;
        break;
    case nrrdSpaceUnknown:
    case nrrdSpaceScannerXYZ:
    case nrrdSpace3DRightHanded:
    case nrrdSpace3DLeftHanded:
        break;
    default:
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: space: a time-varying space", path);
    }
    if (n->spaceDim != 0u && n->spaceDim != 3u) {
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: space dimension %u (3 supported)", path,
                    n->spaceDim);
    }
    for (unsigned a = 0; a < n->dim; a++) {
        const NrrdAxisInfo *ax = &n->axis[a];
        if (n->spaceDim == 3u) {
            const double *v = ax->spaceDirection;
            if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])) {
                return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                            "%s: space directions: axis %u is not spatial (multi-component data)",
                            path, a);
            }
            const double nrm = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            img->spacing[a] = nrm;
            for (int r = 0; r < 3; r++) {
                img->dir[r * 3 + (int)a] = nrm > 0.0 ? to_lps[r] * v[r] / nrm : 0.0;
            }
        } else if (!isnan(ax->spacing)) {
            img->spacing[a] = ax->spacing; /* checked for range by the caller */
        }
    }
    if (n->spaceDim == 3u) {
        for (int r = 0; r < 3; r++) {
            if (!isnan(n->spaceOrigin[r])) {
                img->origin[r] = to_lps[r] * n->spaceOrigin[r];
            }
        }
        if (n->dim == 2u) {
            /* a 2D image in 3D space: its normal completes the frame */
            const double *d = img->dir;
            img->dir[2] = d[3] * d[7] - d[6] * d[4];
            img->dir[5] = d[6] * d[1] - d[0] * d[7];
            img->dir[8] = d[0] * d[4] - d[3] * d[1];
        }
    }
    return SC_OK;
}

static int read_nrrd(const char *path, const sc_read_limits *lim, sc_image *img, char *err,
                     size_t errlen)
{
    int rc = nrrd_precheck(path, lim, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    nrrdStateVerboseIO = 0;
    /* 1: the header only (no data read or allocated): sizes against the ceiling first */
    Nrrd *n = nrrdNew();
    NrrdIoState *nio = nrrdIoStateNew();
    if (n == NULL || nio == NULL) {
        nrrdNuke(n);
        nrrdIoStateNix(nio);
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: out of memory", path);
    }
    nio->skipData = 1;
    if (nrrdLoad(n, path, nio) != 0) {
        nrrdIoStateNix(nio);
        nrrdNuke(n);
        return teem_fail(err, errlen, SC_ERR_PARSE, path);
    }
    nrrdIoStateNix(nio);
    long long d[3] = {1, 1, 1};
    if (n->dim != 2u && n->dim != 3u) {
        rc = fail(err, errlen, SC_ERR_PARSE, "%s: dimension %u (2 or 3 supported)", path, n->dim);
    } else if (teem_type(n->type, &img->type) != 0) {
        rc = fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: type %s", path,
                  airEnumStr(nrrdType, n->type));
    }
    for (unsigned a = 0; rc == SC_OK && a < n->dim; a++) {
        d[a] = n->axis[a].size > (size_t)SC_MAX_VOLUME_DIM ? (long long)SC_MAX_VOLUME_DIM + 1
                                                            : (long long)n->axis[a].size;
    }
    char what[1100];
    snprintf(what, sizeof what, "%s: sizes", path);
    if (rc == SC_OK) {
        rc = set_dims(img, d, (int)n->dim, lim->max_voxels, what, err, errlen);
    }
    if (rc == SC_OK) {
        rc = teem_geometry(n, path, img, err, errlen);
    }
    nrrdNuke(n);
    if (rc != SC_OK) {
        return rc;
    }
    /* 2: the data, now known to be within the ceiling */
    n = nrrdNew();
    if (n == NULL) {
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: out of memory", path);
    }
    if (nrrdLoad(n, path, NULL) != 0) {
        nrrdNuke(n);
        return teem_fail(err, errlen, SC_ERR_PARSE, path);
    }
    const size_t cnt = image_count(img);
    sc_elem_type t2;
    if (n->data == NULL || nrrdElementNumber(n) != cnt || teem_type(n->type, &t2) != 0 ||
        t2 != img->type) {
        nrrdNuke(n); /* the file changed between the two reads */
        return fail(err, errlen, SC_ERR_PARSE, "%s: header changed while reading", path);
    }
    img->data = malloc(cnt * sizeof(double));
    if (img->data == NULL) {
        nrrdNuke(n);
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: out of memory", path);
    }
    for (size_t i = 0; i < cnt; i++) {
        img->data[i] = nrrdDLookup[n->type](n->data, i);
    }
    nrrdNuke(n);
    return SC_OK;
}
#else
static int read_nrrd(const char *path, const sc_read_limits *lim, sc_image *img, char *err,
                     size_t errlen)
{
    return read_nrrd_own(path, lim, img, err, errlen);
}
#endif

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcasecmp(s + a - b, suffix) == 0;
}

sc_read_limits sc_read_default_limits(void)
{
    sc_read_limits l;
    l.max_voxels = SC_IMPORT_DEFAULT_MAX_VOXELS;
    l.allow_data_path = 0;
    l.allow_sequence = 0;
    return l;
}

int sc_image_read(const char *path, sc_image *img, char *err, size_t errlen)
{
    const sc_read_limits lim = sc_read_default_limits();
    return sc_image_read_ex(path, &lim, img, err, errlen);
}

int sc_image_read_ex(const char *path, const sc_read_limits *lim_in, sc_image *img, char *err,
                     size_t errlen)
{
    if (path == NULL || img == NULL) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "no path");
    }
    image_init(img);
    sc_read_limits lim = lim_in != NULL ? *lim_in : sc_read_default_limits();
    if (lim.max_voxels < 1u || lim.max_voxels > SC_MAX_VOLUME_VOXELS) {
        lim.max_voxels = SC_MAX_VOLUME_VOXELS;
    }
    int rc;
    struct stat st;
    const int is_dir = stat(path, &st) == 0 && S_ISDIR(st.st_mode);
    if (!is_dir && stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        return fail(err, errlen, SC_ERR_IO, "%s: not a regular file", path);
    }
    if (ends_with(path, ".mha") || ends_with(path, ".mhd")) {
        rc = read_metaimage(path, &lim, img, err, errlen);
    } else if (ends_with(path, ".nrrd") || ends_with(path, ".nhdr")) {
        rc = read_nrrd(path, &lim, img, err, errlen);
    } else if (is_dir || ends_with(path, ".dcm") || ends_with(path, ".dicom")) {
#ifdef SC_HAVE_DCMTK
        rc = sc_dicom_read(path, lim.max_voxels, img, err, errlen);
        if (rc == SC_OK) {
            long long d[3] = {img->dim[0], img->dim[1], img->dim[2]};
            rc = set_dims(img, d, 3, lim.max_voxels, path, err, errlen);
            if (rc != SC_OK) {
                sc_image_free(img);
                return rc;
            }
        }
#else
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                    "%s: DICOM support not built (install libdcmtk-dev and reconfigure)", path);
#endif
    } else {
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                    "%s: unknown format (.mha .mhd .nrrd .nhdr, .dcm or a DICOM series folder)",
                    path);
    }
    if (rc != SC_OK) {
        return rc;
    }
    for (int a = 0; a < 3; a++) {
        if (!isfinite(img->spacing[a]) || !(img->spacing[a] >= SC_IMPORT_MIN_SPACING_MM) ||
            !(img->spacing[a] <= SC_IMPORT_MAX_SPACING_MM)) {
            const double sp = img->spacing[a];
            sc_image_free(img);
            return fail(err, errlen, SC_ERR_CASE_SPACING,
                        "%s: spacing of axis %d is %g mm, not in %g..%g mm (ElementSpacing, "
                        "NRRD spacings / space directions, DICOM Pixel Spacing / slice positions)",
                        path, a, sp, SC_IMPORT_MIN_SPACING_MM, SC_IMPORT_MAX_SPACING_MM);
        }
        if (!isfinite(img->origin[a]) || fabs(img->origin[a]) > SC_IMPORT_MAX_ORIGIN_MM) {
            const double o = img->origin[a];
            sc_image_free(img);
            return fail(err, errlen, SC_ERR_CASE_TRANSFORM,
                        "%s: origin coordinate %d is %g mm, not within +-%g mm (Offset, NRRD space "
                        "origin, DICOM Image Position)",
                        path, a, o, SC_IMPORT_MAX_ORIGIN_MM);
        }
    }
    /* direction cosines must be orthonormal (either handedness) */
    const double *d = img->dir;
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            double dot = d[a] * d[b] + d[3 + a] * d[3 + b] + d[6 + a] * d[6 + b];
            if (!(fabs(dot - (a == b ? 1.0 : 0.0)) <= 1e-4)) {
                sc_image_free(img);
                return fail(err, errlen, SC_ERR_CASE_TRANSFORM,
                            "%s: direction cosines not orthonormal (TransformMatrix, NRRD space "
                            "directions, DICOM Image Orientation)",
                            path);
            }
        }
    }
    /* non-finite voxels (NaN, +-inf in float data) are refused: no rule could say what tissue
     * they are; the first one is named */
    const size_t n = image_count(img);
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(img->data[i])) {
            const uint32_t x = (uint32_t)(i % img->dim[0]);
            const uint32_t y = (uint32_t)(i / img->dim[0] % img->dim[1]);
            const uint32_t z = (uint32_t)(i / img->dim[0] / img->dim[1]);
            const double v = img->data[i];
            sc_image_free(img);
            return fail(err, errlen, SC_ERR_NOT_FINITE,
                        "%s: voxel (%u, %u, %u) is %g: non-finite values are refused", path, x, y,
                        z, v);
        }
    }
    return SC_OK;
}

void sc_image_free(sc_image *img)
{
    if (img != NULL) {
        free(img->data);
        img->data = NULL;
    }
}

/* ---- import into a case ----------------------------------------------------------------- */
sc_import_opts sc_import_default_opts(void)
{
    sc_import_opts o;
    memset(&o, 0, sizeof o);
    o.mesh_nodes[0] = 24u;
    o.mesh_nodes[1] = 12u;
    o.mesh_nodes[2] = 12u;
    o.limits = sc_read_default_limits();
    o.image_to_probe = sc_xform_identity();
    o.tracker_to_patient = sc_xform_identity();
    return o;
}

void sc_import_result_free(sc_import_result *r)
{
    if (r != NULL) {
        free(r->voxels);
        free(r->labels);
        r->voxels = NULL;
        r->labels = NULL;
    }
}

/* world point -> continuous source index */
static void world_to_index(const sc_image *img, const double p[3], double idx[3])
{
    double q[3] = {p[0] - img->origin[0], p[1] - img->origin[1], p[2] - img->origin[2]};
    for (int a = 0; a < 3; a++) {
        double s = img->dir[a] * q[0] + img->dir[3 + a] * q[1] + img->dir[6 + a] * q[2];
        idx[a] = s / img->spacing[a];
    }
}

static double sample_linear(const sc_image *img, const double idx[3])
{
    double f[3];
    long i0[3];
    for (int a = 0; a < 3; a++) {
        double c = idx[a];
        double hi = (double)(img->dim[a] - 1u);
        c = c < 0.0 ? 0.0 : (c > hi ? hi : c);
        i0[a] = (long)floor(c);
        if (i0[a] >= (long)img->dim[a] - 1) {
            i0[a] = (long)img->dim[a] - 1;
            f[a] = 0.0;
        } else {
            f[a] = c - (double)i0[a];
        }
    }
    double acc = 0.0;
    for (int c = 0; c < 8; c++) {
        long ii[3];
        double w = 1.0;
        for (int a = 0; a < 3; a++) {
            int up = (c >> a) & 1;
            ii[a] = i0[a] + (up && f[a] > 0.0 ? 1 : 0);
            w *= up ? f[a] : 1.0 - f[a];
        }
        if (w > 0.0) {
            acc += w * img->data[(size_t)ii[0] +
                                 img->dim[0] * ((size_t)ii[1] + (size_t)img->dim[1] * ii[2])];
        }
    }
    return acc;
}

static int sample_nearest(const sc_image *img, const double idx[3], double *v)
{
    long ii[3];
    for (int a = 0; a < 3; a++) {
        ii[a] = lround(idx[a]);
        if (ii[a] < 0 || ii[a] >= (long)img->dim[a]) {
            return 0;
        }
    }
    *v = img->data[(size_t)ii[0] + img->dim[0] * ((size_t)ii[1] + (size_t)img->dim[1] * ii[2])];
    return 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- case frame ------------------------------------------------------------------------ */
static const char *const k_label_names[] = {
#define IM_LBL_NAME_(name, value, text) [value] = text,
    SC_LABEL_LIST(IM_LBL_NAME_)
#undef IM_LBL_NAME_
};

/* World direction named by an axis option (see sc_import_opts.depth_axis). */
static int axis_spec_world(const sc_image *img, const char *path, const char *spec,
                           const char *opt, double w[3], char *err, size_t errlen)
{
    if ((spec[0] == '+' || spec[0] == '-') && spec[1] >= 'i' && spec[1] <= 'k' && !spec[2]) {
        const int a = spec[1] - 'i';
        const double sg = spec[0] == '-' ? -1.0 : 1.0;
        for (int r = 0; r < 3; r++) {
            w[r] = sg * img->dir[r * 3 + a];
        }
        return SC_OK;
    }
    static const struct {
        const char *letter, *word;
        int col;
        double sign;
    } an[] = {{"L", "left", 0, 1.0},      {"R", "right", 0, -1.0},   {"P", "posterior", 1, 1.0},
              {"A", "anterior", 1, -1.0}, {"S", "superior", 2, 1.0}, {"I", "inferior", 2, -1.0}};
    for (size_t i = 0; i < sizeof an / sizeof an[0]; i++) {
        if (strcmp(spec, an[i].letter) == 0 || strcasecmp(spec, an[i].word) == 0) {
            if (!img->anatomical) {
                return fail(err, errlen, SC_ERR_INVALID_ARG,
                            "%s: %s %s: the file states no patient frame (NRRD space, MetaImage "
                            "AnatomicalOrientation); name a grid axis (+i -i +j -j +k -k)",
                            path, opt, spec);
            }
            for (int r = 0; r < 3; r++) {
                w[r] = an[i].sign * img->lps[r * 3 + an[i].col];
            }
            return SC_OK;
        }
    }
    return fail(err, errlen, SC_ERR_INVALID_ARG,
                "%s '%s': a grid axis (+i -i +j -j +k -k) or a patient direction (L R A P S I)",
                opt, spec);
}

/* The grid axis (not `exclude`) closest to world direction w, and the sign along it. */
static void snap_axis(const sc_image *img, const double w[3], int exclude, int *axis, int *sign)
{
    double best = -1.0;
    for (int a = 0; a < 3; a++) {
        if (a == exclude) {
            continue;
        }
        double d = img->dir[a] * w[0] + img->dir[3 + a] * w[1] + img->dir[6 + a] * w[2];
        if (fabs(d) > best) {
            best = fabs(d);
            *axis = a;
            *sign = d < 0.0 ? -1 : 1;
        }
    }
}

/* Case frame: case axis c is sign[c] * grid axis axis[c]; C (row-major, columns = world
 * directions of the case axes) is right-handed whatever the grid's handedness. */
static int choose_frame(const sc_image *img, const sc_import_opts *o, int axis[3], int sign[3],
                        double C[9], char *err, size_t errlen)
{
    const char *path = o->volume_path;
    const char *dspec = o->depth_axis ? o->depth_axis : (img->anatomical ? "P" : "+k");
    double w[3];
    int rc = axis_spec_world(img, path, dspec, "--depth-axis", w, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    snap_axis(img, w, -1, &axis[2], &sign[2]);
    const char *lspec = o->lateral_axis;
    if (lspec == NULL) {
        lspec = img->anatomical ? "R" : (axis[2] == 0 ? "+j" : "+i");
    }
    rc = axis_spec_world(img, path, lspec, "--lateral-axis", w, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    int la = 0, ls = 1; /* set on every path below; GCC 12 -O3 cannot see it */
    snap_axis(img, w, -1, &la, &ls);
    if (la == axis[2]) {
        if (o->lateral_axis != NULL) {
            return fail(err, errlen, SC_ERR_INVALID_ARG,
                        "--lateral-axis %s lies along the depth axis (%s)", o->lateral_axis,
                        dspec);
        }
        snap_axis(img, w, axis[2], &la, &ls); /* oblique default: the next closest axis */
    }
    axis[0] = la;
    sign[0] = ls;
    axis[1] = 3 - axis[0] - axis[2];
    /* y = z x x */
    double zx[3], xx[3], cy[3];
    for (int r = 0; r < 3; r++) {
        zx[r] = sign[2] * img->dir[r * 3 + axis[2]];
        xx[r] = sign[0] * img->dir[r * 3 + axis[0]];
    }
    cy[0] = zx[1] * xx[2] - zx[2] * xx[1];
    cy[1] = zx[2] * xx[0] - zx[0] * xx[2];
    cy[2] = zx[0] * xx[1] - zx[1] * xx[0];
    double d = cy[0] * img->dir[axis[1]] + cy[1] * img->dir[3 + axis[1]] +
               cy[2] * img->dir[6 + axis[1]];
    sign[1] = d < 0.0 ? -1 : 1;
    for (int c = 0; c < 3; c++) {
        for (int r = 0; r < 3; r++) {
            C[r * 3 + c] = sign[c] * img->dir[r * 3 + axis[c]];
        }
    }
    return SC_OK;
}

/* ---- label map ---------------------------------------------------------------------------- */
static int label_from_name(const char *s, size_t n)
{
    for (int l = 0; l < (int)SC_LABEL_COUNT; l++) {
        if (strlen(k_label_names[l]) == n && strncasecmp(k_label_names[l], s, n) == 0) {
            return l;
        }
    }
    return -1;
}

/* map[v] = project label of source value v, -1 unmapped; map[256] = the "*" entry or -1 */
static int parse_label_map(const char *spec, int map[257], char *err, size_t errlen)
{
    for (int v = 0; v < 257; v++) {
        map[v] = -1;
    }
    const char *p = spec;
    while (*p) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        const char *eq = memchr(p, '=', len);
        if (eq == NULL || eq == p || eq + 1 == p + len) {
            return fail(err, errlen, SC_ERR_INVALID_ARG,
                        "--label-map: '%.*s' is not VALUE=NAME (e.g. 2=vein,3=artery,*=muscle)",
                        (int)len, p);
        }
        int slot;
        if (eq - p == 1 && p[0] == '*') {
            slot = 256;
        } else {
            char num[16];
            size_t nl = (size_t)(eq - p);
            if (nl >= sizeof num) {
                return fail(err, errlen, SC_ERR_INVALID_ARG, "--label-map: value '%.*s'",
                            (int)nl, p);
            }
            memcpy(num, p, nl);
            num[nl] = 0;
            char *end;
            errno = 0;
            long v = strtol(num, &end, 10);
            if (errno || *end || end == num || v < 0 || v > 255) {
                return fail(err, errlen, SC_ERR_INVALID_ARG,
                            "--label-map: value '%s' is not an integer 0..255", num);
            }
            slot = (int)v;
        }
        const char *nm = eq + 1;
        size_t nn = (size_t)(p + len - nm);
        int l = label_from_name(nm, nn);
        if (l < 0) {
            char known[160] = "";
            for (int k = 0; k < (int)SC_LABEL_COUNT; k++) {
                strncat(known, k_label_names[k], sizeof known - strlen(known) - 2u);
                strncat(known, k + 1 < (int)SC_LABEL_COUNT ? " " : "",
                        sizeof known - strlen(known) - 1u);
            }
            return fail(err, errlen, SC_ERR_INVALID_ARG,
                        "--label-map: unknown label name '%.*s' (known: %s)", (int)nn, nm, known);
        }
        if (map[slot] >= 0) {
            return fail(err, errlen, SC_ERR_INVALID_ARG, "--label-map: value %s given twice",
                        slot == 256 ? "*" : "");
        }
        map[slot] = l;
        p += len;
        if (*p == ',') {
            p++;
            if (!*p) {
                return fail(err, errlen, SC_ERR_INVALID_ARG, "--label-map: trailing comma");
            }
        }
    }
    return SC_OK;
}

/* ---- derived mesh box --------------------------------------------------------------------- */
static int derive_mesh_box(const sc_import_result *r, const uint32_t dim[3], const double sp[3],
                           const double org[3], float box[6], char *err, size_t errlen)
{
    const uint8_t *lab = r->labels;
    uint32_t i0 = dim[0], i1 = 0, j0 = dim[1], j1 = 0, top = dim[2];
    uint32_t bone_top = dim[2], vessel_bottom = 0;
    int have_vessel = 0;
    for (uint32_t k = 0; k < dim[2]; k++) {
        for (uint32_t j = 0; j < dim[1]; j++) {
            const uint8_t *row = lab + (size_t)dim[0] * (j + (size_t)dim[1] * k);
            for (uint32_t i = 0; i < dim[0]; i++) {
                const uint8_t l = row[i];
                if (l == SC_LABEL_OUTSIDE) {
                    continue;
                }
                i0 = i < i0 ? i : i0;
                i1 = i > i1 ? i : i1;
                j0 = j < j0 ? j : j0;
                j1 = j > j1 ? j : j1;
                top = k < top ? k : top;
                if (l == SC_LABEL_BONE && k < bone_top) {
                    bone_top = k;
                }
                if (l == SC_LABEL_VEIN || l == SC_LABEL_ARTERY || l == SC_LABEL_THROMBUS) {
                    have_vessel = 1;
                    vessel_bottom = k > vessel_bottom ? k : vessel_bottom;
                }
            }
        }
    }
    uint32_t bottom = dim[2] - 1u;
    if (bone_top < dim[2] && bone_top > top + 1u && (!have_vessel || bone_top > vessel_bottom)) {
        bottom = bone_top;
    }
    if (top >= dim[2] || i1 <= i0 || j1 <= j0 || bottom <= top) {
        return fail(err, errlen, SC_ERR_CASE_MESH_BOX,
                    "cannot derive a mesh box from the labels (no tissue volume below a skin "
                    "surface, at least 2 voxels on every axis): give --mesh-box");
    }
    const uint32_t lo[3] = {i0, j0, top}, hi[3] = {i1, j1, bottom};
    for (int a = 0; a < 3; a++) {
        box[a] = (float)(org[a] + sp[a] * (double)lo[a]);
        box[3 + a] = (float)(sp[a] * (double)(hi[a] - lo[a]));
    }
    return SC_OK;
}

int sc_import_case(const sc_import_opts *o, sc_import_result *r, char *err, size_t errlen)
{
    if (o == NULL || r == NULL || o->volume_path == NULL) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "no volume");
    }
    memset(r, 0, sizeof *r);
    int lmap[257];
    if (o->label_map != NULL) {
        int rc = parse_label_map(o->label_map, lmap, err, errlen);
        if (rc != SC_OK) {
            return rc;
        }
        if (o->labels_path == NULL) {
            return fail(err, errlen, SC_ERR_INVALID_ARG, "--label-map without --labels");
        }
    }
    const float rs = o->spacing_mm;
    if (!isfinite(rs) || rs < 0.0f || (rs > 0.0f && (rs < 0.01f || rs > 50.0f))) {
        return fail(err, errlen, SC_ERR_CASE_SPACING, "--spacing %g: 0.01 .. 50 mm",
                    (double)o->spacing_mm);
    }
    if (o->has_window &&
        (!isfinite(o->window_lo) || !isfinite(o->window_hi) || !(o->window_hi > o->window_lo))) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "--window %g:%g: finite, LO below HI",
                    (double)o->window_lo, (double)o->window_hi);
    }
    sc_image vol, lab;
    int rc = sc_image_read_ex(o->volume_path, &o->limits, &vol, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    int have_lab = 0;
    if (o->labels_path != NULL) {
        rc = sc_image_read_ex(o->labels_path, &o->limits, &lab, err, errlen);
        if (rc != SC_OK) {
            sc_image_free(&vol);
            return rc;
        }
        have_lab = 1;
    }
    /* the case frame: axes of the source grid, permuted/flipped so that z is depth */
    int axis[3], sign[3];
    double C[9];
    rc = choose_frame(&vol, o, axis, sign, C, err, errlen);
    if (rc != SC_OK) {
        goto out;
    }
    /* the case grid: the volume's extent along each case axis, source or requested spacing */
    uint32_t dim[3];
    double sp[3], org[3];
    for (int c = 0; c < 3; c++) {
        const int a = axis[c];
        const double sa = vol.spacing[a];
        const double ext = sa * (double)(vol.dim[a] - 1u);
        const double o_a = vol.dir[a] * vol.origin[0] + vol.dir[3 + a] * vol.origin[1] +
                           vol.dir[6 + a] * vol.origin[2];
        org[c] = sign[c] > 0 ? o_a : -o_a - ext;
        sp[c] = o->spacing_mm > 0.0f ? (double)o->spacing_mm : sa;
        const double nd = floor(ext / sp[c] + 1e-6) + 1.0;
        if (!(nd >= 1.0 && nd <= (double)SC_MAX_VOLUME_DIM)) {
            rc = fail(err, errlen, SC_ERR_CASE_DIMS,
                      "case grid axis %c: %.4g mm at %.4g mm is %.4g voxels, above %u", "xyz"[c],
                      ext, sp[c], nd, SC_MAX_VOLUME_DIM);
            goto out;
        }
        dim[c] = (uint32_t)nd;
        r->frame_axis[c] = a;
        r->frame_sign[c] = sign[c];
    }
    long long dl[3] = {dim[0], dim[1], dim[2]};
    sc_image tmp;
    rc = set_dims(&tmp, dl, 3, o->limits.max_voxels, "case grid", err, errlen);
    if (rc != SC_OK) {
        goto out;
    }
    const size_t n = (size_t)dim[0] * dim[1] * dim[2];
    r->voxels = malloc(n);
    r->labels = malloc(n);
    if (r->voxels == NULL || r->labels == NULL) {
        rc = fail(err, errlen, SC_ERR_NO_SPACE, "out of memory");
        goto out;
    }
    /* intensity window */
    double lo = 0.0, hi = 255.0;
    if (o->has_window) {
        lo = (double)o->window_lo;
        hi = (double)o->window_hi;
    } else if (vol.type != SC_ELEM_U8) {
        size_t vn = image_count(&vol), step = vn / 65536u + 1u, m = 0;
        double *smp = malloc((vn / step + 1u) * sizeof(double));
        if (smp == NULL) {
            rc = fail(err, errlen, SC_ERR_NO_SPACE, "out of memory");
            goto out;
        }
        for (size_t i = 0; i < vn; i += step) {
            smp[m++] = vol.data[i];
        }
        qsort(smp, m, sizeof(double), cmp_double);
        lo = smp[(m - 1u) / 1000u];
        hi = smp[(m - 1u) - (m - 1u) / 1000u];
        free(smp);
    }
    if (!(hi > lo)) {
        hi = lo + 1.0;
    }
    for (uint32_t k = 0; k < dim[2]; k++) {
        for (uint32_t j = 0; j < dim[1]; j++) {
            for (uint32_t i = 0; i < dim[0]; i++) {
                size_t idx = i + (size_t)dim[0] * (j + (size_t)dim[1] * k);
                /* world point: C * (case origin + (i, j, k) * sp) */
                double q[3] = {org[0] + (double)i * sp[0], org[1] + (double)j * sp[1],
                               org[2] + (double)k * sp[2]};
                double p[3];
                for (int rr = 0; rr < 3; rr++) {
                    p[rr] = C[rr * 3] * q[0] + C[rr * 3 + 1] * q[1] + C[rr * 3 + 2] * q[2];
                }
                double si[3];
                world_to_index(&vol, p, si);
                double v = sample_linear(&vol, si);
                double t = (v - lo) / (hi - lo) * 255.0;
                t = t < 0.0 ? 0.0 : (t > 255.0 ? 255.0 : t);
                r->voxels[idx] = (uint8_t)lrint(t);
                uint8_t l = SC_LABEL_MUSCLE;
                if (have_lab) {
                    double li[3], lv = 0.0;
                    world_to_index(&lab, p, li);
                    int inside = sample_nearest(&lab, li, &lv);
                    if (inside && (!(lv >= 0.0 && lv <= 255.0) || lv > floor(lv))) {
                        rc = fail(err, errlen, SC_ERR_CASE_LABEL,
                                  "%s: label value %g is not an integer 0..255", o->labels_path,
                                  lv);
                        goto out;
                    }
                    if (!inside) {
                        l = SC_LABEL_OUTSIDE; /* label map smaller than the volume */
                    } else if (o->label_map != NULL) {
                        const int m = lmap[(int)lv] >= 0 ? lmap[(int)lv] : lmap[256];
                        if (m < 0) {
                            rc = fail(err, errlen, SC_ERR_CASE_LABEL,
                                      "%s: label value %g has no entry in --label-map (add "
                                      "%g=NAME or *=NAME)",
                                      o->labels_path, lv, lv);
                            goto out;
                        }
                        l = (uint8_t)m;
                    } else if (lv >= (double)SC_LABEL_COUNT) {
                        rc = fail(err, errlen, SC_ERR_CASE_LABEL,
                                  "%s: label value %g is not a project label (0..%d); name what "
                                  "it is with --label-map %g=NAME",
                                  o->labels_path, lv, (int)SC_LABEL_COUNT - 1, lv);
                        goto out;
                    } else {
                        l = (uint8_t)lv;
                    }
                }
                r->labels[idx] = l;
                r->label_voxels[l]++;
            }
        }
    }
    /* the case definition */
    sc_case_def *d = &r->def;
    *d = sc_case_default_def();
    snprintf(r->name, sizeof r->name, "%s", o->name ? o->name : "imported");
    if (o->description != NULL) {
        snprintf(r->description, sizeof r->description, "%s", o->description);
    } else {
        snprintf(
            r->description, sizeof r->description,
            "Imported volume (voxels and geometry only), %u x %u x %u, %.3g x %.3g x %.3g mm%s.",
            dim[0], dim[1], dim[2], sp[0], sp[1], sp[2],
            have_lab ? ", with label map" : ", no label map (soft tissue)");
    }
    d->name = r->name;
    d->description = r->description;
    /* volume frame = case axes: v = C^T (world) */
    for (int a = 0; a < 3; a++) {
        d->volume.dim[a] = dim[a];
        d->volume.spacing_mm[a] = (float)sp[a];
        d->volume.origin_mm[a] = (float)org[a];
    }
    for (int i = 0; i < 9; i++) {
        d->orientation[i] = (float)C[i];
    }
    d->volume.voxels = r->voxels;
    d->volume.labels = r->labels;
    static const sc_case_material mats[] = {
#define IM_MAT_(label, e, nu, rho) {(e), (nu), (rho)},
        SC_MATERIAL_LIST(IM_MAT_)
#undef IM_MAT_
    };
    d->material_count = (uint32_t)(sizeof mats / sizeof mats[0]);
    memcpy(d->materials, mats, sizeof mats);
    d->image_to_probe = o->image_to_probe;
    d->mesh.nx = o->mesh_nodes[0];
    d->mesh.ny = o->mesh_nodes[1];
    d->mesh.nz = o->mesh_nodes[2];
    float box[6];
    if (o->has_mesh_box) {
        memcpy(box, o->mesh_box_mm, sizeof box);
    } else {
        rc = derive_mesh_box(r, dim, sp, org, box, err, errlen);
        if (rc != SC_OK) {
            goto out;
        }
        r->mesh_box_derived = 1;
    }
    for (int a = 0; a < 3; a++) {
        d->mesh.origin_mm[a] = box[a];
        d->mesh.size_mm[a] = box[3 + a];
    }
    if (o->has_registration) {
        d->tracker_to_patient = o->tracker_to_patient;
    } else {
        /* the tracker emulator's frame: tracker -> volume is (x, y, z) -> (x, -y, -z) plus the
         * top centre of the mesh box, so tracker -> patient = C diag(1, -1, -1), t = C top */
        const double top[3] = {(double)box[0] + 0.5 * (double)box[3],
                               (double)box[1] + 0.5 * (double)box[4], (double)box[2]};
        sc_xform x;
        for (int rr = 0; rr < 3; rr++) {
            x.r[rr * 3 + 0] = (float)C[rr * 3 + 0];
            x.r[rr * 3 + 1] = (float)-C[rr * 3 + 1];
            x.r[rr * 3 + 2] = (float)-C[rr * 3 + 2];
            x.t_mm[rr] =
                (float)(C[rr * 3] * top[0] + C[rr * 3 + 1] * top[1] + C[rr * 3 + 2] * top[2]);
        }
        d->tracker_to_patient = x;
    }
    rc = SC_OK;
out:
    sc_image_free(&vol);
    if (have_lab) {
        sc_image_free(&lab);
    }
    if (rc != SC_OK) {
        sc_import_result_free(r);
    }
    return rc;
}
