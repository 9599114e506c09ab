/* sc_candump.c: candump -l log lines, see sc_candump.h. */
#include "sc_candump.h"

#include <string.h>

#include "sc_err.h"
#include "sc_socketcan.h"

#define ERR_FLAG 0x20000000u /* CAN_ERR_FLAG */
#define EFF_MASK 0x1FFFFFFFu

const char *sc_candump_reject_name(sc_candump_reject r)
{
    switch (r) {
    case SC_CDR_OK:
        return "ok";
    case SC_CDR_EMPTY:
        return "empty";
    case SC_CDR_LINE_TOO_LONG:
        return "line_too_long";
    case SC_CDR_TIMESTAMP:
        return "timestamp";
    case SC_CDR_IFACE:
        return "iface";
    case SC_CDR_ID:
        return "id";
    case SC_CDR_SEPARATOR:
        return "separator";
    case SC_CDR_DATA:
        return "data";
    case SC_CDR_LENGTH:
        return "length";
    case SC_CDR_FD_FLAGS:
        return "fd_flags";
    case SC_CDR_DLC:
        return "dlc";
    case SC_CDR_TRAILING:
        return "trailing";
    case SC_CDR_COUNT:
        break;
    }
    return "?";
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t';
}

static int fail(sc_candump_reject *why, sc_candump_reject r)
{
    *why = r;
    return SC_ERR_PARSE;
}

