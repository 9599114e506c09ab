/* test_sc_canproto.c: codec round trips for every message, frame validation, and the codec
 * tables against config/sonocomp.dbc (the protocol's source of truth). */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_err.h"

static uint32_t rng = 12345u;
static uint32_t rnd(void)
{
    rng = rng * 1664525u + 1013904223u;
    return rng >> 8;
}
static float rndf(float lo, float hi)
{
    return lo + (hi - lo) * (float)(rnd() & 0xFFFFu) / 65535.0f;
}

static int e2e_ok(const sc_can_frame *f)
{
    return f->data[0] == sc_e2e_crc((uint16_t)f->id, f->data, f->len);
}

/* ---- pose ------------------------------------------------------------------------------- */

static void pose_round_trip_within_half_a_step_classic_and_fd(void **state)
{
    (void)state;
    for (int it = 0; it < 2000; it++) {
        sc_pose_msg p = {0};
        for (int i = 0; i < 3; i++) {
            p.pos_mm[i] = rndf(-1600.0f, 1600.0f);
        }
        for (int i = 0; i < 4; i++) {
            p.q[i] = rndf(-1.9f, 1.9f);
        }
        p.force_valid = (uint8_t)(it % 3 != 0);
        p.force_n = p.force_valid ? rndf(0.0f, 600.0f) : 0.0f;
        p.tracking = (uint8_t)(it % 5 == 0);
        const uint8_t counter = (uint8_t)(it % 16);
        for (int fd = 0; fd <= 1; fd++) {
            sc_can_frame f[3];
            size_t n = 0;
            assert_int_equal(sc_canproto_encode_pose(&p, counter, fd, f, 3, &n), 0);
            assert_int_equal(n, fd ? 1u : 3u);
            sc_pose_msg d = {0};
            unsigned mask = 0;
            for (size_t k = 0; k < n; k++) {
                assert_true(e2e_ok(&f[k]));
                assert_int_equal(f[k].data[1] & 0x0Fu, counter);
                assert_int_equal(!!(f[k].flags & SC_CAN_FLAG_FD), fd);
                const int part = sc_canproto_decode_pose_part(&f[k], &d);
                assert_true(part > 0);
                mask |= (unsigned)part;
            }
            assert_int_equal(mask, SC_POSE_PARTS_ALL);
            /* half a step, plus float rounding of values up to 1638 (2^-13 relative) */
            for (int i = 0; i < 3; i++) {
                assert_true(fabsf(d.pos_mm[i] - p.pos_mm[i]) <= 0.025f + 1e-3f);
            }
            for (int i = 0; i < 4; i++) {
                assert_true(fabsf(d.q[i] - p.q[i]) <= 0.5f / 16384.0f + 1e-6f);
            }
            assert_int_equal(d.force_valid, p.force_valid);
            if (p.force_valid) {
                assert_true(fabsf(d.force_n - p.force_n) <= 0.005f + 1e-4f);
            }
            assert_int_equal(d.tracking, p.tracking);
            /* decode then encode reproduces the frames bit for bit */
            sc_can_frame g[3];
            size_t m = 0;
            assert_int_equal(sc_canproto_encode_pose(&d, counter, fd, g, 3, &m), 0);
            for (size_t k = 0; k < n; k++) {
                assert_memory_equal(f[k].data, g[k].data, f[k].len);
                assert_int_equal(f[k].id, g[k].id);
            }
        }
    }
}

static void every_raw_value_of_a_16_bit_signal_survives_phys_and_back(void **state)
{
    (void)state;
    const sc_can_msg_info *info = sc_canproto_info(SC_MSG_POSE_POS);
    const sc_can_msg_info *qi = sc_canproto_info(SC_MSG_POSE_QUAT);
    for (int32_t raw = -32768; raw <= 32767; raw++) {
        int64_t back = 0;
        assert_int_equal(sc_canproto_phys_to_raw(
                             &info->sigs[2], sc_canproto_raw_to_phys(&info->sigs[2], raw), &back),
                         0);
        assert_int_equal(back, raw);
        assert_int_equal(sc_canproto_phys_to_raw(&qi->sigs[2],
                                                 sc_canproto_raw_to_phys(&qi->sigs[2], raw), &back),
                         0);
        assert_int_equal(back, raw);
    }
}

static void pose_values_outside_the_fields_are_refused(void **state)
{
    (void)state;
    sc_pose_msg p = {.q = {1.0f, 0.0f, 0.0f, 0.0f}};
    sc_can_frame f[3];
    size_t n;
    p.pos_mm[1] = 2000.0f;
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 3, &n), SC_ERR_CAN_SIGNAL);
    p.pos_mm[1] = NAN;
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 1, f, 3, &n), SC_ERR_NOT_FINITE);
    p.pos_mm[1] = 0.0f;
    p.q[0] = 2.5f;
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 3, &n), SC_ERR_CAN_SIGNAL);
    p.q[0] = 1.0f;
    p.force_valid = 1;
    p.force_n = 655.35f; /* raw 65535 is reserved for "not available" */
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 3, &n), SC_ERR_CAN_SIGNAL);
    p.force_n = 1.0f;
    p.tracking = 2;
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 3, &n), SC_ERR_CAN_SIGNAL);
    p.tracking = 0;
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 2, &n), SC_ERR_NO_SPACE);
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 3, &n), 0);
}

/* ---- commands ------------------------------------------------------------------------------ */

