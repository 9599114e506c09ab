/* sc_rtcfg.c: runtime configuration parser (see sc_rtcfg.h and config/sonocomp.conf). */
#include "sc_rtcfg.h"

#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_hal_log.h"

typedef enum key_kind {
    K_U32,
    K_I32,
    K_F32,
    K_BOOL,
    K_ENUM,
    K_PATH,    /* printable text, no blanks at the ends */
    K_IFNAME,  /* [A-Za-z0-9_.-], 1..15 */
    K_TARGET,  /* display.target */
    K_F32LIST, /* SC_BSCAN_TGC_BANDS numbers */
    K_WDOG,    /* none | soft | /absolute/path */
    K_AUTHKEY, /* bench | 32 hex digits | file:/absolute/path */
} key_kind;

typedef struct key_def {
    const char *name;
    const char *help;
    key_kind kind;
    size_t off;  /* offset in sc_rtcfg */
    size_t size; /* text kinds: buffer size */
    double min;  /* numeric kinds */
    double max;
    double def;               /* numeric kinds: default */
    const char *def_text;     /* other kinds: default as text */
    const char *words;        /* other kinds: accepted values in words */
    const char *const *names; /* K_ENUM: value i is names[i]; NULL-terminated */
} key_def;

static const char *const k_method_names[] = {"msds", "fem", NULL};
static const char *const k_geometry_names[] = {"linear", "curvilinear", NULL};
static const char *const k_log_names[] = {"debug", "info", "warn", "error", NULL};
static const char *const k_tristate_names[] = {"auto", "on", "off", NULL};
static const char *const k_target_names[] = {"none", "udp", "png", "drm", "fbdev", NULL};

#define F(member)                offsetof(sc_rtcfg, member)
#define MIN_U(a, b)              ((a) < (b) ? (a) : (b))
#define NUM(lo, hi, dflt)        0u, (double)(lo), (double)(hi), (double)(dflt), NULL, NULL, NULL
#define TXT(size, dflt, words)   (size), 0.0, 0.0, 0.0, (dflt), (words), NULL
#define ENUM(dflt, words, names) 0u, 0.0, 0.0, 0.0, (dflt), (words), (names)

/* The key table. Numeric ranges and defaults come from sc_config.h where the engine has a
 * compile-time limit; every default passes its own range check (test_sc_rtcfg). */
