/* test_gw_msg.c: the console gateway's client messages (tools/gateway/gw_msg.h): each command
 * the CAN protocol defines parses to that command; malformed, unknown, out-of-range and
 * over-long messages are refused with a reason. */
#include "sc_test.h"

#include <stdio.h>
#include <string.h>

#include "gw_msg.h"

static int parse(const char *s, gw_msg *m, const char **why)
{
    return gw_msg_parse(s, strlen(s), m, why);
}

static void each_protocol_command_parses(void **state)
{
    (void)state;
    gw_msg m;
    const char *why = NULL;
    assert_int_equal(parse("{\"op\":\"case\",\"id\":2}", &m, &why), 0);
    assert_int_equal(m.cmd.kind, SC_CMD_SELECT_CASE);
    assert_int_equal(m.cmd.case_id, 2);
    assert_int_equal(parse(" {\"value\" : \"fem\", \"op\":\"method\"} ", &m, &why), 0);
    assert_int_equal(m.cmd.kind, SC_CMD_SET_METHOD);
    assert_int_equal(m.cmd.method, SC_METHOD_FEM);
    assert_int_equal(parse("{\"op\":\"imaging\",\"depth_mm\":45,\"gain_db\":-3.5,\"dyn_range_db\":70,"
                           "\"tgc_db_per_cm\":1.5,\"geometry\":\"curvilinear\"}", &m, &why), 0);
    assert_int_equal(m.cmd.kind, SC_CMD_SET_IMAGING);
    assert_true(m.cmd.imaging.gain_db < -3.49f && m.cmd.imaging.gain_db > -3.51f);
    assert_int_equal(m.cmd.imaging.geometry, SC_SCAN_CURVILINEAR);
    assert_int_equal(parse("{\"op\":\"reset\",\"target\":\"all\"}", &m, &why), 0);
    assert_int_equal(m.cmd.reset_target, SC_RESET_ALL);
    assert_int_equal(parse("{\"op\":\"auth\",\"pass\":\"a\\\"b\"}", &m, &why), 0);
    assert_int_equal(m.op, GW_OP_AUTH);
    assert_string_equal(m.pass, "a\"b");
    assert_int_equal(parse("{\"op\":\"ping\"}", &m, &why), 0);
    assert_int_equal(m.op, GW_OP_PING);
    assert_int_equal(parse("{\"op\":\"assess\",\"action\":\"call\",\"call\":\"dvt\"}", &m, &why), 0);
    assert_int_equal(m.cmd.kind, SC_CMD_ASSESS);
    assert_int_equal(m.cmd.assess_action, SC_ASSESS_ACTION_CALL);
    assert_int_equal(m.cmd.assess_call, SC_ASSESS_CALL_DVT);
    assert_int_equal(parse("{\"op\":\"assess\",\"action\":\"reset\"}", &m, &why), 0);
    assert_int_equal(m.cmd.assess_action, SC_ASSESS_ACTION_RESET);
    assert_int_equal(m.cmd.assess_call, SC_ASSESS_CALL_NONE);
    assert_int_equal(parse("{\"op\":\"vessels\",\"heart_rate_bpm\":110,\"resp_rate_bpm\":0,"
                           "\"valsalva\":1,\"pulse\":0}", &m, &why), 0);
    assert_int_equal(m.cmd.kind, SC_CMD_VESSELS);
    assert_float_equal(m.cmd.vessels.heart_rate_bpm, 110.0f, 0.0f);
    assert_float_equal(m.cmd.vessels.resp_rate_bpm, 0.0f, 0.0f);
    assert_int_equal(m.cmd.vessels.valsalva, 1);
    assert_int_equal(m.cmd.vessels.pulse, 0);
    assert_string_equal(m.name, "vessels");
    assert_int_equal(parse("{\"op\":\"doppler\",\"colour\":\"off\",\"prf_hz\":2500,"
                           "\"steer_deg\":-20,\"gain_db\":4.5}", &m, &why), 0);
    assert_int_equal(m.cmd.kind, SC_CMD_DOPPLER);
    assert_int_equal(m.cmd.doppler.on, 0);
    assert_float_equal(m.cmd.doppler.prf_hz, 2500.0f, 0.0f);
    assert_float_equal(m.cmd.doppler.steer_deg, -20.0f, 0.0f);
    assert_float_equal(m.cmd.doppler.gain_db, 4.5f, 0.0f);
    assert_int_equal(parse("{\"op\":\"material\",\"label\":\"thrombus\",\"e_kpa\":12.5,"
                           "\"nu\":0.4,\"damping_s\":0.2,\"cg_iterations\":20,\"corotated\":1}",
                           &m, &why), 0);
    assert_int_equal(m.op, GW_OP_COMMAND);
    assert_int_equal(m.cmd.kind, SC_CMD_MATERIAL);
    assert_int_equal(m.cmd.material.label, 7);
    assert_float_equal(m.cmd.material.e_kpa, 12.5f, 0.0f);
    assert_float_equal(m.cmd.material.poisson, 0.4f, 1e-6f);
    assert_float_equal(m.cmd.material.damping_s, 0.2f, 1e-6f);
    assert_int_equal(m.cmd.material.cg_iterations, 20);
    assert_int_equal(m.cmd.material.corotated, 1);
    assert_string_equal(m.name, "material");
    assert_int_equal(parse("{\"op\":\"material\",\"label\":\"skin\",\"e_kpa\":100,"
                           "\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
                           &m, &why), 0);
    assert_int_equal(m.cmd.material.label, 1);
}

