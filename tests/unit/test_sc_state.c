/* test_sc_state.c: the console state stream's records (core/sc_state.h): header, sequence,
 * rate limit, drops counted, surface vertices carried by the deformed mesh. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_case_surf.h"
#include "sc_err.h"
#include "sc_mesh.h"
#include "sc_state.h"

typedef struct sink {
    uint8_t rec[64][SC_STATE_RECORD_MAX];
    uint16_t len[64];
    int n;
    int refuse;
} sink;

static int sink_send(void *ctx, const uint8_t *rec, uint16_t len)
{
    sink *s = ctx;
    if (s->refuse) {
        return SC_ERR_WOULD_BLOCK;
    }
    if (s->n < 64) {
        memcpy(s->rec[s->n], rec, len);
        s->len[s->n++] = len;
    }
    return SC_OK;
}

static const sc_state_ops k_ops = {.send = sink_send};
static sink g_sink;
static sc_state_tx g_tx;
static sc_mesh g_mesh;
static sc_nodes g_nodes;

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float rdf(const uint8_t *p)
{
    const uint32_t u = rd32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static void wr32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void wrf(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    wr32(p, u);
}

static sc_state_in base_in(uint64_t now)
{
    sc_state_in in;
    memset(&in, 0, sizeof in);
    in.now_ns = now;
    in.frame_no = 7;
    in.gain_db = 12.0f;
    in.vein_area_ratio = 0.25f;
    in.artery_area_ratio = -1.0f;
    return in;
}

static void frame_record_has_header_size_and_fields(void **state)
{
    (void)state;
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 33u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    sc_state_in in = base_in(1000000000u);
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 1u);
    assert_int_equal(g_sink.n, 1);
    const uint8_t *r = g_sink.rec[0];
    assert_int_equal(g_sink.len[0], SC_STATE_HEADER_SIZE + SC_STATE_FRAME_SIZE);
    uint32_t seq = 99, fno = 0;
    assert_int_equal(sc_state_check(r, g_sink.len[0], &seq, &fno), SC_STATE_FRAME);
    assert_int_equal(seq, 0u);
    assert_int_equal(fno, 7u);
    const uint8_t *p = r + SC_STATE_HEADER_SIZE;
    assert_true(rdf(p + 92) > 11.99f && rdf(p + 92) < 12.01f); /* gain */
    assert_true(rdf(p + 56) > 0.249f && rdf(p + 56) < 0.251f); /* vein ratio */
}

/* The ASSESSMENT record carries the report in the layout of docs/assessment.md. */
static void assessment_record_has_the_documented_layout(void **state)
{
    (void)state;
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 33u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    sc_assess_report r;
    memset(&r, 0, sizeof r);
    r.version = SC_ASSESS_REPORT_VERSION;
    r.frames = 321u;
    r.vessel[SC_ASSESS_ARTERY].min_ratio = 0.875f;
    r.vessel[SC_ASSESS_ARTERY].frames_in_view = 40u;
    r.vessel[SC_ASSESS_VEIN].coapted = 1u;
    r.peak_force_n = 21.5f;
    r.call = SC_ASSESS_CALL_DVT;
    r.finding = SC_ASSESS_CALL_NORMAL;
    r.criteria_met = 0x0Fu;
    r.points[4] = 3u;
    r.score = 5u;
    r.score_max = 10u;
    r.artery_punctures = 2u;
    r.vein_punctures = 1u;
    r.puncture_points = 2u;
    r.revision = SC_ASSESS_REPORT_REVISION;
    sc_state_in in = base_in(1000000000u);
    in.assess = &r;
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 2u); /* FRAME, ASSESSMENT */
    const uint8_t *rec = g_sink.rec[1];
    assert_int_equal(g_sink.len[1], SC_STATE_HEADER_SIZE + sizeof(sc_assess_report));
    assert_int_equal(sc_state_check(rec, g_sink.len[1], NULL, NULL), SC_STATE_ASSESSMENT);
    const uint8_t *p = rec + SC_STATE_HEADER_SIZE;
    assert_int_equal(rd32(p + 0), SC_ASSESS_REPORT_VERSION);
    assert_int_equal(rd32(p + 4), 321u);
    assert_true(rdf(p + 20 + 20) > 0.874f && rdf(p + 20 + 20) < 0.876f); /* artery min */
    assert_int_equal(rd32(p + 20 + 20 + 8), 40u);
    assert_int_equal(p[20 + 16], 1u);                                   /* vein coapted */
    assert_true(rdf(p + 80) > 21.49f && rdf(p + 80) < 21.51f);
    assert_int_equal(p[89], SC_ASSESS_CALL_DVT);
    assert_int_equal(p[90], SC_ASSESS_CALL_NORMAL);
    assert_int_equal(p[91], 0x0Fu);
    assert_int_equal(p[96], 3u);
    assert_int_equal(p[97], 5u);
    assert_int_equal(p[98], 10u);
    /* revision 1: the needle's punctures in formerly reserved bytes */
    assert_int_equal(p[99], 2u);
    assert_int_equal(p[100], 1u);
    assert_int_equal(p[101], 2u);
    assert_int_equal(p[102], SC_ASSESS_REPORT_REVISION);
    assert_int_equal(p[103], 0u);
}

