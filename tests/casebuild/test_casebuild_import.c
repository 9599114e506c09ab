/* test_casebuild_import.c: MetaImage and NRRD import, every supported encoding and element
 * type, compared voxel by voxel; geometry; resampling; named refusals. The fixtures are
 * written at test time into a temporary directory (no committed blobs). */
#include "sc_test.h"
#include "sc_test_tmpdir.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "sc_caseimport.h"
#include "sc_err.h"
#include "sc_labels.h"

#define DX 7u
#define DY 5u
#define DZ 4u
#define N  (DX * DY * DZ)

static char g_dir[256];

static const char *const met_names[] = {"MET_UCHAR", "MET_CHAR", "MET_USHORT", "MET_SHORT",
                                        "MET_UINT",  "MET_INT",  "MET_FLOAT",  "MET_DOUBLE"};
static const char *const nrrd_names[] = {"uchar", "int8",  "ushort", "short",
                                         "uint",  "int32", "float",  "double"};
static const size_t esize[] = {1, 1, 2, 2, 4, 4, 4, 8};

/* reference value of voxel i for each type: uses the type's range, signs, fractions */
static double ref_value(sc_elem_type t, size_t i)
{
    switch (t) {
    case SC_ELEM_U8:
        return (double)((i * 37u) % 256u);
    case SC_ELEM_I8:
        return (double)((int)((i * 37u) % 256u) - 128);
    case SC_ELEM_U16:
        return (double)((i * 2477u) % 65536u);
    case SC_ELEM_I16:
        return (double)((int)((i * 2477u) % 65536u) - 32768);
    case SC_ELEM_U32:
        return (double)((i * 2654435761u) % 4294967296u);
    case SC_ELEM_I32:
        return (double)((long long)((i * 2654435761u) % 4294967296u) - 2147483648LL);
    case SC_ELEM_F32:
        return (double)((float)i * 0.37f - 9.5f);
    case SC_ELEM_F64:
    default:
        return (double)i * 0.123456789 - 3.25;
    }
}

/* encode the reference volume as bytes of type t */
static void encode(sc_elem_type t, int big, uint8_t *out)
{
    for (size_t i = 0; i < N; i++) {
        double v = ref_value(t, i);
        uint8_t le[8];
        uint64_t u = 0;
        switch (t) {
        case SC_ELEM_U8:
        case SC_ELEM_I8:
            u = (uint64_t)(uint8_t)(int64_t)v;
            break;
        case SC_ELEM_U16:
        case SC_ELEM_I16:
            u = (uint64_t)(uint16_t)(int64_t)v;
            break;
        case SC_ELEM_U32:
        case SC_ELEM_I32:
            u = (uint64_t)(uint32_t)(int64_t)v;
            break;
        case SC_ELEM_F32: {
            float f = (float)v;
            uint32_t w;
            memcpy(&w, &f, 4);
            u = w;
            break;
        }
        case SC_ELEM_F64:
        default:
            memcpy(&u, &v, 8);
            break;
        }
        for (size_t k = 0; k < 8; k++) {
            le[k] = (uint8_t)(u >> (8u * k));
        }
        size_t es = esize[t];
        for (size_t k = 0; k < es; k++) {
            out[i * es + k] = big ? le[es - 1u - k] : le[k];
        }
    }
}

static void path_of(char *p, size_t n, const char *name)
{
    snprintf(p, n, "%s/%s", g_dir, name);
}

