/* test_casebuild_reconstruct.c: freehand reconstruction from a synthetic tracked sweep through
 * a known phantom (an analytic intensity field in the tracker frame): a PLUS sequence file is
 * written at test time (rocking probe, one frame marked INVALID with a wrong pose), read,
 * reconstructed with nearest and trilinear splatting, compared with the field; a sparse sweep
 * exercises hole filling; `import` refuses the sequence by pointing to `reconstruct`. */
#include "sc_test.h"
#include "sc_test_tmpdir.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sc_caseimport.h"
#include "sc_err.h"
#include "sc_reconstruct.h"

#define W  48u
#define H  40u
#define NF 61u
#define PX 0.5 /* mm per pixel */

static char g_dir[256];

/* the phantom: grey level at tracker point p (mm) */
static double field(const double p[3])
{
    double v = 120.0 + 50.0 * sin(p[0] / 4.0) + 40.0 * cos(p[1] / 5.0) + 2.0 * p[2];
    return v < 0.0 ? 0.0 : (v > 255.0 ? 255.0 : v);
}

/* probe pose of frame k: image x -> tracker x, image y (depth) -> tracker -z, rocking about
 * the image x axis by 4 degrees, translated along tracker y from -7.5 to +7.5 mm */
static void pose(uint32_t k, double m[16])
{
    const double th = 4.0 * M_PI / 180.0 * sin((double)k / 6.0);
    const double c = cos(th), s = sin(th);
    /* R = Rx(th) * [ex, -ez, ey] */
    const double r[9] = {1, 0, 0, 0, s, c, 0, -c, s};
    memset(m, 0, 16 * sizeof(double));
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            m[i * 4 + j] = r[i * 3 + j];
        }
    }
    m[3] = -12.0;
    m[7] = -7.5 + 0.25 * (double)k;
    m[11] = 1.0;
    m[15] = 1.0;
}

/* write the sweep (every `step`-th frame) as NAME, frames stored in PLUS orientation `orient`
 * (MF: as acquired; UN: mirrored both ways) */