static void every_command_round_trips(void **state)
{
    (void)state;
    sc_cmd cmds[] = {
        {.kind = SC_CMD_SELECT_CASE, .case_id = 0},
        {.kind = SC_CMD_SELECT_CASE, .case_id = 254},
        {.kind = SC_CMD_SET_METHOD, .method = SC_METHOD_MSDS},
        {.kind = SC_CMD_SET_METHOD, .method = SC_METHOD_FEM},
        {.kind = SC_CMD_SET_IMAGING,
         .imaging = {.depth_mm = 60.0f,
                     .gain_db = -12.5f,
                     .dyn_range_db = 60.0f,
                     .tgc_db_per_cm = 1.2f,
                     .geometry = SC_SCAN_LINEAR}},
        {.kind = SC_CMD_SET_IMAGING,
         .imaging = {.depth_mm = 250.0f,
                     .gain_db = 40.0f,
                     .dyn_range_db = 20.0f,
                     .tgc_db_per_cm = 10.0f,
                     .geometry = SC_SCAN_CURVILINEAR}},
        {.kind = SC_CMD_RESET, .reset_target = SC_RESET_TISSUE},
        {.kind = SC_CMD_RESET, .reset_target = SC_RESET_ALL},
        {.kind = SC_CMD_SYNC_FRESHNESS, .fv_high = 0},
        {.kind = SC_CMD_SYNC_FRESHNESS, .fv_high = 0xFEDCBA987654ull}, /* 48 bits, all used */
    };
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        sc_can_frame f;
        assert_int_equal(sc_canproto_encode_cmd(&cmds[i], (uint8_t)i, &f), 0);
        assert_true(e2e_ok(&f));
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), 0);
        assert_int_equal(d.kind, cmds[i].kind);
        assert_int_equal(d.case_id, cmds[i].case_id);
        assert_int_equal(d.method, cmds[i].method);
        assert_int_equal(d.reset_target, cmds[i].reset_target);
        assert_true(d.fv_high == cmds[i].fv_high);
        assert_int_equal(sc_canproto_info(sc_canproto_cmd_msg(d.kind))->can_id, f.id);
        /* tolerance: half a step of each signal (0.05 mm, 0.25 dB, 0.5 dB, 0.05 dB/cm) */
        assert_true(fabsf(d.imaging.depth_mm - cmds[i].imaging.depth_mm) <= 0.05f);
        assert_true(fabsf(d.imaging.gain_db - cmds[i].imaging.gain_db) <= 0.25f);
        assert_true(fabsf(d.imaging.dyn_range_db - cmds[i].imaging.dyn_range_db) <= 0.5f);
        assert_true(fabsf(d.imaging.tgc_db_per_cm - cmds[i].imaging.tgc_db_per_cm) <= 0.05f);
        assert_int_equal(d.imaging.geometry, cmds[i].imaging.geometry);
        sc_can_frame g;
        assert_int_equal(sc_canproto_encode_cmd(&d, (uint8_t)i, &g), 0);
        assert_memory_equal(f.data, g.data, 8);
    }
}

static void commands_outside_their_ranges_are_refused_both_ways(void **state)
{
    (void)state;
    sc_can_frame f;
    sc_cmd c = {.kind = SC_CMD_SELECT_CASE, .case_id = 255};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_CAN_SIGNAL);
    c = (sc_cmd){.kind = SC_CMD_SET_METHOD, .method = 2};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_CAN_SIGNAL);
    c = (sc_cmd){.kind = SC_CMD_RESET, .reset_target = 0};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_CAN_SIGNAL);
    c = (sc_cmd){.kind = SC_CMD_SYNC_FRESHNESS, .fv_high = 1ull << 48};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_CAN_SIGNAL);
    c = (sc_cmd){.kind = SC_CMD_SET_IMAGING,
                 .imaging = {.depth_mm = 5.0f, .gain_db = 0.0f, .dyn_range_db = 60.0f}};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_CAN_SIGNAL);
    c.imaging.depth_mm = 50.0f;
    c.imaging.gain_db = NAN;
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_NOT_FINITE);
    c = (sc_cmd){.kind = (sc_cmd_kind)10}; /* 9 is CmdMaterial */
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_INVALID_ARG);

    /* raw frames from a foreign sender with out-of-range signals */
    const sc_can_msg_info *im = sc_canproto_info(SC_MSG_CMD_IMAGING);
    sc_cmd ok = {.kind = SC_CMD_SET_IMAGING,
                 .imaging = {.depth_mm = 50.0f, .gain_db = 0.0f, .dyn_range_db = 60.0f}};
    struct {
        unsigned sig;
        int64_t raw;
    } bad[] = {{2, 99}, {2, 2501}, {3, 81}, {3, -81}, {4, 19}, {4, 101}, {5, 101}, {6, 2}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(sc_canproto_encode_cmd(&ok, 0, &f), 0);
        sc_canproto_put_raw(f.data, &im->sigs[bad[i].sig], bad[i].raw);
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
    }
    c = (sc_cmd){.kind = SC_CMD_RESET, .reset_target = 1};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), 0);
    f.data[2] = 0;
    sc_cmd d;
    assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
    c = (sc_cmd){.kind = SC_CMD_SELECT_CASE, .case_id = 1};
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), 0);
    f.data[2] = 255;
    assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
}

/* ---- status -------------------------------------------------------------------------------- */