int sc_candump_parse_line(const char *line, size_t len, sc_candump_rec *out, sc_candump_reject *why)
{
    while (len > 0u && (line[len - 1u] == '\n' || line[len - 1u] == '\r')) {
        len--;
    }
    size_t i = 0;
    while (i < len && is_space(line[i])) {
        i++;
    }
    if (i == len) {
        return fail(why, SC_CDR_EMPTY);
    }
    if (len > SC_CANDUMP_LINE_MAX) {
        return fail(why, SC_CDR_LINE_TOO_LONG);
    }
    sc_candump_rec r;
    memset(&r, 0, sizeof r);

    /* (seconds.microseconds) */
    if (line[i] != '(') {
        return fail(why, SC_CDR_TIMESTAMP);
    }
    i++;
    uint64_t sec = 0;
    size_t nd = 0;
    while (i < len && line[i] >= '0' && line[i] <= '9') {
        if (nd >= 13u) { /* 10^13 s: far beyond any clock, keeps us within uint64 */
            return fail(why, SC_CDR_TIMESTAMP);
        }
        sec = sec * 10u + (uint64_t)(line[i] - '0');
        i++;
        nd++;
    }
    if (nd == 0u || i >= len || line[i] != '.') {
        return fail(why, SC_CDR_TIMESTAMP);
    }
    i++;
    uint64_t usec = 0;
    nd = 0;
    while (i < len && line[i] >= '0' && line[i] <= '9') {
        if (nd >= 6u) {
            return fail(why, SC_CDR_TIMESTAMP);
        }
        usec = usec * 10u + (uint64_t)(line[i] - '0');
        i++;
        nd++;
    }
    if (nd != 6u || i >= len || line[i] != ')') {
        return fail(why, SC_CDR_TIMESTAMP);
    }
    i++;
    r.ts_us = sec * 1000000u + usec;

    /* interface */
    if (i >= len || !is_space(line[i])) {
        return fail(why, SC_CDR_IFACE);
    }
    while (i < len && is_space(line[i])) {
        i++;
    }
    size_t nl = 0;
    while (i < len && !is_space(line[i])) {
        if (nl >= SC_CANDUMP_IFNAME_MAX || line[i] < '!' || line[i] > '~') {
            return fail(why, SC_CDR_IFACE);
        }
        r.iface[nl++] = line[i++];
    }
    if (nl == 0u) {
        return fail(why, SC_CDR_IFACE);
    }
    if (i >= len) {
        return fail(why, SC_CDR_ID);
    }
    while (i < len && is_space(line[i])) {
        i++;
    }

    /* id */
    uint32_t id = 0;
    size_t nh = 0;
    while (i < len && line[i] != '#') {
        const int h = hexval(line[i]);
        if (h < 0 || nh >= 8u) {
            return fail(why, is_space(line[i]) && nh > 0u ? SC_CDR_SEPARATOR : SC_CDR_ID);
        }
        id = (id << 4) | (uint32_t)h;
        nh++;
        i++;
    }
    if (i >= len) {
        return fail(why, nh == 3u || nh == 8u ? SC_CDR_SEPARATOR : SC_CDR_ID);
    }
    i++; /* '#' */
    sc_can_frame *f = &r.frame;
    int is_err = 0;
    if (nh == 3u) {
        if (id > 0x7FFu) {
            return fail(why, SC_CDR_ID);
        }
        f->id = id;
    } else if (nh == 8u) {
        if (id & ERR_FLAG) {
            if (id & ~(ERR_FLAG | EFF_MASK)) {
                return fail(why, SC_CDR_ID);
            }
            is_err = 1;
        } else if (id > EFF_MASK) {
            return fail(why, SC_CDR_ID);
        }
        f->id = id;
        f->flags = SC_CAN_FLAG_EXT;
    } else {
        return fail(why, SC_CDR_ID);
    }

    size_t maxlen = 8u;
    if (i < len && line[i] == '#') {
        i++;
        if (i < len && line[i] == '#') {
            return fail(why, SC_CDR_SEPARATOR); /* CAN XL */
        }
        if (is_err) {
            return fail(why, SC_CDR_SEPARATOR);
        }
        const int fl = i < len ? hexval(line[i]) : -1;
        if (fl < 0) {
            return fail(why, SC_CDR_FD_FLAGS);
        }
        i++;
        f->flags = (uint8_t)(f->flags | SC_CAN_FLAG_FD | ((fl & 0x01) ? SC_CAN_FLAG_BRS : 0u));
        maxlen = 64u;
    } else if (i < len && line[i] == 'R') {
        i++;
        if (is_err) {
            return fail(why, SC_CDR_DLC);
        }
        f->flags = (uint8_t)(f->flags | SC_CAN_FLAG_RTR);
        if (i < len && !is_space(line[i])) {
            const int d = hexval(line[i]);
            if (d < 0 || d > 8) {
                return fail(why, SC_CDR_DLC);
            }
            f->len = (uint8_t)d;
            i++;
        }
        maxlen = 0u;
    }

    /* data */
    size_t nb = 0;
    int last_dot = 0;
    while (maxlen > 0u && i < len && !is_space(line[i]) && line[i] != '_') {
        if (line[i] == '.') {
            if (nb == 0u || last_dot) {
                return fail(why, SC_CDR_DATA);
            }
            last_dot = 1;
            i++;
            continue;
        }
        const int hi = hexval(line[i]);
        const int lo = i + 1u < len ? hexval(line[i + 1u]) : -1;
        if (hi < 0 || lo < 0) {
            return fail(why, SC_CDR_DATA);
        }
        if (nb >= maxlen) {
            return fail(why, SC_CDR_LENGTH);
        }
        f->data[nb++] = (uint8_t)((hi << 4) | lo);
        last_dot = 0;
        i += 2u;
    }
    if (last_dot) {
        return fail(why, SC_CDR_DATA);
    }
    if (!(f->flags & SC_CAN_FLAG_RTR)) {
        f->len = (uint8_t)nb;
    }
    if ((f->flags & SC_CAN_FLAG_FD) && !sc_can_len_valid(f->len, f->flags)) {
        return fail(why, SC_CDR_LENGTH);
    }
    if (i < len && line[i] == '_') {
        /* len8_dlc: only after exactly 8 bytes of a classic data frame, digit 9..F */
        const int d = i + 1u < len ? hexval(line[i + 1u]) : -1;
        if ((f->flags & (SC_CAN_FLAG_FD | SC_CAN_FLAG_RTR)) || f->len != 8u || d < 9) {
            return fail(why, SC_CDR_DLC);
        }
        i += 2u;
    }
    /* optional direction marker, then only blanks */
    size_t j = i;
    while (j < len && is_space(line[j])) {
        j++;
    }
    if (j > i && j < len && (line[j] == 'R' || line[j] == 'T')) {
        j++;
    }
    while (j < len && is_space(line[j])) {
        j++;
    }
    if (j != len || (i < len && !is_space(line[i]))) {
        return fail(why, SC_CDR_TRAILING);
    }

    if (is_err) {
        uint8_t d[8] = {0};
        memcpy(d, f->data, f->len);
        f->flags = SC_CAN_FLAG_ERR;
        f->id = sc_socketcan_errf_from_linux(id, d);
        f->len = 8u;
        memcpy(f->data, d, 8u);
    }
    f->ts_ns = r.ts_us * 1000u;
    *out = r;
    *why = SC_CDR_OK;
    return 0;
}

static const char hexdig[] = "0123456789ABCDEF";