/* The MATERIAL record: the running tissue's rows, the solver parameters, the counters. */
static void material_record_has_the_documented_layout(void **state)
{
    (void)state;
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 33u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    sc_material_table mt;
    sc_material_table_default(&mt);
    mt.row[2].e_pa = 700.0f;
    mt.row[2].poisson = 0.4f;
    sc_state_in in = base_in(1000000000u);
    in.mat = &mt;
    in.mat_override_mask = 1u << 2;
    in.mat_sim_override = 1u;
    in.cg_iterations = 20u;
    in.corotated = 1u;
    in.damping_s = 0.2f;
    in.material_rebuilds = 3u;
    in.material_refused = 5u;
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 2u); /* FRAME, MATERIAL */
    const uint8_t *rec = g_sink.rec[1];
    assert_int_equal(g_sink.len[1], SC_STATE_HEADER_SIZE + SC_STATE_MATERIAL_SIZE);
    assert_int_equal(SC_STATE_MATERIAL_SIZE, 160u);
    assert_int_equal(sc_state_check(rec, g_sink.len[1], NULL, NULL), SC_STATE_MATERIAL);
    const uint8_t *p = rec + SC_STATE_HEADER_SIZE;
    assert_int_equal(p[0], mt.count);
    assert_int_equal(p[1], 1u);
    assert_int_equal(p[2], 20u);
    assert_int_equal(p[3], 1u);
    assert_true(rdf(p + 4) > 0.1999f && rdf(p + 4) < 0.2001f);
    assert_int_equal(rd32(p + 8), 4u);
    assert_int_equal(rd32(p + 16), 3u);
    assert_int_equal(rd32(p + 24), 5u);
    assert_float_equal(rdf(p + 32 + 8 * 2), 700.0f, 0.0f);
    assert_float_equal(rdf(p + 32 + 8 * 2 + 4), 0.4f, 0.0f);
    assert_float_equal(rdf(p + 32 + 8 * 3), 15.0e3f, 0.0f); /* muscle: the table's */
    assert_float_equal(rdf(p + 32 + 8 * mt.count), 0.0f, 0.0f); /* rows past the count: 0 */
    /* without a case (no table) there is no MATERIAL record */
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 33u, 4u);
    in.mat = NULL;
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 1u);
}

static void period_limits_the_rate_and_sequence_counts_up(void **state)
{
    (void)state;
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 33u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    sc_state_in in = base_in(1000000000u);
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 1u);
    in.now_ns += 16666667u; /* the next 60 Hz frame: not due */
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 0u);
    in.now_ns += 16666667u; /* 33.3 ms: due */
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 1u);
    uint32_t s0 = 0, s1 = 0;
    assert_true(sc_state_check(g_sink.rec[0], g_sink.len[0], &s0, NULL) > 0);
    assert_true(sc_state_check(g_sink.rec[1], g_sink.len[1], &s1, NULL) > 0);
    assert_int_equal(s1, s0 + 1u);
}

static void refused_records_are_counted_and_leave_a_sequence_gap(void **state)
{
    (void)state;
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 10u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    sc_state_in in = base_in(1000000000u);
    g_sink.refuse = 1;
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 0u);
    assert_int_equal(g_tx.records_dropped, 1u);
    g_sink.refuse = 0;
    in.now_ns += 10000000u;
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 1u);
    uint32_t seq = 0;
    assert_true(sc_state_check(g_sink.rec[0], g_sink.len[0], &seq, NULL) > 0);
    assert_int_equal(seq, 1u); /* the receiver sees record 0 missing */
}

static void period_zero_or_no_device_sends_nothing(void **state)
{
    (void)state;
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 0u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    sc_state_in in = base_in(1000000000u);
    assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 0u);
    sc_state_tx_init(&g_tx, 33u, 4u);
    const sc_state_dev none = {NULL, NULL};
    assert_int_equal(sc_state_emit(&g_tx, &none, &in), 0u);
    assert_int_equal(g_sink.n, 0);
}