static void status_round_trips_and_saturates(void **state)
{
    (void)state;
    sc_e2e_tx tx[SC_STATUS_FRAMES];
    sc_e2e_tx_init(&tx[0], SC_CANID_STATUS);
    sc_e2e_tx_init(&tx[1], SC_CANID_TIMING);
    sc_e2e_tx_init(&tx[2], SC_CANID_DIAG);
    sc_e2e_tx_init(&tx[3], SC_CANID_AUTH_DIAG);
    sc_status_msg s = {.state = 2,
                       .method = 1,
                       .probe_contact = 1,
                       .probe_lifted = 0,
                       .fault_bits = 0x0A5Au,
                       .deadline_misses = 1234,
                       .case_id = 7,
                       .worst_frame_us = 15321,
                       .vein_area_ratio = 0.25f,
                       .artery_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE,
                       .poses_accepted = 70000,
                       .rejected_e2e = 12,
                       .rejected_plausibility = 300,
                       .lift_events = 3,
                       .cmds_authenticated = 65537,
                       .auth_rejected = 70000,
                       .auth_bad_mac = 9,
                       .auth_stale = 256};
    sc_can_frame f[SC_STATUS_FRAMES];
    assert_int_equal(sc_canproto_encode_status(&s, tx, f), 0);
    sc_status_msg d = {0};
    for (int i = 0; i < (int)SC_STATUS_FRAMES; i++) {
        assert_true(e2e_ok(&f[i]));
        assert_int_equal(sc_canproto_decode_status_part(&f[i], &d), 0);
    }
    assert_int_equal(d.state, 2);
    assert_int_equal(d.method, 1);
    assert_int_equal(d.probe_contact, 1);
    assert_int_equal(d.probe_lifted, 0);
    assert_int_equal(d.fault_bits, 0x0A5Au);
    assert_int_equal(d.deadline_misses, 1234);
    assert_int_equal(d.case_id, 7);
    assert_int_equal(d.worst_frame_us, 15321);
    assert_true(fabsf(d.vein_area_ratio - 0.25f) <= 0.0005f);
    assert_true(d.artery_area_ratio < 0.0f);
    assert_int_equal(d.poses_accepted, 70000u % 65536u); /* documented: modulo 65536 */
    assert_int_equal(d.rejected_e2e, 12);
    assert_int_equal(d.rejected_plausibility, 255); /* saturated to its 8-bit field */
    assert_int_equal(d.lift_events, 3);
    assert_int_equal(d.cmds_authenticated, 1);  /* modulo 65536 */
    assert_int_equal(d.auth_rejected, 65535);   /* saturated */
    assert_int_equal(d.auth_bad_mac, 9);
    assert_int_equal(d.auth_stale, 255);        /* saturated to its 8-bit field */
    assert_int_equal(f[3].id, SC_CANID_AUTH_DIAG);
    /* the sender counters advanced */
    assert_int_equal(tx[0].counter, 1);
    s.deadline_misses = 1000000u;
    s.worst_frame_us = 1000000u;
    assert_int_equal(sc_canproto_encode_status(&s, tx, f), 0);
    assert_int_equal(f[0].data[1] & 0x0Fu, 1);
    for (int i = 0; i < (int)SC_STATUS_FRAMES; i++) {
        assert_int_equal(sc_canproto_decode_status_part(&f[i], &d), 0);
    }
    assert_int_equal(d.deadline_misses, 65535);
    assert_int_equal(d.worst_frame_us, 65535);
    s.state = 4;
    assert_int_equal(sc_canproto_encode_status(&s, tx, f), SC_ERR_CAN_SIGNAL);
    s.state = 1;
    s.vein_area_ratio = INFINITY;
    assert_int_equal(sc_canproto_encode_status(&s, tx, f), SC_ERR_NOT_FINITE);
}

/* ---- frame validation ---------------------------------------------------------------------- */

static void frames_with_unknown_id_wrong_length_or_format_are_classified_as_such(void **state)
{
    (void)state;
    sc_can_frame f = {.id = SC_CANID_POSE_POS, .len = 8};
    sc_msg m;
    assert_int_equal(sc_canproto_classify(&f, &m), 0);
    assert_int_equal(m, SC_MSG_POSE_POS);
    f.len = 7;
    assert_int_equal(sc_canproto_classify(&f, &m), SC_ERR_CAN_DLC);
    f.len = 8;
    f.flags = SC_CAN_FLAG_FD;
    assert_int_equal(sc_canproto_classify(&f, &m), SC_ERR_CAN_DLC);
    f.flags = SC_CAN_FLAG_EXT;
    assert_int_equal(sc_canproto_classify(&f, &m), SC_ERR_CAN_ID);
    f.flags = SC_CAN_FLAG_RTR;
    assert_int_equal(sc_canproto_classify(&f, &m), SC_ERR_CAN_ID);
    f = (sc_can_frame){.id = 0x7FF, .len = 8};
    assert_int_equal(sc_canproto_classify(&f, &m), SC_ERR_CAN_ID);
    f = (sc_can_frame){.id = SC_CANID_POSE_FD, .len = 20};
    assert_int_equal(sc_canproto_classify(&f, &m), SC_ERR_CAN_DLC); /* FD id without FD flag */
    f.flags = SC_CAN_FLAG_FD;
    assert_int_equal(sc_canproto_classify(&f, &m), 0);
    sc_pose_msg p;
    f = (sc_can_frame){.id = SC_CANID_STATUS, .len = 8};
    assert_int_equal(sc_canproto_decode_pose_part(&f, &p), SC_ERR_CAN_ID);
    sc_cmd c;
    assert_int_equal(sc_canproto_decode_cmd(&f, &c), SC_ERR_CAN_ID);
    float phys[SC_CANPROTO_MAX_SIGS];
    assert_int_equal(sc_canproto_decode_phys(&f, &m, phys, 2), SC_ERR_NO_SPACE);
    assert_int_equal(sc_canproto_decode_phys(&f, &m, phys, SC_CANPROTO_MAX_SIGS), 0);
    assert_null(sc_canproto_info(SC_MSG_COUNT));
}