static void bad_messages_are_refused_with_a_reason(void **state)
{
    (void)state;
    static const char *const bad[] = {
        "",
        "[1]",
        "{\"op\":\"case\",\"id\":2",                       /* unterminated */
        "{\"op\":\"case\",\"id\":2} x",                    /* trailing bytes */
        "{\"op\":\"case\",\"id\":255}",                    /* outside the DBC range */
        "{\"op\":\"case\",\"id\":1.5}",
        "{\"op\":\"case\",\"id\":\"1\"}",                  /* wrong type */
        "{\"op\":\"case\",\"id\":1,\"id\":2}",             /* duplicate key */
        "{\"op\":\"case\",\"id\":1,\"extra\":0}",          /* unknown key */
        "{\"op\":\"method\",\"value\":\"magic\"}",
        /* depth outside the DBC range */
        "{\"op\":\"imaging\",\"depth_mm\":5000,\"gain_db\":0,\"dyn_range_db\":60,\"tgc_db_per_cm\":0,\"geometry\":\"linear\"}",
        "{\"op\":\"imaging\",\"depth_mm\":40}",             /* fields missing */
        "{\"op\":\"reset\",\"target\":\"engine\"}",
        "{\"op\":\"shutdown\"}",                           /* not a protocol command */
        "{\"op\":\"assess\",\"action\":\"call\"}",           /* a call without its value */
        "{\"op\":\"assess\",\"action\":\"call\",\"call\":\"maybe\"}",
        "{\"op\":\"assess\",\"action\":\"reset\",\"call\":\"dvt\"}", /* reset takes no call */
        "{\"op\":\"case\",\"id\":1e999}",
        /* vessels: heart rate outside 30..200, breathing above 40, valsalva not 0|1, missing */
        "{\"op\":\"vessels\",\"heart_rate_bpm\":20,\"resp_rate_bpm\":12,\"valsalva\":0,\"pulse\":1}",
        "{\"op\":\"vessels\",\"heart_rate_bpm\":72,\"resp_rate_bpm\":41,\"valsalva\":0,\"pulse\":1}",
        "{\"op\":\"vessels\",\"heart_rate_bpm\":72,\"resp_rate_bpm\":12,\"valsalva\":2,\"pulse\":1}",
        "{\"op\":\"vessels\",\"heart_rate_bpm\":72,\"resp_rate_bpm\":12,\"valsalva\":\"1\",\"pulse\":1}",
        "{\"op\":\"vessels\",\"heart_rate_bpm\":72}",
        /* doppler: scale, steering, gain outside the DBC; colour not on|off; extra key */
        "{\"op\":\"doppler\",\"colour\":\"on\",\"prf_hz\":50,\"steer_deg\":0,\"gain_db\":0}",
        "{\"op\":\"doppler\",\"colour\":\"on\",\"prf_hz\":4000,\"steer_deg\":45,\"gain_db\":0}",
        "{\"op\":\"doppler\",\"colour\":\"on\",\"prf_hz\":4000,\"steer_deg\":0,\"gain_db\":31}",
        "{\"op\":\"doppler\",\"colour\":\"yes\",\"prf_hz\":4000,\"steer_deg\":0,\"gain_db\":0}",
        "{\"op\":\"doppler\",\"colour\":\"on\",\"prf_hz\":4000,\"steer_deg\":0,\"gain_db\":0,\"x\":1}",
        /* material: E, nu, damping, iterations outside the DBC; bone, unknown label, a number
         * for the label, corotated 2, fractional iterations, a field missing */
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":0,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":7000,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":3.5,\"nu\":0.5,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.9,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":64,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":2.5,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"bone\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"liver\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":2,\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":0}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10,\"corotated\":2}",
        "{\"op\":\"material\",\"label\":\"fat\",\"e_kpa\":3.5,\"nu\":0.45,\"damping_s\":0.1,\"cg_iterations\":10}",
        "{\"op\":\"auth\",\"pass\":\"\\u0041\"}",          /* unsupported escape */
        "{\"op\":{\"nested\":1}}",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        gw_msg m;
        const char *why = NULL;
        if (parse(bad[i], &m, &why) != -1 || why == NULL || why[0] == '\0') {
            fail_msg("accepted or no reason: %s", bad[i]);
        }
    }
    char big[GW_MSG_MAX + 2];
    memset(big, ' ', sizeof big);
    memcpy(big, "{\"op\":\"ping\"}", 13);
    gw_msg m;
    const char *why = NULL;
    assert_int_equal(gw_msg_parse(big, sizeof big, &m, &why), -1);
    assert_string_equal(why, "message too long");
}

