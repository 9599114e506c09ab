/* test_casebuild_frame.c: the case frame (depth axis from the file's patient frame or the
 * options, permuted and flipped exactly), the default registration (the tracker emulator's
 * frame), label maps (--label-map, refusals by name) and the mesh box derived from the labels.
 * Fixtures are written at test time into a temporary directory. */
#include "sc_test.h"
#include "sc_test_tmpdir.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sc_caseimport.h"
#include "sc_err.h"
#include "sc_labels.h"

#define DX 7u
#define DY 5u
#define DZ 4u
#define N  (DX * DY * DZ)

static char g_dir[256];
static uint8_t g_vox[N];

static void path_of(char *p, size_t n, const char *name)
{
    snprintf(p, n, "%s/%s", g_dir, name);
}

static void write_file(const char *name, const char *hdr, const void *data, size_t dn)
{
    char p[512];
    path_of(p, sizeof p, name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(hdr, 1, strlen(hdr), f), strlen(hdr));
    if (dn) {
        assert_int_equal(fwrite(data, 1, dn, f), dn);
    }
    assert_int_equal(fclose(f), 0);
}

/* a distinct value per source voxel */
static uint8_t src_value(uint32_t i, uint32_t j, uint32_t k)
{
    return (uint8_t)(1u + i + DX * (j + DY * k));
}

static void fill_source(void)
{
    for (uint32_t k = 0; k < DZ; k++) {
        for (uint32_t j = 0; j < DY; j++) {
            for (uint32_t i = 0; i < DX; i++) {
                g_vox[i + DX * (j + DY * k)] = src_value(i, j, k);
            }
        }
    }
}

static int import(const char *vol, const char *depth, const char *lateral, sc_import_result *r,
                  char *err, size_t errlen)
{
    char pv[512];
    path_of(pv, sizeof pv, vol);
    sc_import_opts o = sc_import_default_opts();
    o.volume_path = pv;
    o.depth_axis = depth;
    o.lateral_axis = lateral;
    o.mesh_nodes[0] = o.mesh_nodes[1] = o.mesh_nodes[2] = 2;
    return sc_import_case(&o, r, err, errlen);
}

/* case voxel (x, y, z) must be source voxel (axis/sign mapping); every voxel checked */
static void check_permutation(const sc_import_result *r, const int axis[3], const int sign[3])
{
    const uint32_t sd[3] = {DX, DY, DZ};
    for (int c = 0; c < 3; c++) {
        assert_int_equal(r->frame_axis[c], axis[c]);
        assert_int_equal(r->frame_sign[c], sign[c]);
        assert_int_equal(r->def.volume.dim[c], sd[axis[c]]);
    }
    const uint32_t *d = r->def.volume.dim;
    for (uint32_t z = 0; z < d[2]; z++) {
        for (uint32_t y = 0; y < d[1]; y++) {
            for (uint32_t x = 0; x < d[0]; x++) {
                const uint32_t q[3] = {x, y, z};
                uint32_t s[3];
                for (int c = 0; c < 3; c++) {
                    s[axis[c]] = sign[c] > 0 ? q[c] : sd[axis[c]] - 1u - q[c];
                }
                const uint8_t got = r->voxels[x + d[0] * (y + d[1] * z)];
                const uint8_t want = src_value(s[0], s[1], s[2]);
                if (got != want) {
                    fail_msg("case voxel (%u,%u,%u) is %u, want %u", x, y, z, got, want);
                }
            }
        }
    }
    /* a valid case: the frame is right-handed */
    size_t need = sc_case_encoded_size(&r->def), n = 0;
    uint8_t *buf = malloc(need);
    assert_int_equal(sc_case_write(&r->def, buf, need, &n), SC_OK);
    sc_case cs;
    assert_int_equal(sc_case_load(buf, n, &cs), SC_OK);
    free(buf);
}

