/* sc_bundle.c: session bundles; see sc_bundle.h and docs/session-bundle.md. */
#include "sc_bundle.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sc_crc32.h"
#include "sc_err.h"

const char *sc_bundle_reject_name(sc_bundle_reject r)
{
    switch (r) {
    case SC_BDL_OK:
        return "ok";
    case SC_BDL_MAGIC:
        return "not a bundle";
    case SC_BDL_VERSION:
        return "unknown version";
    case SC_BDL_TRUNCATED:
        return "truncated";
    case SC_BDL_CRC:
        return "checksum mismatch";
    case SC_BDL_FIELD:
        return "bad header field";
    case SC_BDL_SECTION:
        return "bad section header";
    case SC_BDL_CAN_LINE:
        return "bad CAN record";
    case SC_BDL_EVENT_LINE:
        return "bad event line";
    case SC_BDL_HASH_LINE:
        return "bad image hash line";
    case SC_BDL_TRAILING:
        return "bytes after the end line";
    case SC_BDL_COUNT:
        break;
    }
    return "?";
}

const char *sc_bundle_call_name(uint8_t call)
{
    return call == 1u ? "normal" : call == 2u ? "dvt" : "none";
}

static int call_from_name(const char *s, size_t n, uint8_t *out)
{
    static const char *const names[3] = {"none", "normal", "dvt"};
    for (uint8_t i = 0; i < 3u; i++) {
        if (strlen(names[i]) == n && memcmp(s, names[i], n) == 0) {
            *out = i;
            return 1;
        }
    }
    return 0;
}

int sc_bundle_is_bundle(const uint8_t *buf, size_t len)
{
    const size_t m = sizeof(SC_BUNDLE_MAGIC) - 1u;
    return buf != NULL && len > m && memcmp(buf, SC_BUNDLE_MAGIC, m) == 0 && buf[m] == ' ';
}

/* ---- parsing ------------------------------------------------------------------------------ */

typedef struct cursor {
    const uint8_t *buf;
    size_t len, pos;
    uint64_t line_no;
} cursor;

/* Next line (without '\n'); 0 when no complete line is left. */
static int take_line(cursor *c, const char **line, size_t *n)
{
    if (c->pos >= c->len) {
        return 0;
    }
    const uint8_t *start = c->buf + c->pos;
    const uint8_t *nl = memchr(start, '\n', c->len - c->pos);
    if (nl == NULL) {
        return 0;
    }
    *line = (const char *)start;
    *n = (size_t)(nl - start);
    c->pos += *n + 1u;
    c->line_no++;
    return 1;
}

static int printable(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if ((unsigned char)s[i] < 0x20u || (unsigned char)s[i] > 0x7Eu) {
            return 0;
        }
    }
    return 1;
}

/* Unsigned decimal, no sign, no leading blanks, at most max. */
static int parse_u64(const char *s, size_t n, uint64_t max, uint64_t *out)
{
    if (n == 0u || n > 20u) {
        return 0;
    }
    uint64_t v = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9') {
            return 0;
        }
        const uint64_t d = (uint64_t)(s[i] - '0');
        if (v > (UINT64_MAX - d) / 10u) {
            return 0;
        }
        v = v * 10u + d;
    }
    if (v > max) {
        return 0;
    }
    *out = v;
    return 1;
}

/* "0x" and exactly `digits` hex digits (digits 8 or 16); no prefix when prefix is 0. */
static int parse_hex(const char *s, size_t n, int prefix, size_t digits, uint64_t *out)
{
    if (prefix) {
        if (n < 2u || s[0] != '0' || s[1] != 'x') {
            return 0;
        }
        s += 2;
        n -= 2u;
    }
    if (n != digits) {
        return 0;
    }
    uint64_t v = 0;
    for (size_t i = 0; i < n; i++) {
        const char ch = s[i];
        uint64_t d;
        if (ch >= '0' && ch <= '9') {
            d = (uint64_t)(ch - '0');
        } else if (ch >= 'a' && ch <= 'f') {
            d = (uint64_t)(ch - 'a') + 10u;
        } else {
            return 0;
        }
        v = (v << 4) | d;
    }
    *out = v;
    return 1;
}