static void write_bytes(const char *name, const void *hdr, size_t hn, const void *data, size_t dn)
{
    char p[512];
    path_of(p, sizeof p, name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    if (hn) {
        assert_int_equal(fwrite(hdr, 1, hn, f), hn);
    }
    if (dn) {
        assert_int_equal(fwrite(data, 1, dn, f), dn);
    }
    assert_int_equal(fclose(f), 0);
}

/* zlib (gzip = 0) or gzip (gzip = 1) stream of src */
static size_t deflate_buf(const uint8_t *src, size_t n, uint8_t *dst, size_t cap, int gzip)
{
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    assert_int_equal(deflateInit2(&zs, 6, Z_DEFLATED, gzip ? 31 : 15, 8, Z_DEFAULT_STRATEGY), Z_OK);
    zs.next_in = (Bytef *)(uintptr_t)src;
    zs.avail_in = (uInt)n;
    zs.next_out = dst;
    zs.avail_out = (uInt)cap;
    assert_int_equal(deflate(&zs, Z_FINISH), Z_STREAM_END);
    size_t out = zs.total_out;
    deflateEnd(&zs);
    return out;
}

static const double k_spacing[3] = {0.5, 0.75, 1.25};
static const double k_origin[3] = {-3.0, 2.5, 10.0};

static void check_image(const sc_image *img, sc_elem_type t, const char *what)
{
    assert_int_equal(img->dim[0], DX);
    assert_int_equal(img->dim[1], DY);
    assert_int_equal(img->dim[2], DZ);
    assert_int_equal(img->type, t);
    for (int a = 0; a < 3; a++) {
        assert_true(fabs(img->spacing[a] - k_spacing[a]) < 1e-12);
        assert_true(fabs(img->origin[a] - k_origin[a]) < 1e-12);
    }
    for (size_t i = 0; i < N; i++) {
        double want = ref_value(t, i);
        if (!(fabs(img->data[i] - want) <= 0.0)) {
            fail_msg("%s: voxel %zu is %g, want %g", what, i, img->data[i], want);
        }
    }
}

static uint8_t g_raw[N * 8u], g_z[N * 8u + 1024u];

static void metaimage_every_type_raw_and_compressed_inline_and_detached(void **state)
{
    (void)state;
    for (int t = 0; t <= (int)SC_ELEM_F64; t++) {
        for (int big = 0; big < 2; big++) {
            encode((sc_elem_type)t, big, g_raw);
            size_t rn = N * esize[t];
            size_t zn = deflate_buf(g_raw, rn, g_z, sizeof g_z, 0);
            for (int variant = 0; variant < 4; variant++) {
                /* 0: .mha raw, 1: .mha compressed, 2: .mhd + .raw, 3: .mhd + .zraw */
                int comp = variant & 1, detached = variant >> 1;
                char hdr[1024], name[64], dname[64];
                snprintf(name, sizeof name, "m%d_%d_%d.%s", t, big, variant,
                         detached ? "mhd" : "mha");
                snprintf(dname, sizeof dname, "m%d_%d_%d.%s", t, big, variant,
                         comp ? "zraw" : "raw");
                char extra[64] = "";
                if (comp) {
                    snprintf(extra, sizeof extra, "CompressedDataSize = %zu\n", zn);
                }
                int hn = snprintf(hdr, sizeof hdr,
                                  "ObjectType = Image\nNDims = 3\nBinaryData = True\n"
                                  "BinaryDataByteOrderMSB = %s\nCompressedData = %s\n%s"
                                  "TransformMatrix = 1 0 0 0 1 0 0 0 1\n"
                                  "Offset = -3 2.5 10\nElementSpacing = 0.5 0.75 1.25\n"
                                  "DimSize = %u %u %u\nPatientName = Should Be Ignored\n"
                                  "ElementType = %s\nElementDataFile = %s\n",
                                  big ? "True" : "False", comp ? "True" : "False", extra, DX, DY,
                                  DZ, met_names[t], detached ? dname : "LOCAL");
                const uint8_t *data = comp ? g_z : g_raw;
                size_t dn = comp ? zn : rn;
                if (detached) {
                    write_bytes(name, hdr, (size_t)hn, NULL, 0);
                    write_bytes(dname, NULL, 0, data, dn);
                } else {
                    write_bytes(name, hdr, (size_t)hn, data, dn);
                }
                char p[512], err[256];
                path_of(p, sizeof p, name);
                sc_image img;
                int rc = sc_image_read(p, &img, err, sizeof err);
                if (rc != SC_OK) {
                    fail_msg("%s: %s", name, err);
                }
                check_image(&img, (sc_elem_type)t, name);
                sc_image_free(&img);
            }
        }
    }
}

static void nrrd_every_type_raw_gzip_ascii_attached_and_detached(void **state)
{
    (void)state;
    for (int t = 0; t <= (int)SC_ELEM_F64; t++) {
        for (int big = 0; big < 2; big++) {
            encode((sc_elem_type)t, big, g_raw);
            size_t rn = N * esize[t];
            size_t zn = deflate_buf(g_raw, rn, g_z, sizeof g_z, 1);
            /* ascii text of the values (%.17g round-trips doubles) */
            static char txt[N * 32u];
            size_t tn = 0;
            for (size_t i = 0; i < N; i++) {
                tn += (size_t)snprintf(txt + tn, sizeof txt - tn, "%.17g%c",
                                       ref_value((sc_elem_type)t, i),
                                       (i % DX) == DX - 1u ? '\n' : ' ');
            }
            for (int enc = 0; enc < 3; enc++) {
                if (enc == 2 && big) {
                    continue; /* ascii has no byte order */
                }
                for (int detached = 0; detached < 2; detached++) {
                    static const char *const encs[] = {"raw", "gzip", "ascii"};
                    char hdr[1024], name[64], dname[64];
                    snprintf(name, sizeof name, "n%d_%d_%d_%d.%s", t, big, enc, detached,
                             detached ? "nhdr" : "nrrd");
                    snprintf(dname, sizeof dname, "n%d_%d_%d_%d.%s", t, big, enc, detached,
                             enc == 1 ? "raw.gz" : "raw");
                    char df[128] = "";
                    if (detached) {
                        snprintf(df, sizeof df, "data file: %s\n", dname);
                    }
                    int hn = snprintf(hdr, sizeof hdr,
                                      "NRRD0004\n# a comment\ntype: %s\ndimension: 3\n"
                                      "space: left-posterior-superior\nsizes: %u %u %u\n"
                                      "space directions: (0.5,0,0) (0,0.75,0) (0,0,1.25)\n"
                                      "kinds: domain domain domain\nendian: %s\n"
                                      "encoding: %s\nspace origin: (-3,2.5,10)\n"
                                      "patient name:=Should Be Ignored\n%s%s",
                                      nrrd_names[t], DX, DY, DZ, big ? "big" : "little", encs[enc],
                                      df, detached ? "" : "\n");
                    const void *data = enc == 0   ? (const void *)g_raw
                                       : enc == 1 ? (const void *)g_z
                                                  : (const void *)txt;
                    size_t dn = enc == 0 ? rn : enc == 1 ? zn : tn;
                    if (detached) {
                        write_bytes(name, hdr, (size_t)hn, NULL, 0);
                        write_bytes(dname, NULL, 0, data, dn);
                    } else {
                        write_bytes(name, hdr, (size_t)hn, data, dn);
                    }
                    char p[512], err[256];
                    path_of(p, sizeof p, name);
                    sc_image img;
                    int rc = sc_image_read(p, &img, err, sizeof err);
                    if (rc != SC_OK) {
                        fail_msg("%s: %s", name, err);
                    }
                    check_image(&img, (sc_elem_type)t, name);
                    sc_image_free(&img);
                }
            }
        }
    }
}

static void nrrd_spacings_field_and_byte_skip_are_honoured(void **state)
{
    (void)state;
    encode(SC_ELEM_U16, 0, g_raw);
    size_t rn = N * 2u;
    /* detached raw with a 16-byte preamble skipped by "byte skip: -1" (data at the end) */
    uint8_t pre[16 + N * 2u];
    memset(pre, 0xAB, 16);
    memcpy(pre + 16, g_raw, rn);
    char hdr[512];
    int hn = snprintf(hdr, sizeof hdr,
                      "NRRD0004\ntype: uint16\ndimension: 3\nsizes: %u %u %u\n"
                      "spacings: 0.5 0.75 1.25\nencoding: raw\nendian: little\n"
                      "byte skip: -1\ndata file: skip.raw\n",
                      DX, DY, DZ);
    write_bytes("skip.nhdr", hdr, (size_t)hn, NULL, 0);
    write_bytes("skip.raw", NULL, 0, pre, sizeof pre);
    char p[512], err[256];
    path_of(p, sizeof p, "skip.nhdr");
    sc_image img;
    assert_int_equal(sc_image_read(p, &img, err, sizeof err), SC_OK);
    for (size_t i = 0; i < N; i++) {
        assert_true(fabs(img.data[i] - ref_value(SC_ELEM_U16, i)) <= 0.0);
    }
    assert_true(fabs(img.spacing[2] - 1.25) < 1e-12);
    sc_image_free(&img);
}

/* a u8 volume + label map at the same grid imports voxel for voxel */
static void import_keeps_u8_voxels_and_labels_exactly_at_source_spacing(void **state)
{
    (void)state;
    uint8_t vox[N], lab[N];
    for (size_t i = 0; i < N; i++) {
        vox[i] = (uint8_t)((i * 37u) % 256u);
        lab[i] = (uint8_t)(i % SC_LABEL_COUNT);
    }
    char hdr[512];
    const char *fmt = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
                      "space dimension: 3\nspace directions: (0.5,0,0) (0,0.75,0) (0,0,1.25)\n"
                      "space origin: (-3,2.5,10)\nencoding: raw\n\n";
    int hn = snprintf(hdr, sizeof hdr, fmt, DX, DY, DZ);
    write_bytes("vol.nrrd", hdr, (size_t)hn, vox, N);
    write_bytes("lab.nrrd", hdr, (size_t)hn, lab, N);
    sc_import_opts o = sc_import_default_opts();
    char pv[512], pl[512], err[256];
    path_of(pv, sizeof pv, "vol.nrrd");
    path_of(pl, sizeof pl, "lab.nrrd");
    o.volume_path = pv;
    o.labels_path = pl;
    o.mesh_nodes[0] = 4;
    o.mesh_nodes[1] = 3;
    o.mesh_nodes[2] = 3;
    sc_import_result r;
    int rc = sc_import_case(&o, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    assert_memory_equal(r.def.volume.dim, ((uint32_t[]){DX, DY, DZ}), sizeof r.def.volume.dim);
    assert_memory_equal(r.voxels, vox, N);
    assert_memory_equal(r.labels, lab, N);
    assert_true(fabsf(r.def.volume.origin_mm[0] + 3.0f) < 1e-6f);
    assert_true(fabsf(r.def.volume.spacing_mm[2] - 1.25f) < 1e-6f);
    /* the name never comes from the file name (it may identify a patient) */
    assert_string_equal(r.def.name, "imported");
    /* and the result is a valid case */
    size_t need = sc_case_encoded_size(&r.def), n = 0;
    uint8_t *buf = malloc(need);
    assert_int_equal(sc_case_write(&r.def, buf, need, &n), SC_OK);
    sc_case c;
    assert_int_equal(sc_case_load(buf, n, &c), SC_OK);
    free(buf);
    sc_import_result_free(&r);
}

/* trilinear resampling is exact on a linear ramp; the orientation is carried over */
static void import_resamples_linearly_and_keeps_orientation(void **state)
{
    (void)state;
    float ramp[N];
    for (uint32_t k = 0; k < DZ; k++) {
        for (uint32_t j = 0; j < DY; j++) {
            for (uint32_t i = 0; i < DX; i++) {
                ramp[i + DX * (j + DY * k)] = 10.0f * (float)i + 3.0f * (float)j + 2.0f * (float)k;
            }
        }
    }
    char hdr[512];
    /* grid x along world y, grid y along world -x (rotation of 90 degrees about z) */
    int hn = snprintf(hdr, sizeof hdr,
                      "NRRD0004\ntype: float\ndimension: 3\nsizes: %u %u %u\n"
                      "space dimension: 3\nspace directions: (0,1,0) (-1,0,0) (0,0,1)\n"
                      "space origin: (5,-2,1)\nencoding: raw\nendian: little\n\n",
                      DX, DY, DZ);
    write_bytes("ramp.nrrd", hdr, (size_t)hn, ramp, sizeof ramp);
    sc_import_opts o = sc_import_default_opts();
    char pv[512], err[256];
    path_of(pv, sizeof pv, "ramp.nrrd");
    o.volume_path = pv;
    o.spacing_mm = 0.5f;
    o.has_window = 1;
    o.window_lo = 0.0f;
    o.window_hi = 255.0f;
    sc_import_result r;
    int rc = sc_import_case(&o, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    const uint32_t *d = r.def.volume.dim;
    assert_int_equal(d[0], 2u * DX - 1u);
    assert_int_equal(d[1], 2u * DY - 1u);
    assert_int_equal(d[2], 2u * DZ - 1u);
    for (uint32_t k = 0; k < d[2]; k++) {
        for (uint32_t j = 0; j < d[1]; j++) {
            for (uint32_t i = 0; i < d[0]; i++) {
                double want = 5.0 * i + 1.5 * j + 1.0 * k;
                uint8_t got = r.voxels[i + d[0] * (j + d[1] * k)];
                assert_true(fabs((double)got - want) <= 0.5); /* 8-bit rounding */
            }
        }
    }
    const float want_o[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
    for (int i = 0; i < 9; i++) {
        assert_true(fabsf(r.def.orientation[i] - want_o[i]) < 1e-6f);
    }
    /* case origin = D^T world origin = (world y, -world x, z) = (-2, -5, 1) */
    assert_true(fabsf(r.def.volume.origin_mm[0] + 2.0f) < 1e-5f);
    assert_true(fabsf(r.def.volume.origin_mm[1] + 5.0f) < 1e-5f);
    assert_true(fabsf(r.def.volume.origin_mm[2] - 1.0f) < 1e-5f);
    /* no label map: everything soft tissue */
    assert_int_equal(r.labels[0], SC_LABEL_MUSCLE);
    sc_import_result_free(&r);
}

static int read_named(const char *name, const char *hdr, const void *data, size_t dn)
{
    write_bytes(name, hdr, strlen(hdr), data, dn);
    char p[512], err[256];
    path_of(p, sizeof p, name);
    sc_image img;
    int rc = sc_image_read(p, &img, err, sizeof err);
    if (rc == SC_OK) {
        sc_image_free(&img);
    }
    return rc;
}

static void bad_inputs_are_refused_with_named_errors(void **state)
{
    (void)state;
    uint8_t data[N * 8u] = {0};
    char hdr[512], p[512], err[256];
    sc_image img;
    path_of(p, sizeof p, "missing.mha");
    assert_int_equal(sc_image_read(p, &img, err, sizeof err), SC_ERR_NOT_FOUND);
    path_of(p, sizeof p, "x.vtk");
    assert_int_equal(sc_image_read(p, &img, err, sizeof err), SC_ERR_NOT_SUPPORTED);
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
             "encoding: raw\n\n",
             DX, DY, DZ);
    assert_int_equal(read_named("short.nrrd", hdr, data, N - 1u), SC_ERR_PARSE);
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
             "encoding: bzip2\n\n",
             DX, DY, DZ);
    assert_int_equal(read_named("bz.nrrd", hdr, data, N), SC_ERR_NOT_SUPPORTED);
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
             "encoding: gzip\n\n",
             DX, DY, DZ);
    assert_int_equal(read_named("badgz.nrrd", hdr, data, N), SC_ERR_PARSE);
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2000 2 2\n"
             "encoding: raw\n\n");
    assert_int_equal(read_named("big.nrrd", hdr, data, N), SC_ERR_CASE_DIMS);
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
             "spacings: 1 nan 1\nencoding: raw\n\n",
             DX, DY, DZ);
    #ifdef SC_HAVE_TEEM
    /* libnrrd follows the format: a nan spacing is "unknown", as if not given (1 mm) */
    assert_int_equal(read_named("nan.nrrd", hdr, data, N), SC_OK);