static const key_def k_keys[] = {
    {"can.interface", "SocketCAN interface of the tracker bus; none: no CAN (probe lifted)",
     K_IFNAME, F(can_interface),
     TXT(SC_RTCFG_IFNAME_MAX, "can0", "an interface name of 1..15 characters [A-Za-z0-9_.-]")},
    {"display.target", "where the B-scan lines go (docs/display-link.md for udp)", K_TARGET,
     F(display_target),
     TXT(0u, "udp:127.0.0.1:5600",
         "none | udp:HOST:PORT | png:DIR | drm[:/dev/dri/cardN] | fbdev[:/dev/fbN]")},
    {"frame_rate_hz", "frames per second (one physics step and one image per frame)", K_U32,
     F(frame_rate_hz), NUM(SC_FRAME_RATE_MIN_HZ, SC_FRAME_RATE_MAX_HZ, SC_FRAME_RATE_DEFAULT_HZ)},
    {"case", "case file loaded at start", K_PATH, F(case_path),
     TXT(SC_RTCFG_PATH_MAX, "cases/neck-ijv.scase", "a file path")},
    {"physics.method", "soft-tissue solver (switchable at run time over CAN)", K_ENUM,
     F(physics_method), ENUM("msds", "msds | fem", k_method_names)},
    {"physics.iterations", "solver iterations per frame (paper: 20)", K_U32, F(physics_iterations),
     NUM(1u, SC_PHYS_ITERATIONS_MAX, SC_PHYS_ITERATIONS_DEFAULT)},
    {"physics.dt_s", "MSDS time step in seconds (paper: 0.01)", K_F32, F(physics_dt_s),
     NUM(0.0001, 0.1, SC_PHYS_DT_DEFAULT_S)},
    {"physics.cg_iterations",
     "CG iterations per frame of the implicit step (stable MSDS and FEM): the solver's budget",
     K_U32, F(physics_cg_iterations),
     NUM(1u, SC_PHYS_ITERATIONS_MAX, SC_PHYS_CG_ITERATIONS_DEFAULT)},
    {"image.geometry", "scan geometry of the virtual probe", K_ENUM, F(image_geometry),
     ENUM("linear", "linear | curvilinear", k_geometry_names)},
    {"image.depth_mm", "imaging depth in millimetres", K_F32, F(image_depth_mm), NUM(10, 300, 40)},
    {"image.width_mm", "linear probe: aperture width in millimetres", K_F32, F(image_width_mm),
     NUM(5, 100, 38)},
    {"image.sector_deg", "curvilinear probe: sector angle in degrees", K_F32, F(image_sector_deg),
     NUM(10, 150, 60)},
    {"image.lines", "scan lines per image", K_U32, F(image_lines),
     NUM(16u, SC_MAX_SCAN_LINES, MIN_U(256u, SC_MAX_SCAN_LINES))},
    {"image.samples", "samples per scan line", K_U32, F(image_samples),
     NUM(16u, SC_MAX_SCAN_SAMPLES, MIN_U(384u, SC_MAX_SCAN_SAMPLES))},
    {"image.gain_db", "overall gain in dB", K_F32, F(image_gain_db), NUM(-40, 40, 0)},
    {"image.tgc_db", "time-gain compensation per depth band in dB, shallow to deep", K_F32LIST,
     F(image_tgc_db), NUM(-20, 20, 0)},
    {"image.dynamic_range_db", "displayed dynamic range in dB", K_F32, F(image_dynamic_range_db),
     NUM(20, 120, 60)},
    {"rt.sched_fifo",
     "run the frame loop SCHED_FIFO when permitted (a warning and normal priority otherwise)",
     K_BOOL, F(rt_sched_fifo), TXT(0u, "true", "true | false (also yes/no, on/off, 1/0)")},
    {"rt.priority", "SCHED_FIFO priority of the frame loop", K_U32, F(rt_priority), NUM(1, 99, 80)},
    {"rt.cpu", "CPU the frame loop is pinned to; -1: no pinning", K_I32, F(rt_cpu),
     NUM(-1, 1023, -1)},
    {"rt.mlock", "lock and pre-fault all memory (mlockall)", K_BOOL, F(rt_mlock),
     TXT(0u, "true", "true | false (also yes/no, on/off, 1/0)")},
    {"rt.hugepages",
     "back the engine's state with transparent huge pages (madvise; a warning if refused)",
     K_BOOL, F(rt_hugepages), TXT(0u, "true", "true | false (also yes/no, on/off, 1/0)")},
    {"watchdog.device", "watchdog fed once per frame: kernel device, software (host) or none",
     K_WDOG, F(watchdog_device),
     TXT(SC_RTCFG_PATH_MAX, "soft", "none | soft | an absolute device path such as /dev/watchdog")},
    {"watchdog.timeout_ms", "watchdog timeout in milliseconds", K_U32, F(watchdog_timeout_ms),
     NUM(100, 60000, 1000)},
    {"tracker.timeout_ms", "no valid pose for this long means the probe is lifted", K_U32,
     F(tracker_timeout_ms), NUM(10, 5000, 100)},
    {"can.auth_key",
     "AES-128 key of the commands' MAC (docs/can-protocol.md); bench: the documented bench key",
     K_AUTHKEY, F(can_auth_key),
     TXT(SC_RTCFG_PATH_MAX, "bench",
         "bench | 32 hex digits | file:/absolute/path (a file holding the 32 hex digits)")},
    {"can.auth_window", "commands of one sender that may be lost between two accepted ones + 1",
     K_U32, F(can_auth_window), NUM(1, 32768, 1024)},
    {"can.auth_floor_s",
     "freshness values older than the engine's start minus this many seconds (wall clock) are "
     "refused; -1: no floor",
     K_I32, F(can_auth_floor_s), NUM(-1, 86400, 300)},
    {"log.level", "lowest level of log records written", K_ENUM, F(log_level),
     ENUM("info", "debug | info | warn | error", k_log_names)},
    {"status.line", "live status line once a second (auto: when stderr is a terminal)", K_ENUM,
     F(status_line), ENUM("auto", "auto | on | off", k_tristate_names)},
};

#define KEY_COUNT (sizeof k_keys / sizeof k_keys[0])
_Static_assert(KEY_COUNT <= 64u, "duplicate detection uses one bit per key");
_Static_assert(SC_LOG_DEBUG == 0 && SC_LOG_INFO == 1 && SC_LOG_WARN == 2 && SC_LOG_ERROR == 3,
               "log.level names follow sc_log_level");
_Static_assert(SC_BSCAN_TGC_BANDS <= 32u, "image.tgc_db is parsed into a fixed array");

/* ---- small text helpers (no stdio) ----------------------------------------------------- */

typedef struct text_out {
    char *buf;
    size_t cap;
    size_t n;
} text_out;

