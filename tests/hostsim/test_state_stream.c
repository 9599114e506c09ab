/* test_state_stream.c: the whole engine's console state stream on the host simulator: about 30
 * periods per simulated second, gap-free sequence, the case's surfaces, a skin surface (embedded
 * in the case's SURF section) that sinks under the probe's press, and zero deadline misses. */
#include "sc_test.h"

#include <stdlib.h>
#include <string.h>

#include "sc_case_surf.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_state.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_mesh g_mesh;
static sc_test_case block;
static uint8_t *g_bytes;
static size_t g_size;

/* ---- what the stream delivered ----------------------------------------------------------- */
static struct {
    uint32_t frames, surf_infos, verts, tris, catalogue, assessments, materials, other;
    uint32_t mat_rows; /* of the last MATERIAL record */
    uint32_t assess_frames, assess_score_max; /* of the last ASSESSMENT record */
    uint32_t last_seq;
    int have_seq;
    uint32_t gaps;
    char name[65];
    float z[SC_MAX_MESH_NX * SC_MAX_MESH_NY]; /* the skin vertices' depth, mm */
    uint32_t nz;
} got;

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static int sink(void *ctx, const uint8_t *rec, uint16_t len)
{
    (void)ctx;
    uint32_t seq = 0;
    const int type = sc_state_check(rec, len, &seq, NULL);
    assert_true(type > 0);
    if (got.have_seq && seq != got.last_seq + 1u) {
        got.gaps++;
    }
    got.have_seq = 1;
    got.last_seq = seq;
    const uint8_t *p = rec + SC_STATE_HEADER_SIZE;
    switch (type) {
    case SC_STATE_FRAME: got.frames++; break;
    case SC_STATE_SURF_INFO:
        got.surf_infos++;
        memcpy(got.name, p + 144, 64);
        break;
    case SC_STATE_VERTS: {
        got.verts++;
        const uint32_t first = rd32(p + 4), n = (uint32_t)p[8] | (uint32_t)p[9] << 8;
        for (uint32_t i = 0; i < n; i++) {
            if (first + i < got.nz) {
                float z;
                memcpy(&z, p + 12 + 12 * i + 8, 4);
                got.z[first + i] = z;
            }
        }
        break;
    }
    case SC_STATE_TRIS: got.tris++; break;
    case SC_STATE_CATALOGUE: got.catalogue++; break;
    case SC_STATE_ASSESSMENT: /* docs/assessment.md: frames at 4, score_max at 98 */
        got.assessments++;
        got.assess_frames = rd32(p + 4);
        got.assess_score_max = p[98];
        break;
    case SC_STATE_MATERIAL: /* docs/state-stream.md: row count at 0 */
        got.materials++;
        got.mat_rows = p[0];
        break;
    default: got.other++; break;
    }
    return SC_OK;
}

static void wr32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* the block case plus a SURF of its mesh's top face: each vertex a top node (weight 1) */
static int group_setup(void **state)
{
    (void)state;
    if (sc_test_case_make(&block, 12, 6, 8, SC_LABEL_VEIN, "block") != SC_OK) {
        return -1;
    }
    sc_case c;
    if (sc_case_load(block.bytes, block.size, &c) != SC_OK || sc_mesh_build(&g_mesh, &c.mesh) != SC_OK) {
        return -1;
    }
    const uint32_t nv = g_mesh.nx * g_mesh.ny, nt = 2u * (g_mesh.nx - 1u) * (g_mesh.ny - 1u);
    const size_t n = (size_t)sc_case_surf_payload_size(1, nv, nt);
    uint8_t *p = calloc(n, 1);
    wr32(p, SC_CASE_SURF_VERSION);
    wr32(p + 4, 1);
    wr32(p + 8, nv);
    wr32(p + 12, nt);
    p[17] = SC_CASE_SURF_SKIN;
    wr32(p + 24, nv);
    wr32(p + 28, nt);
    for (uint32_t v = 0; v < nv; v++) {
        uint8_t *q = p + 32 + 16 * v;
        for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
            int k = -1;
            for (int j = 0; j < 4; j++) {
                k = g_mesh.tet[t][j] == v ? j : k; /* node v: i + nx j at k = 0 */
            }
            if (k >= 0) {
                wr32(q, t);
                const float one = 1.0f, zero = 0.0f;
                for (int j = 0; j < 3; j++) {
                    memcpy(q + 4 + 4 * j, j == k ? &one : &zero, 4);
                }
                break;
            }
        }
    }
    uint8_t *tri = p + 32 + 16 * nv;
    for (uint32_t j = 0, t = 0; j + 1u < g_mesh.ny; j++) {
        for (uint32_t i = 0; i + 1u < g_mesh.nx; i++, t += 2) {
            const uint32_t a = i + g_mesh.nx * j, c2 = a + g_mesh.nx;
            const uint32_t idx[6] = {a, a + 1u, c2, a + 1u, c2 + 1u, c2};
            for (int k = 0; k < 6; k++) {
                wr32(tri + 12 * t + 4 * (uint32_t)k, idx[k]);
            }
        }
    }
    const size_t cap = block.size + 64u + n + 64u;
    g_bytes = malloc(cap);
    memcpy(g_bytes, block.bytes, block.size);
    g_size = block.size;
    const int rc = sc_case_append_section(g_bytes, cap, &g_size, SC_CASE_TAG_SURF_U32, p, n);
    free(p);
    got.nz = nv;
    return rc == SC_OK ? 0 : -1;
}