static int parse_float(const char *s, size_t n, float *out)
{
    char tmp[40];
    if (n == 0u || n >= sizeof tmp) {
        return 0;
    }
    memcpy(tmp, s, n);
    tmp[n] = '\0';
    char *end;
    errno = 0;
    const double v = strtod(tmp, &end);
    if (errno != 0 || end != tmp + n || !isfinite(v) || v < -1.0 || v > 1e6) {
        return 0;
    }
    *out = (float)v;
    return 1;
}

/* A header line "<key> <value>": the value's start and length. */
static int key_value(cursor *c, const char *key, const char **val, size_t *n)
{
    const char *line;
    size_t len;
    if (!take_line(c, &line, &len)) {
        return -1; /* truncated */
    }
    const size_t k = strlen(key);
    if (len < k + 2u || memcmp(line, key, k) != 0 || line[k] != ' ' || !printable(line, len)) {
        return 0;
    }
    *val = line + k + 1u;
    *n = len - k - 1u;
    return 1;
}

/* Copy a text value (no blanks, no '/', non-empty, fits). */
static int text_value(const char *v, size_t n, int allow_slash, char *out)
{
    if (n == 0u || n >= SC_BUNDLE_TEXT_MAX) {
        return 0;
    }
    for (size_t i = 0; i < n; i++) {
        if (v[i] == ' ' || (!allow_slash && v[i] == '/')) {
            return 0;
        }
    }
    if (!allow_slash && n <= 2u && v[0] == '.') {
        return 0; /* "." and ".." are not case names */
    }
    memcpy(out, v, n);
    out[n] = '\0';
    return 1;
}

/* Split "a b c" (single blanks, no empty field) into at most cap fields; returns the count,
 * or cap + 1 for more fields or an empty one. */
static size_t split(const char *s, size_t n, const char **f, size_t *fl, size_t cap)
{
    size_t k = 0, i = 0;
    for (;;) {
        size_t j = i;
        while (j < n && s[j] != ' ') {
            j++;
        }
        if (j == i || k == cap) {
            return cap + 1u; /* empty field, or too many */
        }
        f[k] = s + i;
        fl[k] = j - i;
        k++;
        if (j == n) {
            return k;
        }
        i = j + 1u;
    }
}

/* "k=value" with key k into a float. */
static int kv_float(const char *s, size_t n, const char *k, float *out)
{
    const size_t kl = strlen(k);
    return n > kl + 1u && memcmp(s, k, kl) == 0 && s[kl] == '=' &&
           parse_float(s + kl + 1u, n - kl - 1u, out);
}