static void out_str(text_out *o, const char *s)
{
    while (*s && o->n + 1u < o->cap) {
        o->buf[o->n++] = *s++;
    }
    o->buf[o->n] = '\0';
}

static void out_u32(text_out *o, uint32_t v)
{
    char tmp[11];
    size_t i = sizeof tmp;
    tmp[--i] = '\0';
    do {
        tmp[--i] = (char)('0' + (char)(v % 10u));
        v /= 10u;
    } while (v && i > 0u);
    out_str(o, tmp + i);
}

/* Echo a user value into a message, shortened. */
static void out_value(text_out *o, const char *v)
{
    char tmp[40];
    size_t n = strlen(v);
    if (n < sizeof tmp) {
        out_str(o, v);
        return;
    }
    memcpy(tmp, v, sizeof tmp - 4u);
    memcpy(tmp + sizeof tmp - 4u, "...", 4u);
    out_str(o, tmp);
}

/* A limit or default as decimal text, at most 6 decimals, trailing zeros dropped ("0.0001",
 * "-40", "0.01"). Limits of this table stay far below 1e12. */
static void out_num(text_out *o, double v)
{
    if (v < 0.0) {
        out_str(o, "-");
        v = -v;
    }
    const uint64_t scaled = (uint64_t)(v * 1e6 + 0.5);
    const uint64_t ip = scaled / 1000000u;
    uint32_t frac = (uint32_t)(scaled % 1000000u);
    char tmp[24];
    size_t i = sizeof tmp;
    uint64_t q = ip;
    tmp[--i] = '\0';
    do {
        tmp[--i] = (char)('0' + (char)(q % 10u));
        q /= 10u;
    } while (q && i > 0u);
    out_str(o, tmp + i);
    if (frac) {
        char f[8] = {'.', 0, 0, 0, 0, 0, 0, 0};
        for (int d = 6; d >= 1; d--) {
            f[d] = (char)('0' + (char)(frac % 10u));
            frac /= 10u;
        }
        int last = 6;
        while (f[last] == '0') {
            f[last--] = '\0';
        }
        out_str(o, f);
    }
}

static int is_numeric(const struct key_def *k)
{
    return k->kind == K_U32 || k->kind == K_I32 || k->kind == K_F32 || k->kind == K_F32LIST;
}

/* What a key accepts, in words: "1 .. 240", or the words of a text key. */
static void out_range(text_out *o, const struct key_def *k)
{
    if (!is_numeric(k)) {
        out_str(o, k->words);
        return;
    }
    out_num(o, k->min);
    out_str(o, " .. ");
    out_num(o, k->max);
}

static int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static void set_error(sc_rtcfg_error *e, int code, uint32_t line, const char *key, size_t key_len)
{
    if (!e) {
        return;
    }
    e->err = code;
    e->line = line;
    size_t n = key_len < SC_RTCFG_KEY_MAX - 1u ? key_len : SC_RTCFG_KEY_MAX - 1u;
    if (key) {
        memcpy(e->key, key, n);
    } else {
        n = 0;
    }
    e->key[n] = '\0';
    e->reason[0] = '\0';
}

static text_out reason_out(sc_rtcfg_error *e)
{
    text_out o = {e ? e->reason : NULL, e ? SC_RTCFG_REASON_MAX : 0u, 0u};
    return o;
}

/* Append to the reason of e (no-op without e). */
static void why(sc_rtcfg_error *e, const char *a, const char *value, const char *b)
{
    if (!e) {
        return;
    }
    text_out o = reason_out(e);
    o.n = strlen(e->reason);
    out_str(&o, a);
    if (value) {
        out_value(&o, value);
    }
    if (b) {
        out_str(&o, b);
    }
}

/* Append the accepted range of k to the reason of e. */
static void why_range(sc_rtcfg_error *e, const key_def *k)
{
    if (!e) {
        return;
    }
    text_out o = reason_out(e);
    o.n = strlen(e->reason);
    out_range(&o, k);
}

/* ---- number parsing -------------------------------------------------------------------- */

/* Decimal number: [+-]digits[.digits][(e|E)[+-]digits], or [+-].digits. Returns 0 and *out,
 * SC_ERR_CFG_VALUE when malformed, SC_ERR_CFG_RANGE when the magnitude exceeds 1e30 (every
 * key's range is far below). At most 18 significant digits are kept; the rest only scale. */
