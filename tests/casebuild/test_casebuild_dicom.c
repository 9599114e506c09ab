/* test_casebuild_dicom.c: DICOM import through DCMTK (when built): slice series and enhanced
 * multi-frame files, 8/16-bit, signed, rescaled, RLE-compressed, oblique orientation, out of
 * order on disk; compared voxel by voxel. Fixtures are written at test time by DCMTK, and by
 * an independent writer (Debian's python3-pydicom, tests/casebuild/write_dicom_pydicom.py),
 * with and without the optional Rescale Slope / Intercept. */
#include "sc_test.h"
#include "sc_test_tmpdir.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sc_caseimport.h"
#include "sc_err.h"
#ifdef SC_HAVE_DCMTK
#include "sc_dicom.h"
#endif

static char g_dir[128];

#ifdef SC_HAVE_DCMTK
#define DX 6u
#define DY 5u
#define DZ 4u
#define N  (DX * DY * DZ)

static double g_vals[N];

/* an oblique frame: 30 degrees about z, then 20 about x (orthonormal, det +1) */
static void make_volume(sc_image *v, int bits, int is_signed, double slope, double icpt)
{
    memset(v, 0, sizeof *v);
    v->dim[0] = DX;
    v->dim[1] = DY;
    v->dim[2] = DZ;
    v->spacing[0] = 0.4;
    v->spacing[1] = 0.6;
    v->spacing[2] = 1.5;
    v->origin[0] = -12.5;
    v->origin[1] = 3.25;
    v->origin[2] = 40.0;
    const double a = 30.0 * M_PI / 180.0, b = 20.0 * M_PI / 180.0;
    const double rz[9] = {cos(a), -sin(a), 0, sin(a), cos(a), 0, 0, 0, 1};
    const double rx[9] = {1, 0, 0, 0, cos(b), -sin(b), 0, sin(b), cos(b)};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++) {
                s += rx[r * 3 + k] * rz[k * 3 + c];
            }
            v->dir[r * 3 + c] = s;
        }
    }
    for (size_t i = 0; i < N; i++) {
        long long stored;
        if (bits == 8) {
            stored = (long long)((i * 37u) % 256u);
        } else {
            stored = (long long)((i * 2477u) % 65536u) - (is_signed ? 32768 : 0);
        }
        g_vals[i] = (double)stored * slope + icpt;
    }
    v->data = g_vals;
}

static void check(const char *path, const sc_image *ref)
{
    sc_image img;
    char err[256];
    int rc = sc_image_read(path, &img, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s: %s", path, err);
    }
    assert_int_equal(img.dim[0], DX);
    assert_int_equal(img.dim[1], DY);
    assert_int_equal(img.dim[2], DZ);
    for (int a = 0; a < 3; a++) {
        /* DS strings carry 10 significant digits here */
        assert_true(fabs(img.spacing[a] - ref->spacing[a]) < 1e-6);
        assert_true(fabs(img.origin[a] - ref->origin[a]) < 1e-6);
    }
    for (int i = 0; i < 9; i++) {
        assert_true(fabs(img.dir[i] - ref->dir[i]) < 1e-6);
    }
    for (size_t i = 0; i < N; i++) {
        if (!(fabs(img.data[i] - ref->data[i]) <= 1e-9 * fabs(ref->data[i]))) {
            fail_msg("%s: voxel %zu is %g, want %g", path, i, img.data[i], ref->data[i]);
        }
    }
    sc_image_free(&img);
}

static void run_case(const char *name, int bits, int is_signed, double slope, double icpt,
                     int multiframe, int compress)
{
    char d[256];
    snprintf(d, sizeof d, "%s/%s", g_dir, name);
    assert_int_equal(mkdir(d, 0700), 0);
    sc_image ref;
    make_volume(&ref, bits, is_signed, slope, icpt);
    assert_int_equal(
        sc_dicom_write_fixture(d, &ref, bits, is_signed, slope, icpt, multiframe, compress), SC_OK);
    if (multiframe) {
        char f[300];
        snprintf(f, sizeof f, "%s/volume.dcm", d);
        check(f, &ref);
    } else {
        check(d, &ref);
    }
}