static int parse_header(cursor *c, sc_bundle_meta *m, sc_bundle_reject *why)
{
    const char *v;
    size_t n;
    uint64_t u;
    int r;
#define FIELD(key)                                                                             \
    r = key_value(c, key, &v, &n);                                                             \
    if (r <= 0) {                                                                              \
        *why = r < 0 ? SC_BDL_TRUNCATED : SC_BDL_FIELD;                                        \
        return SC_ERR_PARSE;                                                                   \
    }
#define BAD()                                                                                  \
    do {                                                                                       \
        *why = SC_BDL_FIELD;                                                                   \
        return SC_ERR_PARSE;                                                                   \
    } while (0)
    FIELD("case");
    if (!text_value(v, n, 0, m->case_name)) {
        BAD();
    }
    FIELD("case_id");
    if (!parse_hex(v, n, 1, 8u, &u)) {
        BAD();
    }
    m->case_id = (uint32_t)u;
    FIELD("method");
    if (n == 4u && memcmp(v, "msds", 4) == 0) {
        m->method = 0u;
    } else if (n == 3u && memcmp(v, "fem", 3) == 0) {
        m->method = 1u;
    } else {
        BAD();
    }
    FIELD("rate_hz");
    if (!parse_u64(v, n, 1000u, &u) || u < 1u) {
        BAD();
    }
    m->rate_hz = (uint32_t)u;
    FIELD("frames");
    if (!parse_u64(v, n, SC_BUNDLE_FRAMES_MAX, &u)) {
        BAD();
    }
    m->frames = u;
    FIELD("rx_cost_us");
    if (!parse_u64(v, n, 10000u, &u)) {
        BAD();
    }
    m->rx_cost_us = (uint32_t)u;
    FIELD("source");
    if (!text_value(v, n, 1, m->source)) {
        BAD();
    }
    FIELD("date");
    if (!text_value(v, n, 0, m->date)) {
        BAD();
    }
    FIELD("score");
    const char *f[4];
    size_t fl[4];
    if (split(v, n, f, fl, 3u) != 3u || !parse_u64(f[0], fl[0], 255u, &u)) {
        BAD();
    }
    m->score = (uint32_t)u;
    if (!parse_u64(f[1], fl[1], 255u, &u) || u < m->score) {
        BAD();
    }
    m->score_max = (uint32_t)u;
    if (!parse_hex(f[2], fl[2], 1, 2u, &u)) {
        BAD();
    }
    m->criteria = (uint32_t)u;
    FIELD("call");
    if (!call_from_name(v, n, &m->call)) {
        BAD();
    }
    FIELD("finding");
    if (!call_from_name(v, n, &m->finding)) {
        BAD();
    }
    FIELD("assessment");
    if (split(v, n, f, fl, 4u) != 4u || !kv_float(f[0], fl[0], "vein", &m->min_ratio[0]) ||
        !kv_float(f[1], fl[1], "artery", &m->min_ratio[1]) ||
        !kv_float(f[2], fl[2], "thrombus", &m->min_ratio[2]) ||
        !kv_float(f[3], fl[3], "peak_force", &m->peak_force_n)) {
        BAD();
    }
#undef FIELD
#undef BAD
    return 0;
}

/* "<name> <count>" opening a section. */
static int section(cursor *c, const char *name, uint64_t max, uint64_t *count,
                   sc_bundle_reject *why)
{
    const char *v;
    size_t n;
    const int r = key_value(c, name, &v, &n);
    if (r <= 0) {
        *why = r < 0 ? SC_BDL_TRUNCATED : SC_BDL_SECTION;
        return SC_ERR_PARSE;
    }
    if (!parse_u64(v, n, max, count)) {
        *why = SC_BDL_SECTION;
        return SC_ERR_PARSE;
    }
    return 0;
}