static void write_sweep_as(const char *name, uint32_t step, const char *orient, char *path,
                           size_t n)
{
    snprintf(path, n, "%s/%s", g_dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    const uint32_t nf = (NF - 1u) / step + 1u + 1u; /* + the invalid frame */
    fprintf(f,
            "ObjectType = Image\nNDims = 3\nAnatomicalOrientation = RAI\nBinaryData = True\n"
            "BinaryDataByteOrderMSB = False\nCompressedData = False\nDimSize = %u %u %u\n"
            "ElementNumberOfChannels = 1\nElementSpacing = %g %g 1\nElementType = MET_UCHAR\n"
            "Kinds = domain domain list\nUltrasoundImageOrientation = %s\n"
            "UltrasoundImageType = BRIGHTNESS\n",
            W, H, nf, PX, PX, orient);
    uint32_t fi = 0;
    for (uint32_t k = 0; k < NF; k += step, fi++) {
        double m[16];
        pose(k, m);
        fprintf(f, "Seq_Frame%04u_FrameNumber = %u\nSeq_Frame%04u_ProbeToTrackerTransform =", fi, k,
                fi);
        for (int i = 0; i < 16; i++) {
            fprintf(f, " %.17g", m[i]);
        }
        fprintf(f,
                "\nSeq_Frame%04u_ProbeToTrackerTransformStatus = OK\n"
                "Seq_Frame%04u_Timestamp = %.3f\n",
                fi, fi, 0.05 * k);
    }
    /* a frame whose tracking was lost: a wrong pose 50 mm away, status INVALID */
    fprintf(f,
            "Seq_Frame%04u_ProbeToTrackerTransform = 1 0 0 50 0 1 0 50 0 0 1 50 0 0 0 1\n"
            "Seq_Frame%04u_ProbeToTrackerTransformStatus = INVALID\n",
            fi, fi);
    fprintf(f, "ElementDataFile = LOCAL\n");
    static uint8_t px[W * H];
    for (uint32_t k = 0; k < NF; k += step) {
        double m[16];
        pose(k, m);
        for (uint32_t v = 0; v < H; v++) {
            for (uint32_t u = 0; u < W; u++) {
                const double iu = PX * u, iv = PX * v,
                             p[3] = {
                                 m[0] * iu + m[1] * iv + m[3],
                                 m[4] * iu + m[5] * iv + m[7],
                                 m[8] * iu + m[9] * iv + m[11],
                             };
                const uint32_t su = orient[0] == 'U' ? W - 1u - u : u;
                const uint32_t sv = orient[1] == 'N' ? H - 1u - v : v;
                px[sv * W + su] = (uint8_t)lrint(field(p));
            }
        }
        assert_int_equal(fwrite(px, 1, sizeof px, f), sizeof px);
    }
    memset(px, 255, sizeof px); /* the invalid frame's pixels: would show if used */
    assert_int_equal(fwrite(px, 1, sizeof px, f), sizeof px);
    assert_int_equal(fclose(f), 0);
}

static void write_sweep(const char *name, uint32_t step, char *path, size_t n)
{
    write_sweep_as(name, step, "MF", path, n);
}

typedef struct err_stats {
    double mean, max;
    uint64_t n;
} err_stats;

/* compare the reconstruction with the field inside the swept slab (away from its edges) */
static err_stats compare(const sc_image *v)
{
    err_stats e = {0.0, 0.0, 0u};
    double sum = 0.0;
    for (uint32_t l = 0; l < v->dim[2]; l++) {
        for (uint32_t j = 0; j < v->dim[1]; j++) {
            for (uint32_t i = 0; i < v->dim[0]; i++) {
                const double p[3] = {v->origin[0] + v->spacing[0] * i,
                                     v->origin[1] + v->spacing[1] * j,
                                     v->origin[2] + v->spacing[2] * l};
                if (p[0] < -11.0 || p[0] > 10.5 || p[1] < -5.0 || p[1] > 5.0 || p[2] < -17.5 ||
                    p[2] > 0.0) {
                    continue;
                }
                const double d =
                    fabs(v->data[i + v->dim[0] * ((size_t)j + (size_t)v->dim[1] * l)] - field(p));
                sum += d;
                e.max = d > e.max ? d : e.max;
                e.n++;
            }
        }
    }
    e.mean = e.n ? sum / (double)e.n : 1e9;
    return e;
}

static void sweep_reconstructs_the_phantom_within_stated_error(void **state)
{
    (void)state;
    char path[512], err[256];
    write_sweep("sweep.igs.mha", 1u, path, sizeof path);
    sc_plus_seq seq;
    int rc = sc_plusseq_read(path, NULL, NULL, &seq, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    assert_int_equal(seq.frames.dim[2], NF + 1u);
    assert_int_equal(seq.valid_count, NF); /* the INVALID frame is left out */
    for (int trilinear = 0; trilinear < 2; trilinear++) {
        sc_recon_opts o = sc_recon_default_opts();
        o.trilinear = trilinear;
        sc_image v;
        sc_recon_stats st;
        rc = sc_reconstruct(&seq, &o, &v, &st, err, sizeof err);
        if (rc != SC_OK) {
            fail_msg("%s", err);
        }
        const err_stats e = compare(&v);
        print_message("%s splatting: %u x %u x %u voxels, %.1f%% filled, %.2f%% hole-filled; "
                      "error vs the phantom over %llu voxels: mean %.3f, max %.2f grey levels\n",
                      trilinear ? "trilinear" : "nearest", v.dim[0], v.dim[1], v.dim[2],
                      100.0 * (double)st.filled / (double)st.voxels,
                      100.0 * (double)st.hole_filled / (double)st.voxels, (unsigned long long)e.n,
                      e.mean, e.max);
        /* the bounds stated in docs/case-format.md (measured: nearest mean 0.256, max 1.21;
         * trilinear mean 0.150, max 0.66 grey levels) */
        assert_true(e.n > 10000u);
        assert_true(e.mean < (trilinear ? 0.25 : 0.4));
        assert_true(e.max < (trilinear ? 1.2 : 2.0));
        /* the INVALID frame's 50 mm pose did not widen the grid */
        assert_true(v.origin[0] > -13.0 && v.origin[1] > -9.0);
        assert_true(v.origin[0] + v.spacing[0] * v.dim[0] < 13.0);
        /* the beam goes down the tracker's -z */
        assert_true(st.beam_dir[2] < -0.99);
        sc_image_free(&v);
    }
    sc_plusseq_free(&seq);
}

static void frames_stored_in_another_orientation_read_as_mf(void **state)
{
    (void)state;
    char path[512], err[256];
    write_sweep_as("un.igs.mha", 1u, "UN", path, sizeof path);
    sc_plus_seq seq;
    int rc = sc_plusseq_read(path, NULL, NULL, &seq, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    assert_true(seq.flip_u && seq.flip_v);
    sc_recon_opts o = sc_recon_default_opts();
    sc_image v;
    sc_recon_stats st;
    assert_int_equal(sc_reconstruct(&seq, &o, &v, &st, err, sizeof err), SC_OK);
    const err_stats e = compare(&v);
    print_message("UN-stored sweep: mean error %.3f, max %.2f; beam [%.2f %.2f %.2f]\n", e.mean,
                  e.max, st.beam_dir[0], st.beam_dir[1], st.beam_dir[2]);
    assert_true(e.mean < 0.25 && e.max < 1.2); /* as the MF sweep */
    assert_true(st.beam_dir[2] < -0.99);
    sc_image_free(&v);
    sc_plusseq_free(&seq);
    write_sweep_as("xx.igs.mha", 4u, "XF", path, sizeof path);
    assert_int_equal(sc_plusseq_read(path, NULL, NULL, &seq, err, sizeof err),
                     SC_ERR_NOT_SUPPORTED);
    assert_non_null(strstr(err, "UltrasoundImageOrientation"));
}

static void sparse_sweep_holes_are_filled(void **state)
{
    (void)state;
    char path[512], err[256];
    write_sweep("sparse.igs.mha", 4u, path, sizeof path); /* a frame every 1 mm */
    sc_plus_seq seq;
    int rc = sc_plusseq_read(path, NULL, NULL, &seq, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    sc_recon_opts o = sc_recon_default_opts();
    o.trilinear = 0;
    o.fill_passes = 0;
    sc_image v;
    sc_recon_stats st0, st;
    assert_int_equal(sc_reconstruct(&seq, &o, &v, &st0, err, sizeof err), SC_OK);
    const err_stats e0 = compare(&v); /* holes read as 0 */
    sc_image_free(&v);
    o.fill_passes = 3;
    assert_int_equal(sc_reconstruct(&seq, &o, &v, &st, err, sizeof err), SC_OK);
    const err_stats e = compare(&v);
    print_message("sparse sweep: %.1f%% filled, %.1f%% hole-filled; mean error %.3f without "
                  "filling, %.3f with (max %.2f)\n",
                  100.0 * (double)st.filled / (double)st.voxels,
                  100.0 * (double)st.hole_filled / (double)st.voxels, e0.mean, e.mean, e.max);
    assert_true(st.hole_filled > 0u);
    assert_true(e0.mean > 10.0); /* the holes are there without filling */
    assert_true(e.mean < 1.0);   /* measured 0.706, max 4.48 */
    assert_true(e.max < 6.0);
    sc_image_free(&v);
    sc_plusseq_free(&seq);
}

static void import_refuses_a_sequence_and_the_volume_imports(void **state)
{
    (void)state;
    char path[512], err[512];
    write_sweep("seq.igs.mha", 2u, path, sizeof path);
    sc_image img;
    assert_int_equal(sc_image_read(path, &img, err, sizeof err), SC_ERR_NOT_SUPPORTED);
    assert_non_null(strstr(err, "reconstruct"));
    /* a transform name that the file does not have, and a malformed matrix */
    sc_plus_seq seq;
    assert_int_equal(sc_plusseq_read(path, NULL, "ProbeToReference", &seq, err, sizeof err),
                     SC_ERR_PARSE);
    assert_non_null(strstr(err, "ProbeToReferenceTransform"));
    /* the reconstruction, written and imported with depth along the beam */
    assert_int_equal(sc_plusseq_read(path, NULL, NULL, &seq, err, sizeof err), SC_OK);
    sc_recon_opts o = sc_recon_default_opts();
    sc_image v;
    sc_recon_stats st;
    assert_int_equal(sc_reconstruct(&seq, &o, &v, &st, err, sizeof err), SC_OK);
    char mha[600];
    snprintf(mha, sizeof mha, "%s/recon.mha", g_dir);
    assert_int_equal(sc_image_write_mha(&v, mha), SC_OK);
    sc_import_opts io = sc_import_default_opts();
    io.volume_path = mha;
    io.depth_axis = "-k";
    io.mesh_nodes[0] = io.mesh_nodes[1] = io.mesh_nodes[2] = 4;
    sc_import_result r;
    const int rc = sc_import_case(&io, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    assert_int_equal(r.frame_axis[2], 2);
    assert_int_equal(r.frame_sign[2], -1);
    size_t need = sc_case_encoded_size(&r.def), n = 0;
    uint8_t *buf = malloc(need);
    assert_int_equal(sc_case_write(&r.def, buf, need, &n), SC_OK);
    sc_case c;
    assert_int_equal(sc_case_load(buf, n, &c), SC_OK);
    free(buf);
    sc_import_result_free(&r);
    sc_image_free(&v);
    sc_plusseq_free(&seq);
    /* the command line: reconstruct builds a case; import refuses the sequence (exit 1) */
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "'%s/tools/casebuild/sc-casebuild' reconstruct --sequence '%s' -o '%s/r.scase' "
             "--mesh-nodes 4,4,4 --splat nearest > '%s/r.log' 2>&1 && "
             "grep -q 'z (depth) = -k' '%s/r.log' && "
             "'%s/tools/casebuild/sc-casebuild' verify '%s/r.scase' > /dev/null",
             SC_BINARY_DIR, path, g_dir, g_dir, g_dir, SC_BINARY_DIR, g_dir);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "'%s/tools/casebuild/sc-casebuild' import --volume '%s' -o '%s/i.scase' 2>&1 | "
             "grep -q 'sc-casebuild reconstruct'",
             SC_BINARY_DIR, path, g_dir);
    assert_int_equal(system(cmd), 0);
}

static int setup(void **state)
{
    (void)state;
    return sc_test_tmpdir_make(g_dir, sizeof g_dir, "sc_recon");
}

static int teardown(void **state)
{
    (void)state;
    return sc_test_tmpdir_remove(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sweep_reconstructs_the_phantom_within_stated_error),
        cmocka_unit_test(frames_stored_in_another_orientation_read_as_mf),
        cmocka_unit_test(sparse_sweep_holes_are_filled),
        cmocka_unit_test(import_refuses_a_sequence_and_the_volume_imports),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