static void signals_of_a_message_do_not_overlap_and_fit_its_length(void **state)
{
    (void)state;
    for (int i = 0; i < (int)SC_MSG_COUNT; i++) {
        const sc_can_msg_info *m = sc_canproto_info((sc_msg)i);
        uint8_t used[64] = {0};
        assert_true(m->sig_count <= SC_CANPROTO_MAX_SIGS);
        assert_true(sc_can_len_valid(m->len, m->fd ? SC_CAN_FLAG_FD : 0));
        for (unsigned s = 0; s < m->sig_count; s++) {
            const sc_can_sig *g = &m->sigs[s];
            assert_true(g->start_bit + g->bits <= m->len * 8u);
            for (unsigned b = g->start_bit; b < (unsigned)(g->start_bit + g->bits); b++) {
                assert_false(used[b / 8u] & (1u << (b % 8u)));
                used[b / 8u] = (uint8_t)(used[b / 8u] | (1u << (b % 8u)));
            }
        }
        if (m->e2e) {
            assert_string_equal(m->sigs[0].name, "E2E_CRC");
            assert_string_equal(m->sigs[1].name, "E2E_Counter");
        } else {
            /* the cryptographic PDUs: id = their command's + 8, 8 bytes, classic */
            assert_true(SC_MSG_IS_AUTH(i));
            assert_int_equal(m->can_id,
                             sc_canproto_info((sc_msg)(i - (int)SC_MSG_AUTH_CASE))->can_id +
                                 SC_CANID_AUTH_OFFSET);
            assert_int_equal(m->len, 8);
            assert_false(m->fd);
        }
        assert_int_equal(m->data_id, m->can_id);
    }
}

/* ---- the DBC file ------------------------------------------------------------------------- */

static int near(double a, double b)
{
    return fabs(a - b) <= 1e-9 * (fabs(a) + fabs(b) + 1.0);
}

static void dbc_file_defines_exactly_the_codec_tables(void **state)
{
    (void)state;
    FILE *fp = fopen(SC_SOURCE_DIR "/config/sonocomp.dbc", "r");
    assert_non_null(fp);
    char line[1024];
    const sc_can_msg_info *cur = NULL;
    unsigned sig_i = 0, msgs = 0, sigs = 0, cycles = 0, dids = 0, touts = 0, fds = 0;
    while (fgets(line, sizeof line, fp)) {
        unsigned id, len, start, bits, v;
        char name[128], order, sign, unit[64];
        double factor, offset, mn, mx;
        if (sscanf(line, "BO_ %u %127[^:]: %u", &id, name, &len) == 3) {
            cur = NULL;
            for (int i = 0; i < (int)SC_MSG_COUNT; i++) {
                if (sc_canproto_info((sc_msg)i)->can_id == id) {
                    cur = sc_canproto_info((sc_msg)i);
                }
            }
            assert_non_null(cur);
            assert_string_equal(cur->name, name);
            assert_int_equal(cur->len, len);
            sig_i = 0;
            msgs++;
        } else if (sscanf(line, " SG_ %127s : %u|%u@%c%c (%lf,%lf) [%lf|%lf] \"%63[^\"]\"", name,
                          &start, &bits, &order, &sign, &factor, &offset, &mn, &mx, unit) >= 9) {
            assert_non_null(cur);
            assert_true(sig_i < cur->sig_count);
            const sc_can_sig *g = &cur->sigs[sig_i++];
            if (!strstr(line, "\"\"")) {
                assert_string_equal(g->unit, unit);
            } else {
                assert_string_equal(g->unit, "");
            }
            assert_string_equal(g->name, name);
            assert_int_equal(g->start_bit, start);
            assert_int_equal(g->bits, bits);
            assert_int_equal(order, '1'); /* Intel */
            assert_int_equal(g->is_signed, sign == '-');
            /* float32 factors: equal to the DBC decimal within float precision */
            assert_true(fabs(g->factor - factor) <= 1e-7 * fabs(factor));
            assert_true(near(g->offset, offset));
            assert_true(fabs(g->min - mn) <= 1e-3 && fabs(g->max - mx) <= 1e-3);
            sigs++;
        } else if (sscanf(line, "BA_ \"GenMsgCycleTime\" BO_ %u %u", &id, &v) == 2) {
            int found = 0;
            for (int i = 0; i < (int)SC_MSG_COUNT; i++) {
                if (sc_canproto_info((sc_msg)i)->can_id == id) {
                    assert_int_equal(sc_canproto_info((sc_msg)i)->cycle_ms, v);
                    found = 1;
                }
            }
            assert_true(found);
            cycles++;
        } else if (sscanf(line, "BA_ \"E2E_DataID\" BO_ %u %u", &id, &v) == 2) {
            assert_int_equal(id, v); /* data ID = CAN id, as the codec uses */
            dids++;
        } else if (sscanf(line, "BA_ \"E2E_TimeoutMs\" BO_ %u %u", &id, &v) == 2) {
            for (int i = 0; i < (int)SC_MSG_COUNT; i++) {
                if (sc_canproto_info((sc_msg)i)->can_id == id) {
                    assert_int_equal(sc_canproto_info((sc_msg)i)->timeout_ms, v);
                }
            }
            touts++;
        } else if (sscanf(line, "BA_ \"VFrameFormat\" BO_ %u %u", &id, &v) == 2) {
            assert_int_equal(v, 14); /* StandardCAN_FD */
            assert_int_equal(id, SC_CANID_POSE_FD);
            fds++;
        }
        if (cur != NULL && strncmp(line, "BO_ ", 4) != 0 && line[0] == '\n') {
            assert_int_equal(sig_i, cur->sig_count); /* every signal of the message listed */
            cur = NULL;
        }
    }
    fclose(fp);
    assert_int_equal(msgs, SC_MSG_COUNT);
    unsigned total = 0, cyclic = 0, timed = 0;
    for (int i = 0; i < (int)SC_MSG_COUNT; i++) {
        total += sc_canproto_info((sc_msg)i)->sig_count;
        cyclic += sc_canproto_info((sc_msg)i)->cycle_ms != 0u;
        timed += sc_canproto_info((sc_msg)i)->timeout_ms != 0u;
    }
    assert_int_equal(sigs, total);
    assert_int_equal(cycles, cyclic);
    unsigned with_e2e = 0;
    for (int i = 0; i < (int)SC_MSG_COUNT; i++) {
        with_e2e += sc_canproto_info((sc_msg)i)->e2e;
    }
    assert_int_equal(with_e2e, SC_MSG_COUNT - SC_CMD_MSGS);
    assert_int_equal(dids, with_e2e);
    assert_int_equal(touts, timed);
    assert_int_equal(fds, 1);
}