static int event_line_ok(const char *s, size_t n, uint64_t frames)
{
    const char *f[6];
    size_t fl[6];
    if (split(s, n, f, fl, 5u) != 5u) {
        return 0;
    }
    uint64_t u;
    if (!parse_u64(f[0], fl[0], frames, &u) || fl[1] == 0u || fl[1] > 63u) {
        return 0;
    }
    for (size_t i = 0; i < fl[1]; i++) {
        const char ch = f[1][i];
        if (!((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '?')) {
            return 0;
        }
    }
    for (int k = 2; k < 5; k++) { /* signed decimals */
        const char *p = f[k];
        size_t l = fl[k];
        if (l > 0u && p[0] == '-') {
            p++;
            l--;
        }
        if (!parse_u64(p, l, (uint64_t)INT64_MAX, &u)) {
            return 0;
        }
    }
    return 1;
}

int sc_bundle_parse(const uint8_t *buf, size_t len, sc_bundle_info *out, sc_bundle_reject *why,
                    uint64_t *line_out)
{
    sc_bundle_reject dummy;
    if (why == NULL) {
        why = &dummy;
    }
    *why = SC_BDL_OK;
    cursor c = {.buf = buf, .len = buf ? len : 0u};
    sc_bundle_info info;
    memset(&info, 0, sizeof info);
    int rc = SC_ERR_PARSE;
    const char *line;
    size_t n;
    uint64_t u;
    if (!sc_bundle_is_bundle(buf, len)) {
        *why = SC_BDL_MAGIC;
        goto out;
    }
    if (!take_line(&c, &line, &n)) {
        *why = SC_BDL_TRUNCATED;
        goto out;
    }
    if (!parse_u64(line + 9, n - 9u, UINT32_MAX, &u)) {
        *why = SC_BDL_MAGIC;
        goto out;
    }
    if (u != SC_BUNDLE_VERSION) {
        *why = SC_BDL_VERSION;
        goto out;
    }
    if (parse_header(&c, &info.meta, why) != 0) {
        goto out;
    }
    /* CAN records: candump -l lines in time order */
    if (section(&c, "can", UINT32_MAX, &info.can_count, why) != 0) {
        goto out;
    }
    info.can_off = c.pos;
    uint64_t last_us = 0;
    for (uint64_t i = 0; i < info.can_count; i++) {
        if (!take_line(&c, &line, &n)) {
            *why = SC_BDL_TRUNCATED;
            goto out;
        }
        sc_candump_rec r;
        sc_candump_reject cr;
        if (sc_candump_parse_line(line, n, &r, &cr) != 0 || r.ts_us < last_us) {
            *why = SC_BDL_CAN_LINE;
            goto out;
        }
        last_us = r.ts_us;
    }
    info.can_len = c.pos - info.can_off;
    if (section(&c, "events", UINT32_MAX, &info.ev_count, why) != 0) {
        goto out;
    }
    info.ev_off = c.pos;
    for (uint64_t i = 0; i < info.ev_count; i++) {
        if (!take_line(&c, &line, &n)) {
            *why = SC_BDL_TRUNCATED;
            goto out;
        }
        if (!event_line_ok(line, n, info.meta.frames)) {
            *why = SC_BDL_EVENT_LINE;
            goto out;
        }
    }
    info.ev_len = c.pos - info.ev_off;
    if (section(&c, "hashes", SC_BUNDLE_FRAMES_MAX, &info.hash_count, why) != 0) {
        goto out;
    }
    if (info.hash_count != info.meta.frames) {
        *why = SC_BDL_SECTION;
        goto out;
    }
    info.hash_off = c.pos;
    for (uint64_t i = 0; i < info.hash_count; i++) {
        if (!take_line(&c, &line, &n)) {
            *why = SC_BDL_TRUNCATED;
            goto out;
        }
        const char *f[3];
        size_t fl[3];
        uint64_t h;
        if (split(line, n, f, fl, 2u) != 2u || !parse_u64(f[0], fl[0], UINT64_MAX, &u) ||
            u != i || !parse_hex(f[1], fl[1], 0, 16u, &h)) {
            *why = SC_BDL_HASH_LINE;
            goto out;
        }
    }
    info.hash_len = c.pos - info.hash_off;
    /* the end line: the CRC-32 of every byte before it */
    const size_t crc_end = c.pos;
    const char *v;
    const int r = key_value(&c, "end", &v, &n);
    if (r < 0) {
        *why = SC_BDL_TRUNCATED;
        goto out;
    }
    if (r == 0 || !parse_hex(v, n, 1, 8u, &u)) {
        *why = SC_BDL_FIELD;
        goto out;
    }
    info.crc = sc_crc32(buf, crc_end);
    if ((uint32_t)u != info.crc) {
        *why = SC_BDL_CRC;
        goto out;
    }
    if (c.pos != len) {
        *why = SC_BDL_TRAILING;
        goto out;
    }
    if (out != NULL) {
        *out = info;
    }
    rc = 0;
out:
    if (line_out != NULL) {
        *line_out = rc == 0 ? 0u : c.line_no + (*why == SC_BDL_TRUNCATED ? 1u : 0u);
    }
    return rc;
}

int sc_bundle_next_line(const uint8_t *buf, size_t end, size_t *pos, const char **line,
                        size_t *len)
{
    cursor c = {.buf = buf, .len = end, .pos = *pos};
    if (!take_line(&c, line, len)) {
        return 0;
    }
    *pos = c.pos;
    return 1;
}

uint64_t sc_bundle_hash_of_line(const char *line, size_t len)
{
    uint64_t h = 0;
    if (len >= 16u) {
        (void)parse_hex(line + len - 16u, 16u, 0, 16u, &h);
    }
    return h;
}

/* ---- writing ------------------------------------------------------------------------------ */

int sc_bundle_writer_open(sc_bundle_writer *w)
{
    memset(w, 0, sizeof(*w));
    w->can = tmpfile();
    w->ev = tmpfile();
    w->hash = tmpfile();
    if (!w->can || !w->ev || !w->hash) {
        sc_bundle_writer_close(w);
        return SC_ERR_IO;
    }
    return 0;
}

void sc_bundle_add_can(sc_bundle_writer *w, const sc_candump_rec *r)
{
    if (w->can == NULL || sc_candump_write(w->can, r) != 0) {
        w->failed = 1;
        return;
    }
    w->n_can++;
}

void sc_bundle_add_event(sc_bundle_writer *w, uint64_t frame, const char *event, int err,
                         int64_t a, int64_t b)
{
    char name[64];
    size_t n = 0;
    for (; event != NULL && event[n] != '\0' && n < sizeof name - 1u; n++) {
        const char ch = event[n];
        name[n] = (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' ? ch : '?';
    }
    if (n == 0u) {
        name[n++] = '?';
    }
    name[n] = '\0';
    if (w->ev == NULL || fprintf(w->ev, "%" PRIu64 " %s %d %" PRId64 " %" PRId64 "\n", frame,
                                 name, err, a, b) < 0) {
        w->failed = 1;
        return;
    }
    w->n_ev++;
}

void sc_bundle_add_hash(sc_bundle_writer *w, uint64_t frame, uint64_t hash)
{
    if (w->hash == NULL || fprintf(w->hash, "%" PRIu64 " %016" PRIx64 "\n", frame, hash) < 0) {
        w->failed = 1;
        return;
    }
    w->n_hash++;
}

/* Writes buf to fp and adds it to the CRC. */
static int put(FILE *fp, uint32_t *crc, const void *buf, size_t n)
{
    *crc = sc_crc32_update(*crc, buf, n);
    return fwrite(buf, 1, n, fp) == n ? 0 : -1;
}

static int putf(FILE *fp, uint32_t *crc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int putf(FILE *fp, uint32_t *crc, const char *fmt, ...)
{
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    const int n = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof line) {
        return -1;
    }
    return put(fp, crc, line, (size_t)n);
}

static int copy(FILE *dst, uint32_t *crc, FILE *src)
{
    if (fflush(src) != 0 || fseek(src, 0, SEEK_SET) != 0) {
        return -1;
    }
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, src)) > 0u) {
        if (put(dst, crc, buf, n) != 0) {
            return -1;
        }
    }
    return ferror(src) ? -1 : 0;
}

