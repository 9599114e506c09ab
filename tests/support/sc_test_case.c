/* sc_test_case.c: in-memory case files for whole-engine tests, see sc_test_case.h. */
#include "sc_test_case.h"

#include <stdlib.h>
#include <string.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_material.h"

int sc_test_case_make(sc_test_case *tc, uint32_t nx, uint32_t ny, uint32_t nz,
                      uint8_t vein_label, const char *name)
{
    memset(tc, 0, sizeof(*tc));
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = nx;
    p.ny = ny;
    p.nz = nz;
    p.vein_label = vein_label;
    sc_test_scene_build(&tc->scene, &p);

    sc_case_def d = sc_case_default_def();
    d.name = name;
    d.description = "test block: soft vein and stiff artery side by side";
    d.volume = tc->scene.vol;
    sc_material_table mt;
    sc_material_table_default(&mt);
    d.material_count = mt.count;
    for (uint32_t i = 0; i < mt.count; i++) {
        d.materials[i].e_pa = mt.row[i].e_pa;
        d.materials[i].poisson = mt.row[i].poisson;
        d.materials[i].density_kg_m3 = mt.row[i].density_kg_m3;
    }
    d.mesh = tc->scene.mesh;
    d.image_to_probe = sc_xform_identity();
    d.tracker_to_patient = sc_xform_identity();
    d.tracker_to_patient.r[4] = -1.0f; /* half turn about x: tracker Z up */
    d.tracker_to_patient.r[8] = -1.0f;

    const size_t need = sc_case_encoded_size(&d);
    if (need == 0u) {
        return SC_ERR_INVALID_ARG;
    }
    tc->bytes = malloc(need);
    if (!tc->bytes) {
        return SC_ERR_NO_SPACE;
    }
    int rc = sc_case_write(&d, tc->bytes, need, &tc->size);
    if (rc != SC_OK) {
        free(tc->bytes);
        tc->bytes = NULL;
        return rc;
    }
    /* skin points (z = 0 in the volume) in the tracker frame: (x, -y, -z) */
    tc->vein_tracker_mm[0] = p.vein_x_mm;
    tc->vein_tracker_mm[1] = -p.probe_y_mm;
    tc->vein_tracker_mm[2] = 0.0f;
    tc->centre_tracker_mm[0] = p.probe_x_mm;
    tc->centre_tracker_mm[1] = -p.probe_y_mm;
    tc->centre_tracker_mm[2] = 0.0f;
    return SC_OK;
}

sc_engine_def sc_test_engine_def(void)
{
    sc_engine_def d = sc_engine_default_def();
    d.watchdog_timeout_ms = 0;
    d.bscan.scan.lines_n = 64u;
    d.bscan.scan.samples_n = 128u;
    d.bscan.scan.depth_mm = 30.0f;
    d.bscan.scan.width_mm = 36.0f;
    return d;
}
