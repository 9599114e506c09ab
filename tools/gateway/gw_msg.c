/* gw_msg.c: the console gateway's client messages, see gw_msg.h. */
#include "gw_msg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_MEMBERS 8
#define STR_MAX 128u

typedef struct member {
    char key[32];
    int is_str;
    char str[STR_MAX];
    double num;
} member;

typedef struct parser {
    const char *p, *end;
    const char *why;
} parser;

static void ws(parser *ps)
{
    while (ps->p < ps->end && (*ps->p == ' ' || *ps->p == '\t' || *ps->p == '\n' || *ps->p == '\r')) {
        ps->p++;
    }
}

static int str(parser *ps, char *out, size_t cap)
{
    if (ps->p >= ps->end || *ps->p != '"') {
        ps->why = "expected a string";
        return -1;
    }
    ps->p++;
    size_t n = 0;
    while (ps->p < ps->end && *ps->p != '"') {
        char c = *ps->p++;
        if (c == '\\') {
            if (ps->p >= ps->end || (*ps->p != '"' && *ps->p != '\\')) {
                ps->why = "unsupported escape in a string";
                return -1;
            }
            c = *ps->p++;
        }
        if ((unsigned char)c < 0x20u || (unsigned char)c > 0x7eu) {
            ps->why = "string holds a non-printable or non-ASCII byte";
            return -1;
        }
        if (n + 1u >= cap) {
            ps->why = "string too long";
            return -1;
        }
        out[n++] = c;
    }
    if (ps->p >= ps->end) {
        ps->why = "unterminated string";
        return -1;
    }
    ps->p++;
    out[n] = '\0';
    return 0;
}

static int num(parser *ps, double *out)
{
    char buf[40];
    size_t n = 0;
    while (ps->p < ps->end && n + 1u < sizeof buf &&
           (strchr("0123456789+-.eE", *ps->p) != NULL && *ps->p != '\0')) {
        buf[n++] = *ps->p++;
    }
    buf[n] = '\0';
    if (n == 0u || n + 1u >= sizeof buf) {
        ps->why = "expected a number";
        return -1;
    }
    char *e;
    const double v = strtod(buf, &e);
    if (*e != '\0' || !isfinite(v)) {
        ps->why = "malformed number";
        return -1;
    }
    if (fabs(v) > 1e9) {
        ps->why = "number out of range";
        return -1;
    }
    *out = v;
    return 0;
}

static int object(parser *ps, member *m, int *count)
{
    ws(ps);
    if (ps->p >= ps->end || *ps->p != '{') {
        ps->why = "a message is one JSON object";
        return -1;
    }
    ps->p++;
    *count = 0;
    ws(ps);
    if (ps->p < ps->end && *ps->p == '}') {
        ps->p++;
        return 0;
    }
    for (;;) {
        if (*count >= MAX_MEMBERS) {
            ps->why = "too many members";
            return -1;
        }
        member *x = &m[*count];
        ws(ps);
        if (str(ps, x->key, sizeof x->key) != 0) {
            return -1;
        }
        for (int i = 0; i < *count; i++) {
            if (strcmp(m[i].key, x->key) == 0) {
                ps->why = "duplicate key";
                return -1;
            }
        }
        ws(ps);
        if (ps->p >= ps->end || *ps->p != ':') {
            ps->why = "expected ':'";
            return -1;
        }
        ps->p++;
        ws(ps);
        if (ps->p < ps->end && *ps->p == '"') {
            x->is_str = 1;
            if (str(ps, x->str, sizeof x->str) != 0) {
                return -1;
            }
        } else {
            x->is_str = 0;
            if (num(ps, &x->num) != 0) {
                return -1;
            }
        }
        (*count)++;
        ws(ps);
        if (ps->p < ps->end && *ps->p == ',') {
            ps->p++;
            continue;
        }
        if (ps->p < ps->end && *ps->p == '}') {
            ps->p++;
            return 0;
        }
        ps->why = "expected ',' or '}'";
        return -1;
    }
}

static const member *find(const member *m, int n, const char *key, int want_str)
{
    for (int i = 0; i < n; i++) {
        if (strcmp(m[i].key, key) == 0) {
            return m[i].is_str == want_str ? &m[i] : NULL;
        }
    }
    return NULL;
}

/* every key of m is in the NULL-terminated list */
static int only(const member *m, int n, const char *const *keys)
{
    for (int i = 0; i < n; i++) {
        int ok = 0;
        for (const char *const *k = keys; *k; k++) {
            ok |= strcmp(m[i].key, *k) == 0;
        }
        if (!ok) {
            return 0;
        }
    }
    return 1;
}