static int parse_number(const char *s, double *out)
{
    const char *p = s;
    int neg = 0;
    if (*p == '+' || *p == '-') {
        neg = (*p == '-');
        p++;
    }
    uint64_t mant = 0;
    int32_t exp10 = 0;
    uint32_t sig = 0;
    uint32_t digits = 0;
    while (is_digit(*p)) {
        if (sig < 18u) {
            mant = mant * 10u + (uint64_t)(*p - '0');
            if (mant) {
                sig++;
            }
        } else {
            exp10++;
        }
        digits++;
        p++;
    }
    if (*p == '.') {
        p++;
        while (is_digit(*p)) {
            if (sig < 18u) {
                mant = mant * 10u + (uint64_t)(*p - '0');
                if (mant) {
                    sig++;
                }
                exp10--;
            }
            digits++;
            p++;
        }
    }
    if (digits == 0u) {
        return SC_ERR_CFG_VALUE;
    }
    if (*p == 'e' || *p == 'E') {
        p++;
        int eneg = 0;
        if (*p == '+' || *p == '-') {
            eneg = (*p == '-');
            p++;
        }
        if (!is_digit(*p)) {
            return SC_ERR_CFG_VALUE;
        }
        int32_t e = 0;
        while (is_digit(*p)) {
            if (e < 10000) {
                e = e * 10 + (int32_t)(*p - '0');
            }
            p++;
        }
        exp10 += eneg ? -e : e;
    }
    if (*p != '\0') {
        return SC_ERR_CFG_VALUE;
    }
    double v = (double)mant;
    if (mant != 0u) {
        /* magnitude check before scaling: sig digits before exp10 */
        if ((int32_t)sig + exp10 > 31) {
            return SC_ERR_CFG_RANGE;
        }
        while (exp10 > 0) {
            v *= 10.0;
            exp10--;
        }
        while (exp10 < 0) {
            v /= 10.0;
            exp10++;
        }
    }
    *out = neg ? -v : v;
    return 0;
}

static int is_integer_text(const char *s)
{
    const char *p = s;
    if (*p == '-' || *p == '+') {
        p++;
    }
    if (!is_digit(*p)) {
        return 0;
    }
    while (is_digit(*p)) {
        p++;
    }
    return *p == '\0';
}

/* Range check with the reason "V is outside RANGE". */
static int check_range(const key_def *k, double v, const char *text, sc_rtcfg_error *e)
{
    if (v < k->min || v > k->max) {
        why(e, "", text, " is outside ");
        why_range(e, k);
        return SC_ERR_CFG_RANGE;
    }
    return 0;
}

static int parse_int(const key_def *k, const char *v, int32_t *out, sc_rtcfg_error *e)
{
    if (!is_integer_text(v)) {
        why(e, "", v, " is not an integer");
        return SC_ERR_CFG_VALUE;
    }
    double d = 0.0;
    int rc = parse_number(v, &d);
    if (rc == SC_ERR_CFG_RANGE) {
        why(e, "", v, " is outside ");
        why_range(e, k);
        return rc;
    }
    rc = check_range(k, d, v, e);
    if (rc) {
        return rc;
    }
    *out = (int32_t)d; /* exact: an integer within a range far inside int32 */
    return 0;
}

static int parse_real(const key_def *k, const char *v, float *out, sc_rtcfg_error *e)
{
    double d = 0.0;
    int rc = parse_number(v, &d);
    if (rc == SC_ERR_CFG_VALUE) {
        why(e, "", v, " is not a finite decimal number");
        return rc;
    }
    if (rc == SC_ERR_CFG_RANGE) {
        why(e, "", v, " is outside ");
        why_range(e, k);
        return rc;
    }
    rc = check_range(k, d, v, e);
    if (rc) {
        return rc;
    }
    *out = (float)d;
    return 0;
}

/* ---- value kinds ----------------------------------------------------------------------- */

static int parse_enum(const char *const *names, const char *v, uint32_t *out)
{
    for (uint32_t i = 0; names[i]; i++) {
        if (strcmp(names[i], v) == 0) {
            *out = i;
            return 0;
        }
    }
    return SC_ERR_CFG_VALUE;
}

static int parse_bool(const char *v, uint32_t *out)
{
    static const char *const yes[] = {"true", "yes", "on", "1", NULL};
    static const char *const no[] = {"false", "no", "off", "0", NULL};
    uint32_t i;
    if (parse_enum(yes, v, &i) == 0) {
        *out = 1u;
        return 0;
    }
    if (parse_enum(no, v, &i) == 0) {
        *out = 0u;
        return 0;
    }
    return SC_ERR_CFG_VALUE;
}