static void nrrd_ras_space_puts_posterior_depth_on_case_z(void **state)
{
    (void)state;
    fill_source();
    char hdr[512];
    /* RAS world, grid i -> right, j -> anterior, k -> superior: posterior is -j */
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nspace: right-anterior-superior\n"
             "sizes: %u %u %u\nspace directions: (0.5,0,0) (0,0.5,0) (0,0,0.5)\n"
             "space origin: (10,20,30)\nencoding: raw\n\n",
             DX, DY, DZ);
    write_file("ras.nrrd", hdr, g_vox, N);
    sc_import_result r;
    char err[256];
    int rc = import("ras.nrrd", NULL, NULL, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    /* depth P = -j, lateral R = +i, y = z x x = +k (superior) */
    check_permutation(&r, (const int[]){0, 2, 1}, (const int[]){1, 1, -1});
    /* the world is converted to LPS: case z is +y (posterior), case x is -x (right); the
     * origin (10, 20, 30) RAS is (-10, -20, 30) LPS */
    assert_true(fabsf(r.def.orientation[1 * 3 + 2] - 1.0f) < 1e-6f);
    assert_true(fabsf(r.def.orientation[0 * 3 + 0] + 1.0f) < 1e-6f);
    /* case origin: x along R from 10, y along S from 30, z along P: LPS y of j = 4, -22 */
    assert_true(fabsf(r.def.volume.origin_mm[0] - 10.0f) < 1e-5f);
    assert_true(fabsf(r.def.volume.origin_mm[1] - 30.0f) < 1e-5f);
    assert_true(fabsf(r.def.volume.origin_mm[2] + 22.0f) < 1e-5f);
    sc_import_result_free(&r);
}