/* 0 or 1 exactly */
static int is_bit(double v)
{
    return v >= 0.0 && v <= 1.0 && !(floor(v) < v);
}

static int fail(const char **why, const char *reason)
{
    *why = reason;
    return -1;
}

int gw_msg_bundle_name_ok(const char *name)
{
    if (name == NULL) {
        return 0;
    }
    const size_t n = strlen(name);
    if (n <= 4u || n >= GW_MSG_FILE_MAX || name[0] == '.' || strcmp(name + n - 4u, ".scb") != 0) {
        return 0;
    }
    for (size_t i = 0; i < n; i++) {
        const char c = name[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '.' || c == '_' || c == '-')) {
            return 0;
        }
    }
    return 1;
}

/* CmdMaterial: a label by name (config/sc_labels.h, skin..thrombus), its E and nu, and the
 * solver's damping, CG iterations and corotation; the ranges are the encoder's. */
static int parse_material(const member *m, int n, gw_msg *r)
{
    static const char *const k[] = {"op",        "label",         "e_kpa",     "nu",
                                    "damping_s", "cg_iterations", "corotated", NULL};
    static const char *const labels[] = {"skin", "fat", "muscle", "vein", "artery", "nerve",
                                         "thrombus"};
    const member *l = find(m, n, "label", 1), *e = find(m, n, "e_kpa", 0),
                 *nu = find(m, n, "nu", 0), *d = find(m, n, "damping_s", 0),
                 *it = find(m, n, "cg_iterations", 0), *co = find(m, n, "corotated", 0);
    if (!only(m, n, k) || !l || !e || !nu || !d || !it || !co || !is_bit(co->num) ||
        floor(it->num) < it->num || !(it->num >= 1.0 && it->num <= 63.0)) {
        return -1;
    }
    uint8_t label = 0;
    for (unsigned i = 0; i < sizeof labels / sizeof labels[0]; i++) {
        if (strcmp(l->str, labels[i]) == 0) {
            label = (uint8_t)(SC_MATERIAL_LABEL_MIN + i);
        }
    }
    if (label == 0u) {
        return -1;
    }
    r->op = GW_OP_COMMAND;
    r->name = "material";
    r->cmd.kind = SC_CMD_MATERIAL;
    r->cmd.material.label = label;
    r->cmd.material.e_kpa = (float)e->num;
    r->cmd.material.poisson = (float)nu->num;
    r->cmd.material.damping_s = (float)d->num;
    r->cmd.material.cg_iterations = (uint8_t)it->num;
    r->cmd.material.corotated = co->num > 0.5 ? 1u : 0u;
    return 0;
}