static int printable(const char *v)
{
    for (const char *p = v; *p; p++) {
        if ((unsigned char)*p < 0x20u || (unsigned char)*p == 0x7Fu) {
            return 0;
        }
    }
    return 1;
}

static int host_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || is_digit(c) || c == '.' || c == '-';
}

static int ifname_char(char c)
{
    return host_char(c) || c == '_';
}

/* Copy a NUL-terminated value into a fixed buffer; SC_ERR_CFG_TOO_LONG when it does not fit. */
static int copy_text(char *dst, size_t cap, const char *v, sc_rtcfg_error *e)
{
    size_t n = strlen(v);
    if (n + 1u > cap) {
        text_out o = reason_out(e);
        if (e) {
            out_str(&o, "longer than ");
            out_u32(&o, (uint32_t)(cap - 1u));
            out_str(&o, " characters");
        }
        return SC_ERR_CFG_TOO_LONG;
    }
    memcpy(dst, v, n + 1u);
    return 0;
}

static int parse_target(sc_rtcfg *c, const char *v, sc_rtcfg_error *e)
{
    sc_rtcfg t = *c;
    if (strcmp(v, "none") == 0) {
        c->display_target = SC_RTCFG_TARGET_NONE;
        return 0;
    }
    if (strcmp(v, "drm") == 0 || strcmp(v, "fbdev") == 0) {
        c->display_target = v[0] == 'd' ? SC_RTCFG_TARGET_DRM : SC_RTCFG_TARGET_FBDEV;
        c->display_path[0] = '\0';
        return 0;
    }
    if (strncmp(v, "drm:", 4u) == 0 || strncmp(v, "fbdev:", 6u) == 0) {
        const int drm = v[0] == 'd';
        const char *path = v + (drm ? 4 : 6);
        if (path[0] != '/') {
            why(e, "device ", path, " is not an absolute path");
            return SC_ERR_CFG_VALUE;
        }
        int rc = copy_text(t.display_path, sizeof t.display_path, path, e);
        if (rc) {
            return rc;
        }
        t.display_target = drm ? SC_RTCFG_TARGET_DRM : SC_RTCFG_TARGET_FBDEV;
        *c = t;
        return 0;
    }
    if (strncmp(v, "png:", 4u) == 0) {
        if (v[4] == '\0') {
            why(e, "png: needs a directory, e.g. png:/tmp/frames", NULL, NULL);
            return SC_ERR_CFG_VALUE;
        }
        int rc = copy_text(t.display_path, sizeof t.display_path, v + 4, e);
        if (rc) {
            return rc;
        }
        t.display_target = SC_RTCFG_TARGET_PNG;
        *c = t;
        return 0;
    }
    if (strncmp(v, "udp:", 4u) == 0) {
        const char *host = v + 4;
        const char *colon = strrchr(host, ':');
        if (!colon || colon == host) {
            why(e, "udp target ", v, " is not udp:HOST:PORT");
            return SC_ERR_CFG_VALUE;
        }
        const size_t hlen = (size_t)(colon - host);
        for (size_t i = 0; i < hlen; i++) {
            if (!host_char(host[i])) {
                why(e, "host of ", v, " is not a hostname or IPv4 address");
                return SC_ERR_CFG_VALUE;
            }
        }
        if (hlen + 1u > sizeof t.display_host) {
            why(e, "host of ", v, " is too long");
            return SC_ERR_CFG_TOO_LONG;
        }
        const char *port = colon + 1;
        if (!is_integer_text(port) || port[0] == '-' || port[0] == '+') {
            why(e, "port ", port, " is not a number");
            return SC_ERR_CFG_VALUE;
        }
        double p = 0.0;
        if (parse_number(port, &p) != 0 || p < 1.0 || p > 65535.0) {
            why(e, "port ", port, " is outside 1 .. 65535");
            return SC_ERR_CFG_RANGE;
        }
        memcpy(t.display_host, host, hlen);
        t.display_host[hlen] = '\0';
        t.display_port = (uint32_t)p;
        t.display_target = SC_RTCFG_TARGET_UDP;
        *c = t;
        return 0;
    }
    why(e, "", v, " is not one of ");
    why_range(e, &k_keys[1]);
    return SC_ERR_CFG_VALUE;
}

