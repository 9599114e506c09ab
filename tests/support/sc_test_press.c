/* sc_test_press.c: see sc_test_press.h. */
#include "sc_test_press.h"

#include "sc_test.h"

#include <math.h>

#include "sc_engine.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_bscan.h"

void sc_test_press_rig_up(sc_hs_rig *rig, sc_storage_linux *storage, const char *cases_dir,
                          const char *case_file, sc_tissue_method m)
{
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0;
    def.case_names[0] = case_file;
    def.case_count = 1u;
    def.tissue.method = m;
    assert_int_equal(sc_hs_rig_init(rig, &def, 1u, 0), SC_OK);
    sc_storage_linux_init(storage, cases_dir);
    rig->hal.storage = sc_storage_linux_dev(storage);
    const int rc = sc_engine_load_case(&rig->engine, case_file);
    if (rc != SC_OK) {
        print_message("case %s/%s: %s (build the `cases` target)\n", cases_dir, case_file,
                      sc_err_str(rc));
    }
    assert_int_equal(rc, SC_OK);
    assert_int_equal(sc_test_press_tissue(rig)->method, m);
}

void sc_test_press_remesh(sc_hs_rig *rig, uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_tissue *t = sc_test_press_tissue(rig);
    const sc_lumen_drive drive = t->lumen.drive;
    sc_tissue_def td = t->def;
    td.mesh.nx = nx;
    td.mesh.ny = ny;
    td.mesh.nz = nz;
    const sc_material_table mat = t->mat;
    assert_int_equal(sc_tissue_init(t, &td, &rig->engine.slot.c.volume, &mat,
                                    (uint8_t)SC_LABEL_FAT),
                     SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&rig->engine.bscan, &t->mesh), SC_OK);
    assert_int_equal(sc_tissue_set_drive(t, &drive), SC_OK);
}

static int send_peer(void *ctx, const sc_can_frame *f)
{
    return sc_can_send((const sc_can_dev *)ctx, f);
}

void sc_test_press_frame(sc_hs_rig *rig, sc_emu *emu, uint64_t t0, int *more)
{
    if (*more && sc_emu_feed(emu, sc_engine_next_release_ns(&rig->engine) - t0, send_peer,
                             &rig->peer) == SC_ERR_NOT_FOUND) {
        *more = 0;
    }
    sc_engine_step(&rig->engine, NULL);
}

sc_tissue *sc_test_press_tissue(sc_hs_rig *rig)
{
    return &rig->engine.tissue[rig->engine.active];
}

int sc_test_press_state_finite(sc_hs_rig *rig)
{
    const sc_tissue *t = sc_test_press_tissue(rig);
    const sc_nodes *n = &t->nodes;
    for (uint32_t i = 0; i < t->mesh.node_count; i++) {
        if (!isfinite(n->x[i]) || !isfinite(n->y[i]) || !isfinite(n->z[i]) ||
            !isfinite(n->vx[i]) || !isfinite(n->vy[i]) || !isfinite(n->vz[i])) {
            return 0;
        }
    }
    return 1;
}

float sc_test_press_max_dev_mm(sc_hs_rig *rig)
{
    const sc_tissue *t = sc_test_press_tissue(rig);
    float m = 0.0f;
    for (uint32_t i = 0; i < t->mesh.node_count; i++) {
        const float dx = t->nodes.x[i] - t->mesh.rest_x[i];
        const float dy = t->nodes.y[i] - t->mesh.rest_y[i];
        const float dz = t->nodes.z[i] - t->mesh.rest_z[i];
        m = fmaxf(m, sqrtf(dx * dx + dy * dy + dz * dz));
    }
    return m;
}