/* ---- assessment (0x087, 0x210..0x212) ---------------------------------------------------- */

static void assessment_command_round_trips_and_bad_pairs_are_refused(void **state)
{
    (void)state;
    const uint8_t ok[3][2] = {{SC_ASSESS_ACTION_RESET, SC_ASSESS_CALL_NONE},
                              {SC_ASSESS_ACTION_CALL, SC_ASSESS_CALL_NORMAL},
                              {SC_ASSESS_ACTION_CALL, SC_ASSESS_CALL_DVT}};
    for (int i = 0; i < 3; i++) {
        const sc_cmd c = {.kind = SC_CMD_ASSESS, .assess_action = ok[i][0], .assess_call = ok[i][1]};
        sc_can_frame f;
        assert_int_equal(sc_canproto_encode_cmd(&c, (uint8_t)i, &f), 0);
        assert_int_equal(f.id, 0x087);
        assert_true(e2e_ok(&f));
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), 0);
        assert_int_equal(d.kind, SC_CMD_ASSESS);
        assert_int_equal(d.assess_action, ok[i][0]);
        assert_int_equal(d.assess_call, ok[i][1]);
        /* the DBC's signals (table-driven decode): AssessAction, AssessCall */
        float phys[SC_CANPROTO_MAX_SIGS];
        sc_msg m;
        assert_int_equal(sc_canproto_decode_phys(&f, &m, phys, SC_CANPROTO_MAX_SIGS), 0);
        assert_int_equal(m, SC_MSG_CMD_ASSESS);
        assert_float_equal(phys[2], (float)ok[i][0], 0.0f);
        assert_float_equal(phys[3], (float)ok[i][1], 0.0f);
    }
    /* every other pair: refused by the encoder and, built by hand, by the decoder */
    for (uint8_t a = 0; a < 4u; a++) {
        for (uint8_t k = 0; k < 4u; k++) {
            const int good = (a == 1u && k == 0u) || (a == 2u && (k == 1u || k == 2u));
            if (good) {
                continue;
            }
            const sc_cmd c = {.kind = SC_CMD_ASSESS, .assess_action = a, .assess_call = k};
            sc_can_frame f;
            assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), SC_ERR_CAN_SIGNAL);
            f = (sc_can_frame){.id = 0x087, .len = 8};
            f.data[2] = (uint8_t)(a | (k << 2));
            assert_int_equal(sc_e2e_protect_with(0x087, 0, f.data, f.len), 0);
            sc_cmd d;
            assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
        }
    }
    /* its cryptographic PDU classifies at 0x08F */
    sc_can_frame pdu = {.id = 0x08F, .len = 8};
    sc_msg m;
    assert_int_equal(sc_canproto_classify(&pdu, &m), 0);
    assert_int_equal(m, SC_MSG_AUTH_ASSESS);
    assert_true(SC_MSG_IS_AUTH(m));
    assert_true(SC_MSG_IS_CMD(SC_MSG_CMD_ASSESS));
    assert_false(SC_MSG_IS_AUTH(SC_MSG_ASSESS_VESSELS));
}

/* ---- the vessels' drive (0x085) and the Doppler settings (0x086) --------------------------- */

static void vessels_command_round_trips_and_out_of_range_is_refused(void **state)
{
    (void)state;
    const float hr[] = {30.0f, 72.0f, 200.0f};
    const float rr[] = {0.0f, 15.0f, 40.0f};
    for (int i = 0; i < 3; i++) {
        sc_cmd c = {.kind = SC_CMD_VESSELS};
        c.vessels = (sc_vessels_cmd){hr[i], rr[i], (uint8_t)(i & 1), (uint8_t)((i >> 1) & 1)};
        sc_can_frame f;
        assert_int_equal(sc_canproto_encode_cmd(&c, (uint8_t)i, &f), 0);
        assert_int_equal(f.id, 0x085);
        assert_true(e2e_ok(&f));
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), 0);
        assert_int_equal(d.kind, SC_CMD_VESSELS);
        assert_float_equal(d.vessels.heart_rate_bpm, hr[i], 0.0f);
        assert_float_equal(d.vessels.resp_rate_bpm, rr[i], 0.0f);
        assert_int_equal(d.vessels.valsalva, i & 1);
        assert_int_equal(d.vessels.pulse, (i >> 1) & 1);
        float phys[SC_CANPROTO_MAX_SIGS];
        sc_msg m;
        assert_int_equal(sc_canproto_decode_phys(&f, &m, phys, SC_CANPROTO_MAX_SIGS), 0);
        assert_int_equal(m, SC_MSG_CMD_VESSELS);
        assert_float_equal(phys[2], hr[i], 0.0f);
        assert_float_equal(phys[3], rr[i], 0.0f);
    }
    /* refused by the encoder: heart rate 29 / 201, breathing 41, a NaN, Valsalva 2 */
    const sc_vessels_cmd bad[] = {{29.0f, 12.0f, 0, 1}, {201.0f, 12.0f, 0, 1},
                                  {72.0f, 41.0f, 0, 1}, {NAN, 12.0f, 0, 1},
                                  {72.0f, 12.0f, 2, 1}, {72.0f, 12.0f, 0, 3}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sc_cmd c = {.kind = SC_CMD_VESSELS};
        c.vessels = bad[i];
        sc_can_frame f;
        assert_true(sc_canproto_encode_cmd(&c, 0, &f) != 0);
    }
    /* refused by the decoder: a frame built by hand with heart rate 250, then breathing 60 */
    const uint8_t raw[2][2] = {{250u, 12u}, {72u, 60u}};
    for (int i = 0; i < 2; i++) {
        sc_can_frame f = {.id = 0x085, .len = 8};
        f.data[2] = raw[i][0];
        f.data[3] = raw[i][1];
        assert_int_equal(sc_e2e_protect_with(0x085, 0, f.data, f.len), 0);
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
    }
    sc_can_frame pdu = {.id = 0x08D, .len = 8};
    sc_msg m;
    assert_int_equal(sc_canproto_classify(&pdu, &m), 0);
    assert_int_equal(m, SC_MSG_AUTH_VESSELS);
    assert_true(SC_MSG_IS_AUTH(m));
    assert_true(SC_MSG_IS_CMD(SC_MSG_CMD_VESSELS));
    assert_int_equal(sc_canproto_cmd_msg(SC_CMD_VESSELS), SC_MSG_CMD_VESSELS);
}