static int parse_list(const key_def *k, const char *v, float *out, sc_rtcfg_error *e)
{
    float vals[SC_BSCAN_TGC_BANDS];
    uint32_t n = 0;
    const char *p = v;
    char item[40];
    for (;;) {
        while (is_blank(*p) || *p == ',') {
            p++;
        }
        if (*p == '\0') {
            break;
        }
        size_t len = 0;
        while (p[len] && !is_blank(p[len]) && p[len] != ',') {
            len++;
        }
        if (n == SC_BSCAN_TGC_BANDS) {
            text_out o = reason_out(e);
            if (e) {
                out_str(&o, "more than ");
                out_u32(&o, SC_BSCAN_TGC_BANDS);
                out_str(&o, " values");
            }
            return SC_ERR_CFG_VALUE;
        }
        if (len >= sizeof item) {
            why(e, "a value is too long", NULL, NULL);
            return SC_ERR_CFG_VALUE;
        }
        memcpy(item, p, len);
        item[len] = '\0';
        int rc = parse_real(k, item, &vals[n], e);
        if (rc) {
            return rc;
        }
        n++;
        p += len;
    }
    if (n != SC_BSCAN_TGC_BANDS) {
        text_out o = reason_out(e);
        if (e) {
            out_u32(&o, n);
            out_str(&o, " values given, ");
            out_u32(&o, SC_BSCAN_TGC_BANDS);
            out_str(&o, " expected");
        }
        return SC_ERR_CFG_VALUE;
    }
    memcpy(out, vals, sizeof vals);
    return 0;
}

static int parse_authkey(const key_def *k, char *dst, const char *v, sc_rtcfg_error *e)
{
    size_t hex = 0;
    while (v[hex] && ((v[hex] >= '0' && v[hex] <= '9') || (v[hex] >= 'a' && v[hex] <= 'f') ||
                      (v[hex] >= 'A' && v[hex] <= 'F'))) {
        hex++;
    }
    const int is_hex = v[hex] == '\0' && hex == 32u;
    if (strcmp(v, "bench") != 0 && !is_hex && strncmp(v, "file:/", 6) != 0) {
        why(e, "the key is not ", NULL, NULL);
        why_range(e, k);
        return SC_ERR_CFG_VALUE;
    }
    return copy_text(dst, k->size, v, e);
}

static int parse_wdog(const key_def *k, char *dst, const char *v, sc_rtcfg_error *e)
{
    if (strcmp(v, "none") != 0 && strcmp(v, "soft") != 0 && v[0] != '/') {
        why(e, "", v, " is not ");
        why_range(e, k);
        return SC_ERR_CFG_VALUE;
    }
    return copy_text(dst, k->size, v, e);
}

/* Apply value v (NUL-terminated, trimmed, not empty) to key k. cfg unchanged on error. */
static int apply(sc_rtcfg *cfg, const key_def *k, const char *v, sc_rtcfg_error *e)
{
    uint8_t *base = (uint8_t *)cfg;
    void *field = base + k->off;
    if (!printable(v)) {
        why(e, "value contains a control character", NULL, NULL);
        return SC_ERR_CFG_VALUE;
    }
    switch (k->kind) {
    case K_U32: {
        int32_t i = 0;
        if (v[0] == '-' && is_integer_text(v)) {
            why(e, "", v, " is outside ");
            why_range(e, k);
            return SC_ERR_CFG_RANGE;
        }
        int rc = parse_int(k, v, &i, e);
        if (rc) {
            return rc;
        }
        uint32_t u = (uint32_t)i;
        memcpy(field, &u, sizeof u);
        return 0;
    }
    case K_I32: {
        int32_t i = 0;
        int rc = parse_int(k, v, &i, e);
        if (rc) {
            return rc;
        }
        memcpy(field, &i, sizeof i);
        return 0;
    }
    case K_F32: {
        float f = 0.0f;
        int rc = parse_real(k, v, &f, e);
        if (rc) {
            return rc;
        }
        memcpy(field, &f, sizeof f);
        return 0;
    }
    case K_BOOL: {
        uint32_t b = 0;
        if (parse_bool(v, &b) != 0) {
            why(e, "", v, " is not true or false");
            return SC_ERR_CFG_VALUE;
        }
        memcpy(field, &b, sizeof b);
        return 0;
    }
    case K_ENUM: {
        uint32_t i = 0;
        if (parse_enum(k->names, v, &i) != 0) {
            why(e, "", v, " is not one of ");
            why_range(e, k);
            return SC_ERR_CFG_VALUE;
        }
        memcpy(field, &i, sizeof i);
        return 0;
    }
    case K_PATH:
        return copy_text((char *)field, k->size, v, e);
    case K_IFNAME:
        for (const char *p = v; *p; p++) {
            if (!ifname_char(*p)) {
                why(e, "", v, " has characters outside [A-Za-z0-9_.-]");
                return SC_ERR_CFG_VALUE;
            }
        }
        return copy_text((char *)field, k->size, v, e);
    case K_TARGET:
        return parse_target(cfg, v, e);
    case K_F32LIST:
        return parse_list(k, v, (float *)field, e);
    case K_WDOG:
        return parse_wdog(k, (char *)field, v, e);
    case K_AUTHKEY:
        return parse_authkey(k, (char *)field, v, e);
    }
    return SC_ERR_CFG_VALUE;
}