static int group_teardown(void **state)
{
    (void)state;
    free(block.bytes);
    free(g_bytes);
    return 0;
}

static void run(uint32_t frames, int press)
{
    const uint64_t t0 = rig.clock.now_ns;
    uint64_t next_ns = 0;
    int more = press;
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    for (uint32_t i = 0; i < frames; i++) {
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        while (more && t0 + next_ns <= release) {
            uint64_t t_ns;
            const int k = sc_emu_next(&emu, f, SC_EMU_MAX_FRAMES, &t_ns);
            if (k < 0) {
                more = 0;
                break;
            }
            for (int j = 0; j < k; j++) {
                (void)sc_can_send(&rig.peer, &f[j]);
            }
            next_ns = t_ns + (uint64_t)(1e9 / emu.def.rate_hz);
        }
        sc_engine_step(&rig.engine, NULL);
    }
}

static void stream_carries_the_engine_and_the_skin_sinks_under_the_press(void **state)
{
    (void)state;
    sc_engine_def def = sc_test_engine_def();
    def.tissue.collider = sc_test_scene_collider(&block.scene);
    def.case_names[0] = "block";
    def.case_count = 1;
    assert_int_equal(def.state_period_ms, 33u);
    assert_int_equal(sc_hs_rig_init(&rig, &def, 1, 0), SC_OK);
    static const sc_state_ops ops = {.send = sink};
    rig.hal.state = (sc_state_dev){&ops, NULL};
    assert_int_equal(sc_hs_storage_add(&rig.storage, "block", g_bytes, g_size), SC_OK);
    assert_int_equal(sc_engine_load_case(&rig.engine, "block"), SC_OK);
    memset(&got, 0, offsetof(__typeof__(got), z));
    run(60, 0); /* one simulated second, probe lifted */
    print_message("1 s: %u FRAME, %u SURF_INFO, %u VERTS, %u TRIS, %u CATALOGUE, %u gaps\n",
                  got.frames, got.surf_infos, got.verts, got.tris, got.catalogue, got.gaps);
    assert_true(got.frames >= 29u && got.frames <= 31u); /* 33 ms periods */
    assert_int_equal(got.surf_infos, got.frames);
    assert_int_equal(got.verts, got.frames); /* 72 vertices: one record a period */
    assert_int_equal(got.gaps, 0u);
    assert_int_equal(got.assessments, got.frames); /* the exam's record every period */
    assert_true(got.assess_frames >= 55u && got.assess_frames <= 60u);
    assert_int_equal(got.assess_score_max, sc_engine_assessment(&rig.engine)->score_max);
    assert_int_equal(got.materials, got.frames); /* the running materials every period */
    assert_int_equal(got.mat_rows, rig.engine.slot.c.material_count);
    assert_int_equal(got.other, 0u);
    assert_string_equal(got.name, "block");
    float rest_max = -1e9f;
    for (uint32_t v = 0; v < got.nz; v++) {
        rest_max = got.z[v] > rest_max ? got.z[v] : rest_max;
    }
    /* the press (4.5 mm below the skin): the deepest streamed skin vertex sinks */
    sc_emu_def d = sc_emu_default_def();
    d.script = SC_EMU_PRESS;
    memcpy(d.point_mm, block.centre_tracker_mm, sizeof d.point_mm);
    d.hover_mm = 5.0f;
    d.depth_mm = 4.5f;
    d.duration_s = 2.2;
    assert_int_equal(sc_emu_init(&emu, &d), SC_OK);
    float deepest = -1e9f;
    for (int k = 0; k < 120; k++) {
        run(1, 1);
        for (uint32_t v = 0; v < got.nz; v++) {
            deepest = got.z[v] > deepest ? got.z[v] : deepest;
        }
    }
    print_message("skin: deepest vertex %.2f mm at rest, %.2f mm pressed\n", (double)rest_max,
                  (double)deepest);
    assert_true(deepest > rest_max + 1.0f); /* 1.65 mm on this coarse block (12 x 6 x 8) */
    assert_int_equal(got.gaps, 0u);
    assert_int_equal(sc_engine_get_sched(&rig.engine)->misses, 0u);
    assert_int_equal(sc_engine_get_state_tx(&rig.engine)->records_dropped, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stream_carries_the_engine_and_the_skin_sinks_under_the_press),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