static float ratio_or_na(float v)
{
    return isfinite(v) && v >= 0.0f ? v : -1.0f;
}

int sc_bundle_writer_finish(sc_bundle_writer *w, const sc_bundle_meta *m, const char *path)
{
    char name_ok[SC_BUNDLE_TEXT_MAX], tmp_text[SC_BUNDLE_TEXT_MAX];
    if (w->failed || w->can == NULL) {
        return SC_ERR_IO;
    }
    if (!text_value(m->case_name, strlen(m->case_name), 0, name_ok) ||
        !text_value(m->source, strlen(m->source), 1, tmp_text) ||
        !text_value(m->date, strlen(m->date), 0, tmp_text) || m->frames != w->n_hash ||
        m->frames > SC_BUNDLE_FRAMES_MAX || m->rate_hz < 1u || m->rate_hz > 1000u ||
        m->method > 1u || m->score > m->score_max || m->score_max > 255u ||
        m->criteria > 255u || m->call > 2u || m->finding > 2u || m->rx_cost_us > 10000u) {
        return SC_ERR_INVALID_ARG;
    }
    char tmp[4200];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        return SC_ERR_INVALID_ARG;
    }
    FILE *fp = fopen(tmp, "wb");
    if (fp == NULL) {
        return SC_ERR_IO;
    }
    uint32_t crc = SC_CRC32_INIT;
    int bad = 0;
    bad |= putf(fp, &crc, "%s %u\n", SC_BUNDLE_MAGIC, SC_BUNDLE_VERSION);
    bad |= putf(fp, &crc, "case %s\ncase_id 0x%08x\nmethod %s\nrate_hz %u\nframes %" PRIu64
                           "\nrx_cost_us %u\nsource %s\ndate %s\n",
                m->case_name, m->case_id, m->method ? "fem" : "msds", m->rate_hz, m->frames,
                m->rx_cost_us, m->source, m->date);
    bad |= putf(fp, &crc, "score %u %u 0x%02x\ncall %s\nfinding %s\n", m->score, m->score_max,
                m->criteria, sc_bundle_call_name(m->call), sc_bundle_call_name(m->finding));
    bad |= putf(fp, &crc, "assessment vein=%.4f artery=%.4f thrombus=%.4f peak_force=%.3f\n",
                (double)ratio_or_na(m->min_ratio[0]), (double)ratio_or_na(m->min_ratio[1]),
                (double)ratio_or_na(m->min_ratio[2]), (double)ratio_or_na(m->peak_force_n));
    bad |= putf(fp, &crc, "can %" PRIu64 "\n", w->n_can);
    bad |= copy(fp, &crc, w->can);
    bad |= putf(fp, &crc, "events %" PRIu64 "\n", w->n_ev);
    bad |= copy(fp, &crc, w->ev);
    bad |= putf(fp, &crc, "hashes %" PRIu64 "\n", w->n_hash);
    bad |= copy(fp, &crc, w->hash);
    if (fprintf(fp, "end 0x%08x\n", sc_crc32_final(crc)) < 0) {
        bad = 1;
    }
    if (fclose(fp) != 0 || bad) {
        remove(tmp);
        return SC_ERR_IO;
    }
    if (rename(tmp, path) != 0) {
        remove(tmp);
        return SC_ERR_IO;
    }
    return 0;
}

void sc_bundle_writer_close(sc_bundle_writer *w)
{
    FILE *f[3] = {w->can, w->ev, w->hash};
    for (int i = 0; i < 3; i++) {
        if (f[i] != NULL) {
            fclose(f[i]);
        }
    }
    w->can = w->ev = w->hash = NULL;
}

int sc_bundle_read_file(const char *path, size_t max_bytes, uint8_t **buf, size_t *len)
{
    *buf = NULL;
    *len = 0;
    FILE *fp = fopen(path, "rb");
    if (fp == NULL) {
        return SC_ERR_IO;
    }
    struct stat st;
    if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(fp);
        return SC_ERR_IO;
    }
    if ((uint64_t)st.st_size > (uint64_t)max_bytes) {
        fclose(fp);
        return SC_ERR_NO_SPACE;
    }
    const size_t n = (size_t)st.st_size;
    uint8_t *b = malloc(n ? n : 1u);
    if (b == NULL) {
        fclose(fp);
        return SC_ERR_NO_SPACE;
    }
    const size_t got = fread(b, 1, n, fp);
    fclose(fp);
    if (got != n) {
        free(b);
        return SC_ERR_IO;
    }
    *buf = b;
    *len = n;
    return 0;
}