static void metaimage_anatomical_orientation_alone_gives_the_grid_directions(void **state)
{
    (void)state;
    fill_source();
    char hdr[512];
    /* ITK's RAI: i toward Left, j toward Posterior, k toward Superior (LPS identity) */
    snprintf(hdr, sizeof hdr,
             "ObjectType = Image\nNDims = 3\nDimSize = %u %u %u\nElementSpacing = 1 1 1\n"
             "AnatomicalOrientation = RAI\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
             DX, DY, DZ);
    write_file("rai.mha", hdr, g_vox, N);
    sc_import_result r;
    char err[256];
    int rc = import("rai.mha", NULL, NULL, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    /* depth P = +j, lateral R = -i, y = j x -i = +k */
    check_permutation(&r, (const int[]){0, 2, 1}, (const int[]){-1, 1, 1});
    sc_import_result_free(&r);
    /* "SLP": i toward Inferior, j toward Right, k toward Anterior: depth P = -k */
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nAnatomicalOrientation = SLP\n"
             "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
             DX, DY, DZ);
    write_file("slp.mha", hdr, g_vox, N);
    rc = import("slp.mha", NULL, NULL, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    assert_int_equal(r.frame_axis[2], 2);
    assert_int_equal(r.frame_sign[2], -1);
    assert_int_equal(r.frame_axis[0], 1); /* right = +j */
    assert_int_equal(r.frame_sign[0], 1);
    sc_import_result_free(&r);
    snprintf(hdr, sizeof hdr,
             "NDims = 3\nDimSize = %u %u %u\nAnatomicalOrientation = RRI\n"
             "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
             DX, DY, DZ);
    write_file("rri.mha", hdr, g_vox, N);
    rc = import("rri.mha", NULL, NULL, &r, err, sizeof err);
    assert_int_equal(rc, SC_ERR_PARSE);
    assert_non_null(strstr(err, "AnatomicalOrientation"));
}

static void depth_and_lateral_options_permute_and_flip_exactly(void **state)
{
    (void)state;
    fill_source();
    char hdr[512];
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\nencoding: raw\n\n", DX, DY, DZ);
    write_file("plain.nrrd", hdr, g_vox, N);
    sc_import_result r;
    char err[256];
    /* no patient frame: depth +k, lateral +i, the source order */
    assert_int_equal(import("plain.nrrd", NULL, NULL, &r, err, sizeof err), SC_OK);
    check_permutation(&r, (const int[]){0, 1, 2}, (const int[]){1, 1, 1});
    sc_import_result_free(&r);
    /* depth -i (skin at the last column), lateral +k: y = -i x k = +j */
    assert_int_equal(import("plain.nrrd", "-i", "+k", &r, err, sizeof err), SC_OK);
    check_permutation(&r, (const int[]){2, 1, 0}, (const int[]){1, 1, -1});
    sc_import_result_free(&r);
    /* depth along i: the default lateral is +j */
    assert_int_equal(import("plain.nrrd", "+i", NULL, &r, err, sizeof err), SC_OK);
    check_permutation(&r, (const int[]){1, 2, 0}, (const int[]){1, 1, 1});
    sc_import_result_free(&r);
    /* refusals, by option */
    assert_int_equal(import("plain.nrrd", "P", NULL, &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_non_null(strstr(err, "no patient frame"));
    assert_int_equal(import("plain.nrrd", "+q", NULL, &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_non_null(strstr(err, "--depth-axis"));
    assert_int_equal(import("plain.nrrd", "+j", "-j", &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_non_null(strstr(err, "--lateral-axis"));
}

static void left_handed_grid_becomes_a_right_handed_case(void **state)
{
    (void)state;
    fill_source();
    char hdr[512];
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\n"
             "space dimension: 3\nspace directions: (1,0,0) (0,1,0) (0,0,-1)\nencoding: raw\n\n",
             DX, DY, DZ);
    write_file("lh.nrrd", hdr, g_vox, N);
    sc_import_result r;
    char err[256];
    int rc = import("lh.nrrd", NULL, NULL, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    /* z = +k (world -z), x = +i, y = z x x = -world y = -j */
    check_permutation(&r, (const int[]){0, 1, 2}, (const int[]){1, -1, 1});
    sc_import_result_free(&r);
}

static void default_registration_is_the_tracker_emulator_frame_at_the_box_top(void **state)
{
    (void)state;
    fill_source();
    char hdr[512];
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nspace: LPS\nsizes: %u %u %u\n"
             "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (-40,100,-300)\n"
             "encoding: raw\n\n",
             DX, DY, DZ);
    write_file("reg.nrrd", hdr, g_vox, N);
    sc_import_result r;
    char err[256];
    int rc = import("reg.nrrd", NULL, NULL, &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    size_t need = sc_case_encoded_size(&r.def), n = 0;
    uint8_t *buf = malloc(need);
    assert_int_equal(sc_case_write(&r.def, buf, need, &n), SC_OK);
    sc_case cs;
    assert_int_equal(sc_case_load(buf, n, &cs), SC_OK);
    /* tracker -> volume: (x, y, z) -> (x, -y, -z) as the phantoms (tracker Z up) */
    const float want[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
    for (int i = 0; i < 9; i++) {
        assert_true(fabsf(cs.tracker_to_volume.r[i] - want[i]) < 1e-5f);
    }
    /* the tracker origin is the top centre of the mesh box */
    const float top[3] = {cs.mesh.origin_mm[0] + 0.5f * cs.mesh.size_mm[0],
                          cs.mesh.origin_mm[1] + 0.5f * cs.mesh.size_mm[1], cs.mesh.origin_mm[2]};
    for (int a = 0; a < 3; a++) {
        assert_true(fabsf(cs.tracker_to_volume.t_mm[a] - top[a]) < 1e-3f);
    }
    /* a probe 5 mm above that point (tracker +Z) is above the skin in the volume (smaller z) */
    const float p_trk[3] = {0.0f, 0.0f, 5.0f};
    float p_vol[3];
    sc_xform_apply(&cs.tracker_to_volume, p_trk, p_vol);
    assert_true(fabsf(p_vol[2] - (top[2] - 5.0f)) < 1e-3f);
    free(buf);
    sc_import_result_free(&r);
}

/* labels: a 12 x 6 x 10 grid, outside in the top 2 rows of depth, bone from k = 8, a "vein"
 * (source value 20) and an "artery" (30) at k = 4..5, the rest 10 (soft tissue) */
#define LX 12u
#define LY 6u
#define LZ 10u
static uint8_t g_lab[LX * LY * LZ], g_lv[LX * LY * LZ];

static void write_labelled(int bone_value, int outside_value)
{
    for (uint32_t k = 0; k < LZ; k++) {
        for (uint32_t j = 0; j < LY; j++) {
            for (uint32_t i = 0; i < LX; i++) {
                uint8_t v = 10;
                if (k < 2u) {
                    v = (uint8_t)outside_value;
                } else if (k >= 8u) {
                    v = (uint8_t)bone_value;
                } else if (k >= 4u && k <= 5u && i >= 2u && i <= 3u) {
                    v = 20;
                } else if (k >= 4u && k <= 5u && i >= 7u && i <= 8u) {
                    v = 30;
                }
                g_lab[i + LX * (j + LY * k)] = v;
                g_lv[i + LX * (j + LY * k)] = (uint8_t)(v * 3u);
            }
        }
    }
    char hdr[512];
    snprintf(hdr, sizeof hdr,
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: %u %u %u\nspacings: 0.5 0.5 0.5\n"
             "encoding: raw\n\n",
             LX, LY, LZ);
    write_file("lab.nrrd", hdr, g_lab, sizeof g_lab);
    write_file("lvol.nrrd", hdr, g_lv, sizeof g_lv);
}

static int import_labels(const char *map, sc_import_result *r, char *err, size_t errlen)
{
    char pv[512], pl[512];
    path_of(pv, sizeof pv, "lvol.nrrd");
    path_of(pl, sizeof pl, "lab.nrrd");
    sc_import_opts o = sc_import_default_opts();
    o.volume_path = pv;
    o.labels_path = pl;
    o.label_map = map;
    o.mesh_nodes[0] = o.mesh_nodes[1] = o.mesh_nodes[2] = 3;
    return sc_import_case(&o, r, err, errlen);
}

static void label_map_names_source_values_and_refuses_unknowns(void **state)
{
    (void)state;
    write_labelled(40, 0);
    sc_import_result r;
    char err[256];
    int rc = import_labels("0=outside,10=muscle,20=vein,30=artery,40=bone", &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    const uint8_t want_of[41] = {[0] = SC_LABEL_OUTSIDE,
                                 [10] = SC_LABEL_MUSCLE,
                                 [20] = SC_LABEL_VEIN,
                                 [30] = SC_LABEL_ARTERY,
                                 [40] = SC_LABEL_BONE};
    for (size_t i = 0; i < sizeof g_lab; i++) {
        assert_int_equal(r.labels[i], want_of[g_lab[i]]);
    }
    assert_int_equal(r.label_voxels[SC_LABEL_VEIN], 2u * 2u * LY);
    assert_int_equal(r.label_voxels[SC_LABEL_NERVE], 0u);
    sc_import_result_free(&r);
    /* "*" covers the rest */
    rc = import_labels("20=vein,30=artery,40=bone,*=fat", &r, err, sizeof err);
    assert_int_equal(rc, SC_OK);
    assert_int_equal(r.labels[0], SC_LABEL_FAT);
    sc_import_result_free(&r);
    /* refusals: an unknown name, a value without an entry, malformed, no map and value 40 */
    assert_int_equal(import_labels("20=vien", &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_non_null(strstr(err, "vien"));
    assert_int_equal(import_labels("0=outside,10=muscle,20=vein,30=artery", &r, err, sizeof err),
                     SC_ERR_CASE_LABEL);
    assert_non_null(strstr(err, "40"));
    assert_int_equal(import_labels("20:vein", &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_int_equal(import_labels("256=vein", &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_int_equal(import_labels("20=vein,20=artery", &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_int_equal(import_labels("20=vein,", &r, err, sizeof err), SC_ERR_INVALID_ARG);
    assert_int_equal(import_labels(NULL, &r, err, sizeof err), SC_ERR_CASE_LABEL);
    assert_non_null(strstr(err, "--label-map"));
}

static void mesh_box_is_derived_from_skin_to_bone(void **state)
{
    (void)state;
    write_labelled(40, 0);
    sc_import_result r;
    char err[256];
    int rc = import_labels("0=outside,10=muscle,20=vein,30=artery,40=bone", &r, err, sizeof err);
    if (rc != SC_OK) {
        fail_msg("%s", err);
    }
    assert_true(r.mesh_box_derived);
    /* x, y: all columns; top: k = 2 (1 mm); bottom: the bone top k = 8 (4 mm) */
    const float want[6] = {0.0f, 0.0f, 1.0f, 5.5f, 2.5f, 3.0f};
    for (int a = 0; a < 3; a++) {
        assert_true(fabsf(r.def.mesh.origin_mm[a] - want[a]) < 1e-5f);
        assert_true(fabsf(r.def.mesh.size_mm[a] - want[3 + a]) < 1e-5f);
    }
    sc_import_result_free(&r);
    /* no bone: down to the volume's bottom */
    rc = import_labels("0=outside,10=muscle,20=vein,30=artery,40=fat", &r, err, sizeof err);
    assert_int_equal(rc, SC_OK);
    assert_true(fabsf(r.def.mesh.size_mm[2] - 3.5f) < 1e-5f);
    sc_import_result_free(&r);
    /* nothing but outside: no box can be derived, named */
    rc = import_labels("*=outside", &r, err, sizeof err);
    assert_int_equal(rc, SC_ERR_CASE_MESH_BOX);
    assert_non_null(strstr(err, "--mesh-box"));
}

static int setup(void **state)
{
    (void)state;
    return sc_test_tmpdir_make(g_dir, sizeof g_dir, "sc_frame");
}

static int teardown(void **state)
{
    (void)state;
    return sc_test_tmpdir_remove(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(nrrd_ras_space_puts_posterior_depth_on_case_z),
        cmocka_unit_test(metaimage_anatomical_orientation_alone_gives_the_grid_directions),
        cmocka_unit_test(depth_and_lateral_options_permute_and_flip_exactly),
        cmocka_unit_test(left_handed_grid_becomes_a_right_handed_case),
        cmocka_unit_test(default_registration_is_the_tracker_emulator_frame_at_the_box_top),
        cmocka_unit_test(label_map_names_source_values_and_refuses_unknowns),
        cmocka_unit_test(mesh_box_is_derived_from_skin_to_bone),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