#else
    assert_int_equal(read_named("nan.nrrd", hdr, data, N), SC_ERR_CASE_SPACING);
#endif
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
             "space dimension: 3\nspace directions: (1,0,0) (1,1,0) (0,0,1)\nencoding: raw\n\n",
             DX, DY, DZ);
    assert_int_equal(read_named("sheared.nrrd", hdr, data, N), SC_ERR_CASE_TRANSFORM);
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nElementType = MET_LONG_LONG\n"
             "ElementDataFile = LOCAL\n",
             DX, DY, DZ);
    assert_int_equal(read_named("ll.mha", hdr, data, N), SC_ERR_NOT_SUPPORTED);
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nElementType = MET_UCHAR\n"
             "CompressedData = True\nElementDataFile = LOCAL\n",
             DX, DY, DZ);
    assert_int_equal(read_named("badz.mha", hdr, data, N), SC_ERR_PARSE);
    /* label values that are not labels */
    float fl[N];
    for (size_t i = 0; i < N; i++) {
        fl[i] = 1.0f;
    }
    fl[N / 2u] = 1.5f;
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: float\ndimension: 3\nsizes: %u %u %u\n"
             "encoding: raw\nendian: little\n\n",
             DX, DY, DZ);
    write_bytes("flab.nrrd", hdr, strlen(hdr), fl, sizeof fl);
    write_bytes("fvol.nrrd", hdr, strlen(hdr), fl, sizeof fl);
    sc_import_opts o = sc_import_default_opts();
    char pv[512], pl[512];
    path_of(pv, sizeof pv, "fvol.nrrd");
    path_of(pl, sizeof pl, "flab.nrrd");
    o.volume_path = pv;
    o.labels_path = pl;
    sc_import_result r;
    assert_int_equal(sc_import_case(&o, &r, err, sizeof err), SC_ERR_CASE_LABEL);
    fl[N / 2u] = 300.0f;
    write_bytes("flab.nrrd", hdr, strlen(hdr), fl, sizeof fl);
    assert_int_equal(sc_import_case(&o, &r, err, sizeof err), SC_ERR_CASE_LABEL);
}