static const key_def *find_key(const char *key, size_t len, uint32_t *index)
{
    for (uint32_t i = 0; i < KEY_COUNT; i++) {
        if (strlen(k_keys[i].name) == len && memcmp(k_keys[i].name, key, len) == 0) {
            *index = i;
            return &k_keys[i];
        }
    }
    return NULL;
}

/* Default of key k as text: numeric defaults are formatted from the table (a list repeats its
 * one default per band), so they go through the same parser as a file would. */
static void out_default(text_out *o, const key_def *k)
{
    if (!is_numeric(k)) {
        out_str(o, k->def_text);
        return;
    }
    const uint32_t n = k->kind == K_F32LIST ? SC_BSCAN_TGC_BANDS : 1u;
    for (uint32_t i = 0; i < n; i++) {
        if (i) {
            out_str(o, " ");
        }
        out_num(o, k->def);
    }
}

void sc_rtcfg_default(sc_rtcfg *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    for (uint32_t i = 0; i < KEY_COUNT; i++) {
        char text[SC_RTCFG_REASON_MAX];
        text_out o = {text, sizeof text, 0u};
        text[0] = '\0';
        out_default(&o, &k_keys[i]);
        int rc = apply(cfg, &k_keys[i], text, NULL);
        SC_ASSERT(rc == 0);
        (void)rc;
    }
}

uint32_t sc_rtcfg_parse(sc_rtcfg *cfg, const char *text, size_t len, sc_rtcfg_error *errs,
                        uint32_t max_errs, uint32_t *n_errs_stored)
{
    uint32_t line_no_of_key[KEY_COUNT] = {0};
    uint64_t seen = 0;
    uint32_t bad = 0;
    uint32_t stored = 0;
    sc_rtcfg_error scratch;
    char value[SC_RTCFG_LINE_MAX + 1u];
    size_t pos = 0;
    uint32_t line_no = 0;
    while (pos < len) {
        line_no++;
        size_t start = pos;
        size_t end = start;
        while (end < len && text[end] != '\n') {
            end++;
        }
        pos = end < len ? end + 1u : end;
        if (end > start && text[end - 1u] == '\r') {
            end--;
        }
        sc_rtcfg_error *e = stored < max_errs && errs ? &errs[stored] : &scratch;
        int rc = 0;
        /* trim leading blanks */
        size_t a = start;
        while (a < end && is_blank(text[a])) {
            a++;
        }
        if (end - start > SC_RTCFG_LINE_MAX) {
            rc = SC_ERR_CFG_TOO_LONG;
            set_error(e, rc, line_no, NULL, 0u);
            text_out o = reason_out(e);
            out_str(&o, "line longer than ");
            out_u32(&o, SC_RTCFG_LINE_MAX);
            out_str(&o, " bytes");
        } else if (a == end || text[a] == '#') {
            continue;
        } else {
            size_t ctl = start;
            while (ctl < end && ((unsigned char)text[ctl] >= 0x20u || text[ctl] == '\t') &&
                   (unsigned char)text[ctl] != 0x7Fu) {
                ctl++;
            }
            size_t eq = a;
            while (eq < end && text[eq] != '=') {
                eq++;
            }
            size_t kend = eq;
            while (kend > a && is_blank(text[kend - 1u])) {
                kend--;
            }
            if (ctl < end) {
                rc = SC_ERR_CFG_SYNTAX;
                set_error(e, rc, line_no, NULL, 0u);
                text_out o = reason_out(e);
                out_str(&o, "control character in column ");
                out_u32(&o, (uint32_t)(ctl - start + 1u));
            } else if (eq == end) {
                rc = SC_ERR_CFG_SYNTAX;
                set_error(e, rc, line_no, NULL, 0u);
                why(e, "expected key = value", NULL, NULL);
            } else if (kend == a) {
                rc = SC_ERR_CFG_SYNTAX;
                set_error(e, rc, line_no, NULL, 0u);
                why(e, "missing key before '='", NULL, NULL);
            } else {
                uint32_t ki = 0;
                const key_def *k = find_key(text + a, kend - a, &ki);
                /* value: after '=', up to a comment ('#' after a blank), trimmed */
                size_t vs = eq + 1u;
                while (vs < end && is_blank(text[vs])) {
                    vs++;
                }
                size_t ve = vs;
                while (ve < end && !(text[ve] == '#' && ve > eq + 1u && is_blank(text[ve - 1u]))) {
                    ve++;
                }
                while (ve > vs && is_blank(text[ve - 1u])) {
                    ve--;
                }
                set_error(e, 0, line_no, text + a, kend - a);
                if (!k) {
                    rc = SC_ERR_CFG_KEY;
                    why(e, "unknown key", NULL, NULL);
                } else if (seen & (UINT64_C(1) << ki)) {
                    rc = SC_ERR_CFG_DUPLICATE;
                    text_out o = reason_out(e);
                    out_str(&o, "already set on line ");
                    out_u32(&o, line_no_of_key[ki]);
                } else if (ve == vs) {
                    rc = SC_ERR_CFG_VALUE;
                    why(e, "empty value; expected ", NULL, NULL);
                    why_range(e, k);
                } else {
                    memcpy(value, text + vs, ve - vs);
                    value[ve - vs] = '\0';
                    rc = apply(cfg, k, value, e);
                    if (rc == 0) {
                        seen |= UINT64_C(1) << ki;
                        line_no_of_key[ki] = line_no;
                    }
                }
                e->err = rc;
            }
        }
        if (rc != 0) {
            bad++;
            if (e != &scratch) {
                stored++;
            }
        }
    }
    if (n_errs_stored) {
        *n_errs_stored = stored;
    }
    return bad;
}