int sc_candump_format(const sc_candump_rec *r, char *buf, size_t cap)
{
    const size_t nl = strnlen(r->iface, sizeof r->iface);
    if (nl == 0u || nl > SC_CANDUMP_IFNAME_MAX) {
        return SC_ERR_INVALID_ARG;
    }
    for (size_t k = 0; k < nl; k++) {
        if (is_space(r->iface[k]) || r->iface[k] == '\n') {
            return SC_ERR_INVALID_ARG;
        }
    }
    sc_socketcan_raw raw;
    int is_fd = 0;
    if (sc_socketcan_to_raw(&r->frame, &raw, &is_fd) != 0) {
        return SC_ERR_INVALID_ARG;
    }
    char tmp[SC_CANDUMP_LINE_MAX + 64];
    int n =
        snprintf(tmp, sizeof tmp, "(%010llu.%06llu) %s ", (unsigned long long)(r->ts_us / 1000000u),
                 (unsigned long long)(r->ts_us % 1000000u), r->iface);
    if (n < 0) {
        return SC_ERR_INVALID_ARG;
    }
    size_t o = (size_t)n;
    const sc_can_frame *f = &r->frame;
    if (f->flags & SC_CAN_FLAG_ERR) {
        o += (size_t)snprintf(tmp + o, sizeof tmp - o, "%08X#", (unsigned)raw.can_id);
    } else if (f->flags & SC_CAN_FLAG_EXT) {
        o += (size_t)snprintf(tmp + o, sizeof tmp - o, "%08X#", (unsigned)f->id);
    } else {
        o += (size_t)snprintf(tmp + o, sizeof tmp - o, "%03X#", (unsigned)f->id);
    }
    const uint8_t *data = (f->flags & SC_CAN_FLAG_ERR) ? raw.data : f->data;
    const size_t dlen = (f->flags & SC_CAN_FLAG_ERR) ? 8u : f->len;
    if (f->flags & SC_CAN_FLAG_FD) {
        tmp[o++] = '#';
        tmp[o++] = hexdig[(f->flags & SC_CAN_FLAG_BRS) ? 1 : 0];
    } else if (f->flags & SC_CAN_FLAG_RTR) {
        tmp[o++] = 'R';
        if (f->len > 0u) {
            tmp[o++] = hexdig[f->len & 0x0Fu];
        }
    }
    if (!(f->flags & SC_CAN_FLAG_RTR)) {
        for (size_t k = 0; k < dlen; k++) {
            tmp[o++] = hexdig[data[k] >> 4];
            tmp[o++] = hexdig[data[k] & 0x0Fu];
        }
    }
    tmp[o++] = '\n';
    tmp[o] = '\0';
    if (o + 1u > cap) {
        return SC_ERR_NO_SPACE;
    }
    memcpy(buf, tmp, o + 1u);
    return (int)o;
}

void sc_candump_reader_init(sc_candump_reader *r, FILE *fp)
{
    memset(r, 0, sizeof *r);
    r->fp = fp;
}

uint32_t sc_candump_reader_rejected_total(const sc_candump_reader *r)
{
    uint32_t s = 0;
    for (unsigned k = 1; k < (unsigned)SC_CDR_COUNT; k++) {
        s += r->rejected[k];
    }
    return s;
}

static void reject(sc_candump_reader *r, sc_candump_reject why)
{
    r->rejected[why]++;
    r->last_reject = why;
    r->last_reject_line = r->line_no;
}

int sc_candump_reader_next(sc_candump_reader *r, sc_candump_rec *out)
{
    char buf[SC_CANDUMP_LINE_MAX + 2u];
    for (;;) {
        /* one line by hand: fgets cannot tell an embedded NUL from the end of the line */
        size_t n = 0;
        int c = EOF, too_long = 0, has_nul = 0;
        while ((c = getc(r->fp)) != EOF) {
            if (c == '\n') {
                break;
            }
            if (c == '\0') {
                has_nul = 1;
            }
            if (n < sizeof buf) {
                buf[n++] = (char)c;
            } else {
                too_long = 1;
            }
        }
        if (c == EOF && n == 0u && !too_long) {
            return ferror(r->fp) ? SC_ERR_IO : SC_ERR_NOT_FOUND;
        }
        r->line_no++;
        if (too_long || n > SC_CANDUMP_LINE_MAX) {
            reject(r, SC_CDR_LINE_TOO_LONG);
            continue;
        }
        if (has_nul) {
            reject(r, SC_CDR_TRAILING);
            continue;
        }
        sc_candump_reject why;
        if (sc_candump_parse_line(buf, n, out, &why) == 0) {
            r->records++;
            return 0;
        }
        reject(r, why);
    }
}

int sc_candump_write(FILE *fp, const sc_candump_rec *r)
{
    char buf[SC_CANDUMP_LINE_MAX + 64];
    const int n = sc_candump_format(r, buf, sizeof buf);
    if (n < 0) {
        return n;
    }
    if (fwrite(buf, 1, (size_t)n, fp) != (size_t)n) {
        return SC_ERR_IO;
    }
    return 0;
}