static void session_ops_parse_and_bad_names_are_refused(void **state)
{
    (void)state;
    gw_msg m;
    const char *why = NULL;
    assert_int_equal(parse("{\"op\":\"sessions\"}", &m, &why), 0);
    assert_int_equal(m.op, GW_OP_SESSIONS);
    assert_int_equal(parse("{\"op\":\"sessions\",\"dir\":\"/etc\"}", &m, &why), -1);
    assert_int_equal(parse("{\"op\":\"replay\",\"name\":\"press-2026_11.24.scb\"}", &m, &why), 0);
    assert_int_equal(m.op, GW_OP_REPLAY);
    assert_string_equal(m.name, "replay");
    assert_string_equal(m.file, "press-2026_11.24.scb");
    /* names that leave the folder, are empty, too long, hidden or not bundles */
    static const char *const bad[] = {
        "{\"op\":\"replay\",\"name\":\"../x.scb\"}",
        "{\"op\":\"replay\",\"name\":\"a/b.scb\"}",
        "{\"op\":\"replay\",\"name\":\"/abs.scb\"}",
        "{\"op\":\"replay\",\"name\":\"a\\\\b.scb\"}",
        "{\"op\":\"replay\",\"name\":\"\"}",
        "{\"op\":\"replay\",\"name\":\".scb\"}",
        "{\"op\":\"replay\",\"name\":\".hidden.scb\"}",
        "{\"op\":\"replay\",\"name\":\"session.txt\"}",
        "{\"op\":\"replay\",\"name\":\"a b.scb\"}",
        "{\"op\":\"replay\",\"name\":7}",
        "{\"op\":\"replay\"}",
        "{\"op\":\"replay\",\"name\":\"a.scb\",\"x\":1}",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        why = NULL;
        assert_int_equal(parse(bad[i], &m, &why), -1);
        assert_non_null(why);
    }
    /* too long: one byte over the limit (the parser's own string limit is larger) */
    char name[GW_MSG_FILE_MAX + 1];
    memset(name, 'a', sizeof name);
    memcpy(name + GW_MSG_FILE_MAX - 4, ".scb", 5);
    assert_int_equal(strlen(name), GW_MSG_FILE_MAX);
    char msg[256];
    snprintf(msg, sizeof msg, "{\"op\":\"replay\",\"name\":\"%s\"}", name);
    assert_int_equal(parse(msg, &m, &why), -1);
    assert_non_null(strstr(why, "plain file name"));
    /* the longest accepted */
    memcpy(name + GW_MSG_FILE_MAX - 5, ".scb", 5);
    snprintf(msg, sizeof msg, "{\"op\":\"replay\",\"name\":\"%s\"}", name);
    assert_int_equal(parse(msg, &m, &why), 0);
    assert_int_equal(strlen(m.file), GW_MSG_FILE_MAX - 1);
    assert_true(gw_msg_bundle_name_ok("x.scb"));
    assert_false(gw_msg_bundle_name_ok("../x.scb"));
    assert_false(gw_msg_bundle_name_ok(NULL));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(each_protocol_command_parses),
        cmocka_unit_test(bad_messages_are_refused_with_a_reason),
        cmocka_unit_test(session_ops_parse_and_bad_names_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