/* read hdr (+ data) as NAME with the given limits: the return code, the message in err */
static int read_lim(const char *name, const char *hdr, const void *data, size_t dn,
                    const sc_read_limits *lim, char *err, size_t errlen)
{
    write_bytes(name, hdr, strlen(hdr), data, dn);
    char p[512];
    path_of(p, sizeof p, name);
    sc_image img;
    err[0] = 0;
    int rc = sc_image_read_ex(p, lim, &img, err, errlen);
    if (rc == SC_OK) {
        sc_image_free(&img);
    }
    return rc;
}

#define EXPECT_REFUSED(name, hdr, data, dn, lim, want_rc, needle)                                \
    do {                                                                                       \
        char e_[512];                                                                          \
        int rc_ = read_lim(name, hdr, data, dn, lim, e_, sizeof e_);                           \
        if (rc_ != (want_rc) || strstr(e_, needle) == NULL || strstr(e_, name) == NULL) {      \
            fail_msg("%s: rc %d '%s', want %d and '%s'", name, rc_, e_, want_rc, needle);      \
        }                                                                                      \
    } while (0)

/* Issue 14: every header number range-checked before use, data files only beside the
 * header, a ceiling before any allocation or inflation, non-finite voxels refused; each
 * refusal names the file and the field. */