static void doppler_command_round_trips_and_out_of_range_is_refused(void **state)
{
    (void)state;
    const sc_doppler_cmd ok[] = {{1u, 100.0f, -30.0f, -30.0f},
                                 {0u, 4000.0f, 0.0f, 0.0f},
                                 {1u, 20000.0f, 30.0f, 30.0f},
                                 {1u, 2500.0f, -12.0f, 4.5f}};
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        sc_cmd c = {.kind = SC_CMD_DOPPLER};
        c.doppler = ok[i];
        sc_can_frame f;
        assert_int_equal(sc_canproto_encode_cmd(&c, (uint8_t)i, &f), 0);
        assert_int_equal(f.id, 0x086);
        assert_true(e2e_ok(&f));
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), 0);
        assert_int_equal(d.kind, SC_CMD_DOPPLER);
        assert_int_equal(d.doppler.on, ok[i].on);
        assert_float_equal(d.doppler.prf_hz, ok[i].prf_hz, 0.0f);
        assert_float_equal(d.doppler.steer_deg, ok[i].steer_deg, 0.0f);
        assert_float_equal(d.doppler.gain_db, ok[i].gain_db, 0.0f);
    }
    const sc_doppler_cmd bad[] = {{1u, 99.0f, 0.0f, 0.0f},   {1u, 20001.0f, 0.0f, 0.0f},
                                  {1u, 4000.0f, 31.0f, 0.0f}, {1u, 4000.0f, -31.0f, 0.0f},
                                  {1u, 4000.0f, 0.0f, 30.5f}, {1u, 4000.0f, 0.0f, NAN},
                                  {2u, 4000.0f, 0.0f, 0.0f}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sc_cmd c = {.kind = SC_CMD_DOPPLER};
        c.doppler = bad[i];
        sc_can_frame f;
        assert_true(sc_canproto_encode_cmd(&c, 0, &f) != 0);
    }
    /* by hand: PRF 50 Hz (raw 50), steering 100 deg, gain -64 dB: each refused alone */
    for (int i = 0; i < 3; i++) {
        sc_can_frame f = {.id = 0x086, .len = 8};
        f.data[2] = 1u;
        f.data[3] = (uint8_t)(4000u & 0xFFu);
        f.data[4] = (uint8_t)(4000u >> 8);
        if (i == 0) {
            f.data[3] = 50u;
            f.data[4] = 0u;
        } else if (i == 1) {
            f.data[5] = 100u;
        } else {
            f.data[6] = 0x80u; /* -128 * 0.5 dB */
        }
        assert_int_equal(sc_e2e_protect_with(0x086, 0, f.data, f.len), 0);
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
    }
    sc_can_frame pdu = {.id = 0x08E, .len = 8};
    sc_msg m;
    assert_int_equal(sc_canproto_classify(&pdu, &m), 0);
    assert_int_equal(m, SC_MSG_AUTH_DOPPLER);
    assert_int_equal(sc_canproto_cmd_msg(SC_CMD_DOPPLER), SC_MSG_CMD_DOPPLER);
}

/* ---- CmdMaterial (0x090, MAC 0x098) ------------------------------------------------------ */

static sc_material_cmd material_ok(void)
{
    return (sc_material_cmd){.label = 2u, .cg_iterations = 10u, .corotated = 0u,
                             .e_kpa = 3.5f, .poisson = 0.45f, .damping_s = 0.1f};
}