static void series_of_16_bit_signed_rescaled_oblique_slices(void **state)
{
    (void)state;
    run_case("s16", 16, 1, 0.5, -100.0, 0, 0);
}

static void series_of_16_bit_unsigned_rle_compressed_slices(void **state)
{
    (void)state;
    run_case("u16rle", 16, 0, 1.0, 0.0, 0, 1);
}

static void enhanced_multiframe_8_bit_frames_out_of_order(void **state)
{
    (void)state;
    run_case("mf8", 8, 0, 1.0, 0.0, 1, 0);
}

static void enhanced_multiframe_rle_compressed_imports_into_a_valid_case(void **state)
{
    (void)state;
    run_case("mf8rle", 8, 0, 1.0, 0.0, 1, 1);
    char f[300];
    snprintf(f, sizeof f, "%s/mf8rle/volume.dcm", g_dir);
    sc_import_opts o = sc_import_default_opts();
    o.volume_path = f;
    o.depth_axis = "+k"; /* source order (the default would be depth posterior, x right) */
    o.lateral_axis = "+i";
    o.mesh_nodes[0] = o.mesh_nodes[1] = o.mesh_nodes[2] = 3;
    sc_import_result r;
    char err[256];
    int rc = sc_import_case(&o, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    /* 8-bit data keeps its values at the source spacing */
    for (size_t i = 0; i < N; i++) {
        assert_int_equal(r.voxels[i], (uint8_t)g_vals[i]);
    }
    size_t need = sc_case_encoded_size(&r.def), n = 0;
    uint8_t *buf = malloc(need);
    assert_int_equal(sc_case_write(&r.def, buf, need, &n), SC_OK);
    sc_case c;
    assert_int_equal(sc_case_load(buf, n, &c), SC_OK);
    /* the oblique orientation is kept and folded into the registration */
    assert_true(fabsf(c.orientation[1] - (float)(-sin(M_PI / 6.0))) < 1e-6f);
    free(buf);
    sc_import_result_free(&r);
}

/* The pydicom volumes: stored value at (x, y, z) as write_dicom_pydicom.py documents. */
#define PX 12u
#define PY 10u
#define PZ 8u

static double pydicom_value(uint32_t x, uint32_t y, uint32_t z, int bits, int is_signed)
{
    if (bits == 8) {
        return (double)((7u * x + 13u * y + 29u * z) % 256u);
    }
    const double v = (double)((257u * x + 1031u * y + 4099u * z) % 65536u);
    return is_signed ? v - 32768.0 : v;
}

static void check_pydicom(const char *name, int bits, int is_signed, double slope, double icpt)
{
    char path[300], err[256];
    snprintf(path, sizeof path, "%s/pyd/%s", g_dir, name);
    sc_image img;
    const int rc = sc_image_read(path, &img, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s: %s", path, err);
    }
    assert_int_equal(img.dim[0], PX);
    assert_int_equal(img.dim[1], PY);
    assert_int_equal(img.dim[2], PZ);
    assert_true(fabs(img.spacing[0] - 0.3) < 1e-9 && fabs(img.spacing[1] - 0.5) < 1e-9 &&
                fabs(img.spacing[2] - 0.8) < 1e-9);
    assert_true(fabs(img.origin[2] - 30.0) < 1e-9);
    double lo = INFINITY, hi = -INFINITY;
    for (uint32_t z = 0; z < PZ; z++) {
        for (uint32_t y = 0; y < PY; y++) {
            for (uint32_t x = 0; x < PX; x++) {
                const double want = pydicom_value(x, y, z, bits, is_signed) * slope + icpt;
                const double got = img.data[x + PX * (y + PY * (size_t)z)];
                if (!(fabs(got - want) <= 1e-9 * fabs(want))) {
                    fail_msg("%s: voxel (%u,%u,%u) is %g, want %g", name, x, y, z, got, want);
                }
                lo = got < lo ? got : lo;
                hi = got > hi ? got : hi;
            }
        }
    }
    assert_true(hi > lo); /* not a constant (all-zero) volume */
    sc_image_free(&img);
}

static void series_and_multiframe_by_pydicom_with_and_without_rescale_import_exactly(void **state)
{
    (void)state;
    char cmd[600];
    snprintf(cmd, sizeof cmd,
             "mkdir -p '%s/pyd' && /usr/bin/python3 '%s/tests/casebuild/write_dicom_pydicom.py' "
             "'%s/pyd' >/dev/null",
             g_dir, SC_SOURCE_DIR, g_dir);
    assert_int_equal(system(cmd), 0); /* needs python3-pydicom (tools/install-deps.sh base) */
    /* no Rescale Slope / Intercept: the stored values, as the standard defaults say */
    check_pydicom("series8", 8, 0, 1.0, 0.0);
    check_pydicom("series16", 16, 0, 1.0, 0.0);
    check_pydicom("usmf.dcm", 8, 0, 1.0, 0.0);
    /* present: applied */
    check_pydicom("series16r", 16, 1, 0.5, -20.0);
    /* enhanced: shared Pixel Value Transformation, per-frame positions out of order */
    check_pydicom("enh.dcm", 8, 0, 2.0, -5.0);
    /* refused by name, never a crash: a frame count that would size gigabytes, a single 2D
     * frame, a slice missing from a series, two series in a folder */
    static const struct {
        const char *name, *needle;
        int rc;
    } bad[] = {{"hostile/frames.dcm", "Number of Frames", SC_ERR_NO_SPACE},
               {"hostile/single.dcm", "single 2D frame", SC_ERR_NOT_SUPPORTED},
               {"hostile/gap", "spacing not uniform", SC_ERR_NOT_SUPPORTED},
               {"hostile/mixed", "several series", SC_ERR_NOT_SUPPORTED}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char path[300], err[256] = "";
        snprintf(path, sizeof path, "%s/pyd/%s", g_dir, bad[i].name);
        sc_image img;
        const int rc = sc_image_read(path, &img, err, sizeof err);
        if (rc != bad[i].rc || strstr(err, bad[i].needle) == NULL) {
            fail_msg("%s: %s (%d), want %s", bad[i].name, err, rc, bad[i].needle);
        }
    }
}

static void missing_or_empty_dicom_inputs_are_refused(void **state)
{
    (void)state;
    char d[256], err[256];
    sc_image img;
    snprintf(d, sizeof d, "%s/none.dcm", g_dir);
    assert_int_equal(sc_image_read(d, &img, err, sizeof err), SC_ERR_NOT_FOUND);
    snprintf(d, sizeof d, "%s/emptydir", g_dir);
    assert_int_equal(mkdir(d, 0700), 0);
    assert_int_equal(sc_image_read(d, &img, err, sizeof err), SC_ERR_PARSE);
    snprintf(d, sizeof d, "%s/emptydir/junk.dcm", g_dir);
    FILE *f = fopen(d, "w");
    fputs("not dicom", f);
    fclose(f);
    assert_int_equal(sc_image_read(d, &img, err, sizeof err), SC_ERR_PARSE);
}
#else
static void dicom_without_dcmtk_is_not_supported(void **state)
{
    (void)state;
    char err[256];
    sc_image img;
    assert_int_equal(sc_image_read("/tmp/x.dcm", &img, err, sizeof err), SC_ERR_NOT_SUPPORTED);
}
#endif

static int setup(void **state)
{
    (void)state;
    return sc_test_tmpdir_make(g_dir, sizeof g_dir, "sc_dicom");
}

static int teardown(void **state)
{
    (void)state;
    return sc_test_tmpdir_remove(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
#ifdef SC_HAVE_DCMTK
        cmocka_unit_test(series_of_16_bit_signed_rescaled_oblique_slices),
        cmocka_unit_test(series_of_16_bit_unsigned_rle_compressed_slices),
        cmocka_unit_test(enhanced_multiframe_8_bit_frames_out_of_order),
        cmocka_unit_test(enhanced_multiframe_rle_compressed_imports_into_a_valid_case),
        cmocka_unit_test(series_and_multiframe_by_pydicom_with_and_without_rescale_import_exactly),
        cmocka_unit_test(missing_or_empty_dicom_inputs_are_refused),
#else
        cmocka_unit_test(dicom_without_dcmtk_is_not_supported),
#endif
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