int gw_msg_parse(const char *text, size_t len, gw_msg *out, const char **why)
{
    static const char *dummy;
    if (why == NULL) {
        why = &dummy;
    }
    if (text == NULL || out == NULL) {
        return fail(why, "no message");
    }
    if (len > GW_MSG_MAX) {
        return fail(why, "message too long");
    }
    member m[MAX_MEMBERS];
    int n = 0;
    parser ps = {text, text + len, NULL};
    if (object(&ps, m, &n) != 0) {
        return fail(why, ps.why);
    }
    ws(&ps);
    if (ps.p != ps.end) {
        return fail(why, "bytes after the object");
    }
    const member *op = find(m, n, "op", 1);
    if (op == NULL) {
        return fail(why, "no \"op\" string");
    }
    gw_msg r;
    memset(&r, 0, sizeof r);
    if (strcmp(op->str, "auth") == 0) {
        static const char *const k[] = {"op", "pass", NULL};
        const member *p = find(m, n, "pass", 1);
        if (!only(m, n, k) || p == NULL || strlen(p->str) >= GW_MSG_PASS_MAX) {
            return fail(why, "auth wants {\"op\":\"auth\",\"pass\":\"...\"}");
        }
        r.op = GW_OP_AUTH;
        r.name = "auth";
        strcpy(r.pass, p->str);
    } else if (strcmp(op->str, "ping") == 0) {
        static const char *const k[] = {"op", NULL};
        if (!only(m, n, k)) {
            return fail(why, "ping takes no arguments");
        }
        r.op = GW_OP_PING;
        r.name = "ping";
    } else if (strcmp(op->str, "case") == 0) {
        static const char *const k[] = {"op", "id", NULL};
        const member *id = find(m, n, "id", 0);
        if (!only(m, n, k) || id == NULL || floor(id->num) < id->num || id->num < 0.0 ||
            id->num > 254.0) {
            return fail(why, "case wants {\"op\":\"case\",\"id\":0..254}");
        }
        r.op = GW_OP_COMMAND;
        r.name = "case";
        r.cmd.kind = SC_CMD_SELECT_CASE;
        r.cmd.case_id = (uint8_t)id->num;
    } else if (strcmp(op->str, "method") == 0) {
        static const char *const k[] = {"op", "value", NULL};
        const member *v = find(m, n, "value", 1);
        if (!only(m, n, k) || v == NULL ||
            (strcmp(v->str, "msds") != 0 && strcmp(v->str, "fem") != 0)) {
            return fail(why, "method wants {\"op\":\"method\",\"value\":\"msds\"|\"fem\"}");
        }
        r.op = GW_OP_COMMAND;
        r.name = "method";
        r.cmd.kind = SC_CMD_SET_METHOD;
        r.cmd.method = strcmp(v->str, "fem") == 0 ? SC_METHOD_FEM : SC_METHOD_MSDS;
    } else if (strcmp(op->str, "reset") == 0) {
        static const char *const k[] = {"op", "target", NULL};
        const member *v = find(m, n, "target", 1);
        uint8_t t = 0;
        if (v != NULL) {
            t = strcmp(v->str, "tissue") == 0   ? SC_RESET_TISSUE
                : strcmp(v->str, "faults") == 0 ? SC_RESET_FAULTS
                : strcmp(v->str, "all") == 0    ? SC_RESET_ALL
                                                : 0u;
        }
        if (!only(m, n, k) || t == 0u) {
            return fail(why, "reset wants {\"op\":\"reset\",\"target\":\"tissue\"|\"faults\"|\"all\"}");
        }
        r.op = GW_OP_COMMAND;
        r.name = "reset";
        r.cmd.kind = SC_CMD_RESET;
        r.cmd.reset_target = t;
    } else if (strcmp(op->str, "imaging") == 0) {
        static const char *const k[] = {"op",           "depth_mm",      "gain_db",
                                        "dyn_range_db", "tgc_db_per_cm", "geometry", NULL};
        const member *d = find(m, n, "depth_mm", 0), *g = find(m, n, "gain_db", 0),
                     *r_ = find(m, n, "dyn_range_db", 0), *t = find(m, n, "tgc_db_per_cm", 0),
                     *geo = find(m, n, "geometry", 1);
        if (!only(m, n, k) || !d || !g || !r_ || !t || !geo ||
            (strcmp(geo->str, "linear") != 0 && strcmp(geo->str, "curvilinear") != 0)) {
            return fail(why, "imaging wants depth_mm, gain_db, dyn_range_db, tgc_db_per_cm "
                             "(numbers) and geometry (\"linear\"|\"curvilinear\")");
        }
        r.op = GW_OP_COMMAND;
        r.name = "imaging";
        r.cmd.kind = SC_CMD_SET_IMAGING;
        r.cmd.imaging.depth_mm = (float)d->num;
        r.cmd.imaging.gain_db = (float)g->num;
        r.cmd.imaging.dyn_range_db = (float)r_->num;
        r.cmd.imaging.tgc_db_per_cm = (float)t->num;
        r.cmd.imaging.geometry =
            strcmp(geo->str, "curvilinear") == 0 ? SC_SCAN_CURVILINEAR : SC_SCAN_LINEAR;
    } else if (strcmp(op->str, "assess") == 0) {
        /* the exam's assessment: reset it, or enter the trainee's call (CmdAssessment) */
        static const char *const k[] = {"op", "action", "call", NULL};
        const member *a = find(m, n, "action", 1), *c = find(m, n, "call", 1);
        const int reset = a != NULL && strcmp(a->str, "reset") == 0 && c == NULL;
        const int call = a != NULL && strcmp(a->str, "call") == 0 && c != NULL &&
                         (strcmp(c->str, "normal") == 0 || strcmp(c->str, "dvt") == 0);
        if (!only(m, n, k) || (!reset && !call)) {
            return fail(why, "assess wants {\"op\":\"assess\",\"action\":\"reset\"} or "
                             "{\"op\":\"assess\",\"action\":\"call\",\"call\":\"normal\"|\"dvt\"}");
        }
        r.op = GW_OP_COMMAND;
        r.name = "assess";
        r.cmd.kind = SC_CMD_ASSESS;
        r.cmd.assess_action = reset ? SC_ASSESS_ACTION_RESET : SC_ASSESS_ACTION_CALL;
        r.cmd.assess_call = reset                           ? SC_ASSESS_CALL_NONE
                            : strcmp(c->str, "dvt") == 0 ? SC_ASSESS_CALL_DVT
                                                          : SC_ASSESS_CALL_NORMAL;
    } else if (strcmp(op->str, "sessions") == 0) {
        static const char *const k[] = {"op", NULL};
        if (!only(m, n, k)) {
            return fail(why, "sessions takes no arguments");
        }
        r.op = GW_OP_SESSIONS;
        r.name = "sessions";
    } else if (strcmp(op->str, "replay") == 0) {
        static const char *const k[] = {"op", "name", NULL};
        const member *f = find(m, n, "name", 1);
        if (!only(m, n, k) || f == NULL) {
            return fail(why, "replay wants {\"op\":\"replay\",\"name\":\"FILE.scb\"}");
        }
        if (!gw_msg_bundle_name_ok(f->str)) {
            return fail(why, "replay: the name must be a plain file name of [A-Za-z0-9._-] ending "
                             "in .scb, not starting with '.' (no path)");
        }
        r.op = GW_OP_REPLAY;
        r.name = "replay";
        strcpy(r.file, f->str);
    } else if (strcmp(op->str, "vessels") == 0) {
        /* the vessels' drive (CmdVessels): heart and breathing rates, Valsalva, pulsation */
        static const char *const k[] = {"op",       "heart_rate_bpm", "resp_rate_bpm",
                                        "valsalva", "pulse",          NULL};
        const member *hr = find(m, n, "heart_rate_bpm", 0), *rr = find(m, n, "resp_rate_bpm", 0),
                     *va = find(m, n, "valsalva", 0), *pu = find(m, n, "pulse", 0);
        if (!only(m, n, k) || !hr || !rr || !va || !pu || !is_bit(va->num) || !is_bit(pu->num)) {
            return fail(why, "vessels wants heart_rate_bpm (30..200), resp_rate_bpm (0..40) "
                             "(numbers), valsalva and pulse (0|1)");
        }
        r.op = GW_OP_COMMAND;
        r.name = "vessels";
        r.cmd.kind = SC_CMD_VESSELS;
        r.cmd.vessels.heart_rate_bpm = (float)hr->num;
        r.cmd.vessels.resp_rate_bpm = (float)rr->num;
        r.cmd.vessels.valsalva = va->num > 0.5 ? 1u : 0u;
        r.cmd.vessels.pulse = pu->num > 0.5 ? 1u : 0u;
    } else if (strcmp(op->str, "doppler") == 0) {
        /* colour Doppler (CmdDoppler): on/off, scale, steering, colour gain */
        static const char *const k[] = {"op", "colour", "prf_hz", "steer_deg", "gain_db", NULL};
        const member *c = find(m, n, "colour", 1), *prf = find(m, n, "prf_hz", 0),
                     *st = find(m, n, "steer_deg", 0), *g = find(m, n, "gain_db", 0);
        if (!only(m, n, k) || !c || !prf || !st || !g ||
            (strcmp(c->str, "on") != 0 && strcmp(c->str, "off") != 0)) {
            return fail(why, "doppler wants colour (\"on\"|\"off\"), prf_hz (100..20000), "
                             "steer_deg (-30..30), gain_db (-30..30)");
        }
        r.op = GW_OP_COMMAND;
        r.name = "doppler";
        r.cmd.kind = SC_CMD_DOPPLER;
        r.cmd.doppler.on = strcmp(c->str, "on") == 0 ? 1u : 0u;
        r.cmd.doppler.prf_hz = (float)prf->num;
        r.cmd.doppler.steer_deg = (float)st->num;
        r.cmd.doppler.gain_db = (float)g->num;
    } else if (strcmp(op->str, "material") == 0) {
        if (parse_material(m, n, &r) != 0) {
            return fail(why, "material wants label (\"skin\"|\"fat\"|\"muscle\"|\"vein\"|"
                             "\"artery\"|\"nerve\"|\"thrombus\"), e_kpa (0.1..6553.4), nu "
                             "(0..0.49), damping_s (0.01..0.5), cg_iterations (1..63), corotated "
                             "(0|1)");
        }
    } else {
        return fail(why, "unknown op (auth, ping, case, method, imaging, reset, assess, sessions, "
                         "replay, vessels, doppler, material)");
    }
    if (r.op == GW_OP_COMMAND) {
        sc_can_frame f;
        if (sc_canproto_encode_cmd(&r.cmd, 0, &f) != 0) {
            return fail(why, "value outside the CAN protocol's range (config/sonocomp.dbc)");
        }
    }
    *out = r;
    return 0;
}
