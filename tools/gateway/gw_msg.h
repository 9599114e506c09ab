/*
 * gw_msg.h: the console gateway's client messages (docs/console.md): one flat JSON object per
 * WebSocket text message, parsed strictly, each mapped to one of the commands the CAN protocol
 * defines (core/link/sc_canproto.h, config/sonocomp.dbc) and range-checked by the protocol's
 * own encoder, or to a gateway request (auth, ping). Anything else is refused with a reason.
 *
 *   {"op":"auth","pass":"..."}                         unlock the controls (pass phrase)
 *   {"op":"ping"}
 *   {"op":"case","id":N}                               CmdSelectCase, catalogue index 0..254
 *   {"op":"method","value":"msds"|"fem"}               CmdSetMethod
 *   {"op":"imaging","depth_mm":D,"gain_db":G,"dyn_range_db":R,"tgc_db_per_cm":T,
 *    "geometry":"linear"|"curvilinear"}                CmdSetImaging (every field required)
 *   {"op":"reset","target":"tissue"|"faults"|"all"}    CmdReset
 *   {"op":"material","label":"fat","e_kpa":E,"nu":NU,"damping_s":D,"cg_iterations":N,
 *    "corotated":0|1}                                  CmdMaterial (every field required; label
 *                                                      skin|fat|muscle|vein|artery|nerve|thrombus)
 *   {"op":"sessions"}                                  list the recorded sessions (--sessions DIR)
 *   {"op":"replay","name":"FILE.scb"}                  replay one of them into the console
 *
 * A replay's name is a plain file name: 1..GW_MSG_FILE_MAX-1 bytes of [A-Za-z0-9._-], not
 * starting with '.', ending in ".scb" (so no path separator, no "..", no hidden file); the
 * gateway then checks that DIR/name parses as a bundle.
 *
 * Parser rules: at most GW_MSG_MAX bytes, one object, at most 8 members, keys and strings of
 * printable ASCII without escapes other than \" and \\ (at most 127 bytes), numbers finite
 * decimals, no nesting, no duplicate keys, nothing after the object but white space, unknown
 * keys refused. Pure function, no allocation.
 */
#ifndef GW_MSG_H
#define GW_MSG_H

#include <stddef.h>

#include "sc_canproto.h"

#define GW_MSG_MAX 1024u
#define GW_MSG_PASS_MAX 128u
#define GW_MSG_FILE_MAX 96u

typedef enum gw_op {
    GW_OP_NONE = 0,
    GW_OP_AUTH,
    GW_OP_PING,
    GW_OP_COMMAND, /* cmd holds the CAN command */
    GW_OP_SESSIONS,
    GW_OP_REPLAY, /* file holds the bundle's file name */
} gw_op;

typedef struct gw_msg {
    gw_op op;
    sc_cmd cmd;
    char pass[GW_MSG_PASS_MAX];
    char file[GW_MSG_FILE_MAX];
    const char *name; /* the op's name ("case", "auth", ...), static */
} gw_msg;

/* Parse one message. 0, or -1 with a static reason in *why (never NULL on -1). */
/* 1 when name is a plain bundle file name as described above. */
int gw_msg_bundle_name_ok(const char *name);

int gw_msg_parse(const char *text, size_t len, gw_msg *out, const char **why);

#endif /* GW_MSG_H */
