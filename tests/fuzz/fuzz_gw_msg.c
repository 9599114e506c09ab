/* fuzz_gw_msg.c: the console gateway's client-message parser (tools/gateway/gw_msg.c) takes any
 * WebSocket text, never crashes, and accepts only messages that map to a command the CAN
 * protocol can carry (its encoder accepts the command) or to auth/ping. */
#include <string.h>

#include "gw_msg.h"
#include "sc_fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    gw_msg m;
    const char *why = NULL;
    const int rc = gw_msg_parse((const char *)data, size, &m, &why);
    SC_FUZZ_CHECK(rc == 0 || rc == -1);
    if (rc != 0) {
        SC_FUZZ_CHECK(why != NULL && why[0] != '\0');
        return 0;
    }
    SC_FUZZ_CHECK(size <= GW_MSG_MAX);
    SC_FUZZ_CHECK(m.name != NULL);
    if (m.op == GW_OP_COMMAND) {
        sc_can_frame f;
        SC_FUZZ_CHECK(sc_canproto_encode_cmd(&m.cmd, 0, &f) == 0);
        sc_cmd back;
        SC_FUZZ_CHECK(sc_canproto_decode_cmd(&f, &back) == 0 && back.kind == m.cmd.kind);
    } else if (m.op == GW_OP_AUTH) {
        SC_FUZZ_CHECK(strlen(m.pass) < GW_MSG_PASS_MAX);
    } else if (m.op == GW_OP_REPLAY) {
        /* a plain file name in the sessions folder: never a path */
        SC_FUZZ_CHECK(gw_msg_bundle_name_ok(m.file) && strchr(m.file, '/') == NULL &&
                      strstr(m.file, "..") != m.file && m.file[0] != '.');
    } else {
        SC_FUZZ_CHECK(m.op == GW_OP_PING || m.op == GW_OP_SESSIONS);
    }
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const seeds[] = {
        "{\"op\":\"case\",\"id\":1}",
        "{\"op\":\"sessions\"}",
        "{\"op\":\"replay\",\"name\":\"press.scb\"}",
        "{\"op\":\"method\",\"value\":\"fem\"}",
        "{\"op\":\"imaging\",\"depth_mm\":40,\"gain_db\":12.5,\"dyn_range_db\":60,\"tgc_db_per_cm\":1,\"geometry\":\"linear\"}",
        "{\"op\":\"reset\",\"target\":\"tissue\"}",
        "{\"op\":\"auth\",\"pass\":\"in\\\"struct\\\\or\"}",
        " { \"op\" : \"ping\" } ",
    };
    if (i >= sizeof seeds / sizeof seeds[0] || strlen(seeds[i]) > cap) {
        return 0;
    }
    memcpy(buf, seeds[i], strlen(seeds[i]));
    return strlen(seeds[i]);
}