static void material_command_round_trips_within_half_a_step(void **state)
{
    (void)state;
    const sc_material_cmd ok[] = {
        {1u, 1u, 0u, 0.1f, 0.0f, 0.01f},      /* every lower bound */
        {7u, 63u, 1u, 6553.4f, 0.49f, 0.5f},  /* every upper bound */
        {2u, 10u, 0u, 3.5f, 0.45f, 0.1f},     /* the default fat and Algorithm 1's damping */
        {4u, 20u, 1u, 0.15f, 0.3f, 0.25f},    /* vein filler */
        {3u, 33u, 0u, 1234.5f, 0.333f, 0.037f},
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        sc_cmd c = {.kind = SC_CMD_MATERIAL};
        c.material = ok[i];
        sc_can_frame f;
        assert_int_equal(sc_canproto_encode_cmd(&c, (uint8_t)i, &f), 0);
        assert_int_equal(f.id, 0x090);
        assert_int_equal(f.len, 8);
        assert_true(e2e_ok(&f));
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), 0);
        assert_int_equal(d.kind, SC_CMD_MATERIAL);
        assert_int_equal(d.material.label, ok[i].label);
        assert_int_equal(d.material.cg_iterations, ok[i].cg_iterations);
        assert_int_equal(d.material.corotated, ok[i].corotated);
        /* half a step: 0.05 kPa, 0.001, 0.001 s */
        assert_true(fabsf(d.material.e_kpa - ok[i].e_kpa) <= 0.05f + 1e-3f);
        assert_true(fabsf(d.material.poisson - ok[i].poisson) <= 0.001f + 1e-6f);
        assert_true(fabsf(d.material.damping_s - ok[i].damping_s) <= 0.001f + 1e-6f);
        sc_can_frame g;
        assert_int_equal(sc_canproto_encode_cmd(&d, (uint8_t)i, &g), 0);
        assert_memory_equal(f.data, g.data, 8);
    }
    sc_can_frame pdu = {.id = 0x098, .len = 8};
    sc_msg m;
    assert_int_equal(sc_canproto_classify(&pdu, &m), 0);
    assert_int_equal(m, SC_MSG_AUTH_MATERIAL);
    assert_true(SC_MSG_IS_AUTH(m));
    assert_true(SC_MSG_IS_CMD(SC_MSG_CMD_MATERIAL));
    assert_int_equal(sc_canproto_cmd_msg(SC_CMD_MATERIAL), SC_MSG_CMD_MATERIAL);
    assert_int_equal(sc_canproto_info(SC_MSG_AUTH_MATERIAL)->can_id,
                     sc_canproto_info(SC_MSG_CMD_MATERIAL)->can_id + SC_CANID_AUTH_OFFSET);
    /* the rest of the second block is not the protocol's (the flood test's ids among them) */
    for (uint32_t id = 0x091; id <= 0x09F; id++) {
        if (id == 0x098) {
            continue;
        }
        sc_can_frame x = {.id = id, .len = 8};
        assert_int_equal(sc_canproto_classify(&x, &m), SC_ERR_CAN_ID);
    }
}

static void material_command_out_of_range_is_refused_both_ways(void **state)
{
    (void)state;
    /* encoder: each field out of range alone */
    sc_material_cmd bad[12];
    for (size_t i = 0; i < 12u; i++) {
        bad[i] = material_ok();
    }
    bad[0].label = 0u;       /* outside */
    bad[1].label = 8u;       /* bone */
    bad[2].cg_iterations = 0u;
    bad[3].cg_iterations = 64u;
    bad[4].corotated = 2u;
    bad[5].e_kpa = 0.04f;    /* rounds to raw 0 */
    bad[6].e_kpa = 6553.6f;  /* above the range */
    bad[7].e_kpa = -1.0f;
    bad[8].poisson = 0.5f;
    bad[9].damping_s = 0.0f;
    bad[10].damping_s = 0.52f;
    bad[11].e_kpa = NAN;
    for (size_t i = 0; i < 12u; i++) {
        sc_cmd c = {.kind = SC_CMD_MATERIAL};
        c.material = bad[i];
        sc_can_frame f;
        const int rc = sc_canproto_encode_cmd(&c, 0, &f);
        assert_int_equal(rc, i == 11u ? SC_ERR_NOT_FINITE : SC_ERR_CAN_SIGNAL);
    }
    /* decoder: a valid frame with one raw field out of range, from a foreign sender */
    const sc_can_msg_info *mi = sc_canproto_info(SC_MSG_CMD_MATERIAL);
    struct {
        unsigned sig;
        int64_t raw;
    } raw_bad[] = {{2, 0},   {2, 8},   {2, 15},  {3, 0},   {5, 0},
                   {6, 246}, {6, 255}, {7, 0},   {7, 4},   {7, 251}};
    for (size_t i = 0; i < sizeof raw_bad / sizeof raw_bad[0]; i++) {
        sc_cmd c = {.kind = SC_CMD_MATERIAL};
        c.material = material_ok();
        sc_can_frame f;
        assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), 0);
        sc_canproto_put_raw(f.data, &mi->sigs[raw_bad[i].sig], raw_bad[i].raw);
        assert_int_equal(sc_e2e_protect_with(0x090, 0, f.data, f.len), 0);
        sc_cmd d;
        assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_SIGNAL);
    }
    /* wrong length, FD flag */
    sc_cmd c = {.kind = SC_CMD_MATERIAL};
    c.material = material_ok();
    sc_can_frame f;
    assert_int_equal(sc_canproto_encode_cmd(&c, 0, &f), 0);
    f.len = 7;
    sc_cmd d;
    assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_DLC);
    f.len = 8;
    f.flags = SC_CAN_FLAG_FD;
    assert_int_equal(sc_canproto_decode_cmd(&f, &d), SC_ERR_CAN_DLC);
}