int sc_rtcfg_set(sc_rtcfg *cfg, const char *key, const char *value, sc_rtcfg_error *err)
{
    sc_rtcfg_error scratch;
    sc_rtcfg_error *e = err ? err : &scratch;
    if (!cfg || !key || !value) {
        set_error(e, SC_ERR_CFG_SYNTAX, 0u, NULL, 0u);
        return SC_ERR_CFG_SYNTAX;
    }
    uint32_t ki = 0;
    const size_t klen = strlen(key);
    const key_def *k = find_key(key, klen, &ki);
    set_error(e, 0, 0u, key, klen);
    if (!k) {
        e->err = SC_ERR_CFG_KEY;
        why(e, "unknown key", NULL, NULL);
        return SC_ERR_CFG_KEY;
    }
    if (value[0] == '\0') {
        e->err = SC_ERR_CFG_VALUE;
        why(e, "empty value; expected ", NULL, NULL);
        why_range(e, k);
        return SC_ERR_CFG_VALUE;
    }
    if (strlen(value) > SC_RTCFG_LINE_MAX) {
        e->err = SC_ERR_CFG_TOO_LONG;
        text_out o = reason_out(e);
        out_str(&o, "value longer than ");
        out_u32(&o, SC_RTCFG_LINE_MAX);
        out_str(&o, " bytes");
        return SC_ERR_CFG_TOO_LONG;
    }
    int rc = apply(cfg, k, value, e);
    e->err = rc;
    return rc;
}

uint32_t sc_rtcfg_key_count(void)
{
    return (uint32_t)KEY_COUNT;
}

int sc_rtcfg_key_describe(uint32_t i, sc_rtcfg_key_info *out)
{
    if (i >= KEY_COUNT || !out) {
        return SC_ERR_RANGE;
    }
    const key_def *k = &k_keys[i];
    out->name = k->name;
    out->help = k->help;
    text_out d = {out->default_text, sizeof out->default_text, 0u};
    out->default_text[0] = '\0';
    out_default(&d, k);
    text_out r = {out->range_text, sizeof out->range_text, 0u};
    out->range_text[0] = '\0';
    if (k->kind == K_U32 || k->kind == K_I32) {
        out_str(&r, "integer ");
    } else if (k->kind == K_F32) {
        out_str(&r, "number ");
    } else if (k->kind == K_F32LIST) {
        out_u32(&r, SC_BSCAN_TGC_BANDS);
        out_str(&r, " numbers, separated by blanks or commas, each ");
    }
    out_range(&r, k);
    return 0;
}

static const char *name_of(const char *const *names, uint32_t i, uint32_t n)
{
    return i < n ? names[i] : "?";
}

const char *sc_rtcfg_target_name(uint32_t target)
{
    return name_of(k_target_names, target, 5u);
}

const char *sc_rtcfg_method_name(uint32_t method)
{
    return name_of(k_method_names, method, 2u);
}

const char *sc_rtcfg_geometry_name(uint32_t geometry)
{
    return name_of(k_geometry_names, geometry, 2u);
}