static void hostile_headers_are_refused_naming_the_field(void **state)
{
    (void)state;
    static uint8_t data[N * 8u];
    memset(data, 0, sizeof data);
    const sc_read_limits def = sc_read_default_limits();
    char hdr[1024];
    /* sizes that would overflow an integer cast (undefined behaviour before) */
    EXPECT_REFUSED("huge.mha",
                   "NDims = 3\nDimSize = 1e300 2 2\nElementType = MET_UCHAR\n"
                   "ElementDataFile = LOCAL\n",
                   data, N, &def, SC_ERR_CASE_DIMS, "DimSize");
    EXPECT_REFUSED("huge.nrrd",
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1e300 2 2\nencoding: raw\n\n",
                   data, N, &def, SC_ERR_CASE_DIMS, "sizes");
    EXPECT_REFUSED("frac.nrrd",
                   "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2.5 2 2\nencoding: raw\n\n", data,
                   N, &def, SC_ERR_CASE_DIMS, "sizes");
    EXPECT_REFUSED("ndims.mha",
                   "NDims = three\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
                   "ElementDataFile = LOCAL\n",
                   data, N, &def, SC_ERR_PARSE, "NDims");
    EXPECT_REFUSED("dim.nrrd",
                   "NRRD0004\ntype: uchar\ndimension: 99999999999\nsizes: 2 2 2\n"
                   "encoding: raw\n\n",
                   data, N, &def, SC_ERR_PARSE, "dimension");
    /* spacing and origin outside any physical range */
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nElementSpacing = 1e308 1 1\nElementType = MET_UCHAR\n"
             "ElementDataFile = LOCAL\n",
             DX, DY, DZ);
    EXPECT_REFUSED("sp308.mha", hdr, data, N, &def, SC_ERR_CASE_SPACING, "spacing");
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\nspacings: 1e-30 1 1\n"
             "encoding: raw\n\n",
             DX, DY, DZ);
    EXPECT_REFUSED("sp30.nrrd", hdr, data, N, &def, SC_ERR_CASE_SPACING, "spacing");
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nOffset = 0 1e300 0\nElementType = MET_UCHAR\n"
             "ElementDataFile = LOCAL\n",
             DX, DY, DZ);
    EXPECT_REFUSED("org.mha", hdr, data, N, &def, SC_ERR_CASE_TRANSFORM, "origin");
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nTransformMatrix = 1 0 0 0 1\nElementType = "
             "MET_UCHAR\nElementDataFile = LOCAL\n",
             DX, DY, DZ);
    EXPECT_REFUSED("tm5.mha", hdr, data, N, &def, SC_ERR_PARSE, "TransformMatrix");
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\nbyte skip: 1e20\n"
             "encoding: raw\n\n",
             DX, DY, DZ);
    EXPECT_REFUSED("skip.nrrd", hdr, data, N, &def, SC_ERR_PARSE, "byte skip");
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nHeaderSize = -7\nElementType = MET_UCHAR\n"
             "ElementDataFile = vol.raw\n",
             DX, DY, DZ);
    EXPECT_REFUSED("hs.mhd", hdr, data, N, &def, SC_ERR_PARSE, "HeaderSize");
    /* data files only beside the header: not ../, not absolute, unless allowed */
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nElementType = MET_UCHAR\n"
             "ElementDataFile = ../../../../etc/passwd\n",
             DX, DY, DZ);
    EXPECT_REFUSED("up.mhd", hdr, NULL, 0, &def, SC_ERR_INVALID_ARG, "ElementDataFile");
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\ndata file: /etc/passwd\n"
             "encoding: raw\n\n",
             DX, DY, DZ);
    EXPECT_REFUSED("abs.nhdr", hdr, NULL, 0, &def, SC_ERR_INVALID_ARG, "data file");
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\ndata file: sub/../x.raw\n"
             "encoding: raw\n\n",
             DX, DY, DZ);
    EXPECT_REFUSED("mid.nhdr", hdr, NULL, 0, &def, SC_ERR_INVALID_ARG, "data file");
    {
        /* allowed by option: a data file one folder up is read */
        char sub[512], p[600], err[256];
        path_of(sub, sizeof sub, "sub");
        mkdir(sub, 0700);
        write_bytes("up.raw", NULL, 0, data, N);
        snprintf(hdr, sizeof hdr,
                 "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\ndata file: ../up.raw\n"
                 "encoding: raw\n\n",
                 DX, DY, DZ);
        write_bytes("sub/up.nhdr", hdr, strlen(hdr), NULL, 0);
        snprintf(p, sizeof p, "%s/up.nhdr", sub);
        sc_image img;
        assert_int_equal(sc_image_read(p, &img, err, sizeof err), SC_ERR_INVALID_ARG);
        sc_read_limits allow = def;
        allow.allow_data_path = 1;
        assert_int_equal(sc_image_read_ex(p, &allow, &img, err, sizeof err), SC_OK);
        sc_image_free(&img);
    }
    /* the ceiling, checked before allocating or inflating: a gzip header that claims
     * 1024 x 1024 x 128 voxels (a 1 GiB double buffer) over a few bytes of gzip */
    EXPECT_REFUSED("bomb.nrrd",
                   "NRRD0004\ntype: double\ndimension: 3\nsizes: 1024 1024 128\n"
                   "encoding: gzip\nendian: little\n\n",
                   g_z, deflate_buf(data, 64, g_z, sizeof g_z, 1), &def, SC_ERR_CASE_DIMS,
                   "ceiling");
    sc_read_limits small = def;
    small.max_voxels = 50; /* below DX*DY*DZ = 140 */
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\nencoding: raw\n\n", DX, DY,
             DZ);
    EXPECT_REFUSED("cap.nrrd", hdr, data, N, &small, SC_ERR_CASE_DIMS, "ceiling");
    /* non-finite voxels: refused, the first one named */
    float fl[N];
    for (size_t i = 0; i < N; i++) {
        fl[i] = (float)i;
    }
    fl[DX + 2] = NAN; /* voxel (2, 1, 0) */
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: float\ndimension: 3\nsizes: %u %u %u\nencoding: raw\n"
             "endian: little\n\n",
             DX, DY, DZ);
    EXPECT_REFUSED("nanvox.nrrd", hdr, fl, sizeof fl, &def, SC_ERR_NOT_FINITE, "(2, 1, 0)");
    fl[DX + 2] = INFINITY;
    EXPECT_REFUSED("infvox.nrrd", hdr, fl, sizeof fl, &def, SC_ERR_NOT_FINITE, "inf");
    /* options of the import itself */
    fl[DX + 2] = 1.0f;
    write_bytes("fine.nrrd", hdr, strlen(hdr), fl, sizeof fl);
    sc_import_opts o = sc_import_default_opts();
    char pv[512], err[256];
    path_of(pv, sizeof pv, "fine.nrrd");
    o.volume_path = pv;
    sc_import_result r;
    o.spacing_mm = 1e-30f;
    assert_int_equal(sc_import_case(&o, &r, err, sizeof err), SC_ERR_CASE_SPACING);
    o.spacing_mm = -3.0f;
    assert_int_equal(sc_import_case(&o, &r, err, sizeof err), SC_ERR_CASE_SPACING);
    o.spacing_mm = 0.0f;
    o.has_window = 1;
    o.window_lo = NAN;
    o.window_hi = INFINITY;
    assert_int_equal(sc_import_case(&o, &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_non_null(strstr(err, "--window"));
    o.has_window = 0;
    o.spacing_mm = 0.05f; /* 121 x 81 x 61 = 598 k case voxels: above a ceiling of 100 k */
    o.limits.max_voxels = 100000u;
    assert_int_equal(sc_import_case(&o, &r, err, sizeof err), SC_ERR_CASE_DIMS);
    assert_non_null(strstr(err, "case grid"));
}

static int setup(void **state)
{
    (void)state;
    return sc_test_tmpdir_make(g_dir, sizeof g_dir, "sc_import");
}

static int teardown(void **state)
{
    (void)state;
    return sc_test_tmpdir_remove(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(metaimage_every_type_raw_and_compressed_inline_and_detached),
        cmocka_unit_test(nrrd_every_type_raw_gzip_ascii_attached_and_detached),
        cmocka_unit_test(nrrd_spacings_field_and_byte_skip_are_honoured),
        cmocka_unit_test(import_keeps_u8_voxels_and_labels_exactly_at_source_spacing),
        cmocka_unit_test(import_resamples_linearly_and_keeps_orientation),
        cmocka_unit_test(bad_inputs_are_refused_with_named_errors),
        cmocka_unit_test(hostile_headers_are_refused_naming_the_field),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