static void assessment_frames_decode_as_the_dbc_says(void **state)
{
    (void)state;
    sc_e2e_tx tx[SC_ASSESS_FRAMES];
    for (unsigned i = 0; i < SC_ASSESS_FRAMES; i++) {
        sc_e2e_tx_init(&tx[i], (uint16_t)(0x210u + i));
    }
    for (int it = 0; it < 500; it++) {
        sc_assess_msg a = {0};
        for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
            a.min_ratio[v] = (it + (int)v) % 7 == 0 ? -1.0f : rndf(0.0f, 1.3f);
            a.force_at_min_n[v] = (it + (int)v) % 5 == 0 ? -1.0f : rndf(0.0f, 200.0f);
            a.coapted[v] = (uint8_t)(rnd() & 1u);
        }
        a.peak_force_n = it % 11 == 0 ? -1.0f : rndf(0.0f, 650.0f);
        a.artery_over = (uint8_t)(rnd() & 1u);
        a.call = (uint8_t)(rnd() % 3u);
        a.finding = (uint8_t)(1u + rnd() % 2u);
        a.criteria_met = (uint8_t)(rnd() & 0x1Fu);
        a.score = (uint8_t)(rnd() % 9u);
        a.score_max = 8u;
        sc_can_frame f[SC_ASSESS_FRAMES];
        assert_int_equal(sc_canproto_encode_assess(&a, tx, f), 0);
        sc_assess_msg d;
        memset(&d, 0x55, sizeof d);
        for (unsigned i = 0; i < SC_ASSESS_FRAMES; i++) {
            assert_int_equal(f[i].id, 0x210u + i);
            assert_int_equal(f[i].len, 8);
            assert_true(e2e_ok(&f[i]));
            assert_int_equal(sc_canproto_decode_assess_part(&f[i], &d), 0);
            /* the DBC's scaling, applied by the table-driven decoder */
            float phys[SC_CANPROTO_MAX_SIGS];
            sc_msg m;
            assert_int_equal(sc_canproto_decode_phys(&f[i], &m, phys, SC_CANPROTO_MAX_SIGS), 0);
            assert_int_equal(m, (sc_msg)(SC_MSG_ASSESS_VESSELS + i));
            if (i == 2u) {
                assert_float_equal(phys[7], (float)a.call, 0.0f);       /* TraineeCall */
                assert_float_equal(phys[8], (float)a.finding, 0.0f);    /* CaseFinding */
                assert_float_equal(phys[9], (float)a.criteria_met, 0.0f);
                assert_float_equal(phys[10], (float)a.score, 0.0f);
                assert_float_equal(phys[11], (float)a.score_max, 0.0f);
            } else {
                const float *want = i == 0u ? a.min_ratio : a.force_at_min_n;
                for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
                    if (want[v] >= 0.0f) {
                        const float step = i == 0u ? 0.001f : 0.01f;
                        assert_float_equal(phys[2u + v], want[v], 0.5f * step + 1e-4f);
                    } else {
                        assert_float_equal(phys[2u + v], 65535.0f * (i == 0u ? 0.001f : 0.01f),
                                           0.01f);
                    }
                }
            }
        }
        for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
            if (a.min_ratio[v] < 0.0f) {
                assert_true(d.min_ratio[v] < 0.0f);
            } else {
                assert_float_equal(d.min_ratio[v], a.min_ratio[v], 0.0006f);
            }
            if (a.force_at_min_n[v] < 0.0f) {
                assert_true(d.force_at_min_n[v] < 0.0f);
            } else {
                assert_float_equal(d.force_at_min_n[v], a.force_at_min_n[v], 0.006f);
            }
            assert_int_equal(d.coapted[v], a.coapted[v]);
        }
        if (a.peak_force_n < 0.0f) {
            assert_true(d.peak_force_n < 0.0f);
        } else {
            assert_float_equal(d.peak_force_n, a.peak_force_n, 0.006f);
        }
        assert_int_equal(d.artery_over, a.artery_over);
        assert_int_equal(d.call, a.call);
        assert_int_equal(d.finding, a.finding);
        assert_int_equal(d.criteria_met, a.criteria_met);
        assert_int_equal(d.score, a.score);
        assert_int_equal(d.score_max, a.score_max);
    }
    /* refused: a call or finding out of range, a non-finite value; another message */
    sc_assess_msg bad = {.call = 3u};
    sc_can_frame f[SC_ASSESS_FRAMES];
    assert_int_equal(sc_canproto_encode_assess(&bad, tx, f), SC_ERR_CAN_SIGNAL);
    bad = (sc_assess_msg){.peak_force_n = NAN};
    assert_int_equal(sc_canproto_encode_assess(&bad, tx, f), SC_ERR_NOT_FINITE);
    const sc_can_frame status = {.id = 0x200, .len = 8};
    sc_assess_msg d;
    assert_int_equal(sc_canproto_decode_assess_part(&status, &d), SC_ERR_CAN_ID);
    /* a ratio above the field is sent as its maximum */
    sc_assess_msg big = {.min_ratio = {100.0f, 0.5f, 0.5f}, .finding = 1u};
    assert_int_equal(sc_canproto_encode_assess(&big, tx, f), 0);
    assert_int_equal(sc_canproto_decode_assess_part(&f[0], &d), 0);
    assert_float_equal(d.min_ratio[0], 65.534f, 0.001f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(assessment_command_round_trips_and_bad_pairs_are_refused),
        cmocka_unit_test(assessment_frames_decode_as_the_dbc_says),
        cmocka_unit_test(pose_round_trip_within_half_a_step_classic_and_fd),
        cmocka_unit_test(every_raw_value_of_a_16_bit_signal_survives_phys_and_back),
        cmocka_unit_test(pose_values_outside_the_fields_are_refused),
        cmocka_unit_test(every_command_round_trips),
        cmocka_unit_test(commands_outside_their_ranges_are_refused_both_ways),
        cmocka_unit_test(status_round_trips_and_saturates),
        cmocka_unit_test(frames_with_unknown_id_wrong_length_or_format_are_classified_as_such),
        cmocka_unit_test(signals_of_a_message_do_not_overlap_and_fit_its_length),
        cmocka_unit_test(dbc_file_defines_exactly_the_codec_tables),
        cmocka_unit_test(vessels_command_round_trips_and_out_of_range_is_refused),
        cmocka_unit_test(doppler_command_round_trips_and_out_of_range_is_refused),
        cmocka_unit_test(material_command_round_trips_within_half_a_step),
        cmocka_unit_test(material_command_out_of_range_is_refused_both_ways),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