static void check_refuses_bad_magic_version_and_length(void **state)
{
    (void)state;
    uint8_t r[SC_STATE_HEADER_SIZE + 4] = {0};
    wr32(r, SC_STATE_MAGIC);
    r[4] = SC_STATE_VERSION;
    r[5] = SC_STATE_FRAME;
    r[6] = 4;
    assert_int_equal(sc_state_check(r, sizeof r, NULL, NULL), SC_STATE_FRAME);
    assert_int_equal(sc_state_check(r, sizeof r - 1u, NULL, NULL), SC_ERR_RANGE);
    r[4] = 2;
    assert_int_equal(sc_state_check(r, sizeof r, NULL, NULL), SC_ERR_RANGE);
    r[4] = SC_STATE_VERSION;
    r[0] ^= 1u;
    assert_int_equal(sc_state_check(r, sizeof r, NULL, NULL), SC_ERR_RANGE);
    assert_int_equal(sc_state_check(r, 3u, NULL, NULL), SC_ERR_INVALID_ARG);
}

static void surface_vertices_follow_the_deformed_mesh(void **state)
{
    (void)state;
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = md.ny = md.nz = 3u;
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    /* a SURF payload: one vessel surface of 2 vertices in tets 0 and 5, one degenerate tri */
    uint8_t p[16 + 16 + 2 * 16 + 12] = {0};
    wr32(p, SC_CASE_SURF_VERSION);
    wr32(p + 4, 1);
    wr32(p + 8, 2);
    wr32(p + 12, 1);
    p[16] = 4;
    p[17] = SC_CASE_SURF_VESSEL;
    wr32(p + 24, 2);
    wr32(p + 28, 1);
    const float w[3] = {0.1f, 0.2f, 0.3f};
    for (int v = 0; v < 2; v++) {
        wr32(p + 32 + 16 * v, v == 0 ? 0u : 5u);
        for (int k = 0; k < 3; k++) {
            wrf(p + 36 + 16 * v + 4 * k, w[k]);
        }
    }
    wr32(p + 64, 0);
    wr32(p + 68, 1);
    wr32(p + 72, 1);
    sc_case c;
    memset(&c, 0, sizeof c);
    c.name = "t";
    assert_int_equal(sc_case_surf_parse(p, sizeof p, g_mesh.tet_count, &c.surf), SC_OK);
    memset(&g_sink, 0, sizeof g_sink);
    sc_state_tx_init(&g_tx, 33u, 4u);
    const sc_state_dev dev = {&k_ops, &g_sink};
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            for (uint32_t n = 0; n < g_mesh.node_count; n++) {
                g_nodes.z[n] += 1.5f; /* the whole mesh 1.5 mm deeper */
            }
        }
        sc_state_in in = base_in(1000000000u + (uint64_t)pass * 100000000u);
        in.c = &c;
        in.mesh = &g_mesh;
        in.x = g_nodes.x;
        in.y = g_nodes.y;
        in.z = g_nodes.z;
        g_sink.n = 0;
        assert_int_equal(sc_state_emit(&g_tx, &dev, &in), 4u); /* FRAME SURF_INFO VERTS TRIS */
        const uint8_t *vr = g_sink.rec[2];
        assert_int_equal(sc_state_check(vr, g_sink.len[2], NULL, NULL), SC_STATE_VERTS);
        const uint8_t *q = vr + SC_STATE_HEADER_SIZE;
        assert_int_equal(rd32(q + 4), 0u);
        assert_int_equal(q[8], 2u);
        const uint32_t *tn = g_mesh.tet[0];
        const float ww[4] = {0.1f, 0.2f, 0.3f, 0.4f};
        float ez = 0.0f;
        for (int k = 0; k < 4; k++) {
            ez += ww[k] * g_nodes.z[tn[k]];
        }
        assert_true(fabsf(rdf(q + 12 + 8) - ez) < 1e-4f);
        const uint8_t *tr = g_sink.rec[3] + SC_STATE_HEADER_SIZE;
        assert_int_equal(sc_state_check(g_sink.rec[3], g_sink.len[3], NULL, NULL), SC_STATE_TRIS);
        assert_int_equal(rd32(tr + 12), 0u);
        assert_int_equal(rd32(tr + 16), 1u);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(frame_record_has_header_size_and_fields),
        cmocka_unit_test(assessment_record_has_the_documented_layout),
        cmocka_unit_test(material_record_has_the_documented_layout),
        cmocka_unit_test(period_limits_the_rate_and_sequence_counts_up),
        cmocka_unit_test(refused_records_are_counted_and_leave_a_sequence_gap),
        cmocka_unit_test(period_zero_or_no_device_sends_nothing),
        cmocka_unit_test(check_refuses_bad_magic_version_and_length),
        cmocka_unit_test(surface_vertices_follow_the_deformed_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
