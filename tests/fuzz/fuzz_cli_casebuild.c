/* fuzz_cli_casebuild.c: sc-casebuild's import and reconstruct options (parse_import_opt in
 * tools/casebuild/sc_casebuild_main.c, the parser both subcommands share and the largest of the
 * program's) take any argument vector, pair by pair as cmd_import reads it, never crash, and
 * leave every option they accept within the ranges the importer then relies on. The other
 * subcommands parse their few options inline beside the work (files read and written), so they
 * are not run here; tests/casebuild/casebuild_cli.sh holds their refusals. */
#define _GNU_SOURCE
#include "sc_fuzz_argv.h"

#include <math.h>

#define main casebuild_main
#include "../../tools/casebuild/sc_casebuild_main.c"
#undef main

static int finite_all(const float *v, int n)
{
    for (int i = 0; i < n; i++) {
        if (!isfinite(v[i]) || fabsf(v[i]) > 1e6f) {
            return 0;
        }
    }
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_argv av;
    sc_fuzz_argv_split(data, size, "sc-casebuild", &av);
    sc_import_opts o = sc_import_default_opts();
    const sc_import_opts d = o;
    const char *out = NULL;
    int rc = 0;
    sc_fuzz_quiet(1);
    for (int i = 1; i + 1 < av.argc && rc == 0; i += 2) {
        rc = parse_import_opt(av.argv[i], av.argv[i + 1], &o, &out);
        SC_FUZZ_CHECK(rc == 0 || rc == 1 || rc == 2);
    }
    sc_fuzz_quiet(0);
    if (rc == 0) {
        SC_FUZZ_CHECK(memcmp(&o.spacing_mm, &d.spacing_mm, sizeof o.spacing_mm) == 0 ||
                      (o.spacing_mm >= 0.01f && o.spacing_mm <= 50.0f));
        if (o.has_window) {
            SC_FUZZ_CHECK(isfinite(o.window_lo) && isfinite(o.window_hi));
            SC_FUZZ_CHECK(o.window_hi > o.window_lo);
        }
        SC_FUZZ_CHECK(o.mesh_nodes[0] >= 2u && o.mesh_nodes[0] <= SC_MAX_MESH_NX);
        SC_FUZZ_CHECK(o.mesh_nodes[1] >= 2u && o.mesh_nodes[1] <= SC_MAX_MESH_NY);
        SC_FUZZ_CHECK(o.mesh_nodes[2] >= 2u && o.mesh_nodes[2] <= SC_MAX_MESH_NZ);
        SC_FUZZ_CHECK(o.limits.max_voxels >= 1u && o.limits.max_voxels <= SC_MAX_VOLUME_VOXELS);
        SC_FUZZ_CHECK(o.limits.allow_data_path == 0 || o.limits.allow_data_path == 1);
        SC_FUZZ_CHECK(finite_all(o.image_to_probe.r, 9) && finite_all(o.image_to_probe.t_mm, 3));
        SC_FUZZ_CHECK(finite_all(o.tracker_to_patient.r, 9) &&
                      finite_all(o.tracker_to_patient.t_mm, 3));
        SC_FUZZ_CHECK(!o.has_mesh_box || finite_all(o.mesh_box_mm, 6));
        /* the vessel drive options: what the case loader accepts (sc_case_drive.h) */
        SC_FUZZ_CHECK(!o.has_drive || sc_lumen_drive_validate(&o.drive) == SC_OK);
    }
    sc_fuzz_argv_free(&av);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const lines[] = {
        "--volume|v.nrrd|--labels|l.nrrd|-o|c.scase|--label-map|2=vein,3=artery,*=muscle",
        "--volume|v.mha|--spacing|0.5|--window|-100:400|--mesh-nodes|24,12,12|--max-voxels|1000",
        "--volume|d|--depth-axis|-j|--lateral-axis|R|--allow-data-path|yes|--name|n",
        "--registration|1,0,0,0,-1,0,0,0,-1,0,0,0|--calibration|1,0,0,0,1,0,0,0,1,0,0,0",
        "--mesh-box|0,0,0,40,20,30|--description|d|-o|x.scase",
        "--window|nan:inf|--spacing|1e-30|--mesh-nodes|-1,2,2",
        "--heart-rate|80|--pulse-kpa|5.5|--waveform|sine|--breathing|14|--venous-swing-kpa|0.4",
        "--valsalva-kpa|12|--heart-rate|19|--breathing|0|--pulse-kpa|nan|--waveform|square",
    };
    return sc_fuzz_argv_seed(lines, sizeof lines / sizeof lines[0], i, buf, cap);
}
