/* sc_trkemu.c: scripted probe motions and fault injection for the tracker emulator. */
#include "sc_trkemu.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"

static const char *const script_names[SC_EMU_SCRIPT_COUNT] = {"press", "sweep", "rock", "lift",
                                                              "csv"};
static const char *const fault_names[SC_EMU_F_COUNT] = {"bad-crc", "counter-jump", "repeat",
                                                        "silence", "implausible"};

const char *sc_emu_script_name(sc_emu_script s)
{
    return (unsigned)s < SC_EMU_SCRIPT_COUNT ? script_names[s] : "?";
}

const char *sc_emu_fault_name(sc_emu_fault_kind k)
{
    return (unsigned)k < SC_EMU_F_COUNT ? fault_names[k] : "?";
}

int sc_emu_script_from_name(const char *name, sc_emu_script *out)
{
    for (unsigned i = 0; i < SC_EMU_SCRIPT_COUNT; i++) {
        if (strcmp(name, script_names[i]) == 0) {
            *out = (sc_emu_script)i;
            return 0;
        }
    }
    return SC_ERR_NOT_FOUND;
}

int sc_emu_fault_from_name(const char *name, sc_emu_fault_kind *out)
{
    for (unsigned i = 0; i < SC_EMU_F_COUNT; i++) {
        if (strcmp(name, fault_names[i]) == 0) {
            *out = (sc_emu_fault_kind)i;
            return 0;
        }
    }
    return SC_ERR_NOT_FOUND;
}

sc_emu_def sc_emu_default_def(void)
{
    sc_emu_def d;
    memset(&d, 0, sizeof d);
    d.script = SC_EMU_PRESS;
    d.rate_hz = 100.0;
    d.duration_s = 10.0;
    d.hover_mm = 30.0f;
    d.depth_mm = 10.0f;
    d.length_mm = 60.0f;
    d.period_s = 4.0;
    d.angle_deg = 15.0f;
    d.base_q[1] = 1.0f; /* 180 degrees about x: the beam (probe z) points down */
    d.force_n_per_mm = 0.5f;
    d.force_valid = 1;
    d.silence_ms = 300.0;
    return d;
}

int sc_emu_init(sc_emu *e, const sc_emu_def *def)
{
    memset(e, 0, sizeof *e);
    if (!(def->rate_hz >= 1.0 && def->rate_hz <= 10000.0) || !(def->duration_s > 0.0) ||
        !(def->period_s > 0.0) || def->n_faults > SC_EMU_MAX_FAULTS ||
        (unsigned)def->script >= SC_EMU_SCRIPT_COUNT) {
        return SC_ERR_RANGE;
    }
    if (def->script == SC_EMU_CSV && (def->rows == NULL || def->n_rows == 0u)) {
        return SC_ERR_INVALID_ARG;
    }
    e->def = *def;
    return 0;
}

static float lerpf(float a, float b, double u)
{
    return a + (b - a) * (float)u;
}

static void quat_mul(const float a[4], const float b[4], float out[4])
{
    out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

sc_pose_msg sc_emu_pose_at(const sc_emu_def *d, double t)
{
    sc_pose_msg p;
    memset(&p, 0, sizeof p);
    const float top = d->point_mm[2] + d->hover_mm;
    const float bottom = d->point_mm[2] - d->depth_mm;
    memcpy(p.pos_mm, d->point_mm, sizeof p.pos_mm);
    memcpy(p.q, d->base_q, sizeof p.q);
    switch (d->script) {
    case SC_EMU_PRESS: {
        const double u = fmod(t, 4.0);
        p.pos_mm[2] = u < 0.5   ? top
                      : u < 1.5 ? lerpf(top, bottom, u - 0.5)
                      : u < 2.5 ? bottom
                      : u < 3.5 ? lerpf(bottom, top, u - 2.5)
                                : top;
        break;
    }
    case SC_EMU_SWEEP: {
        const double u = fmod(t / d->period_s, 1.0);
        const double tri = u < 0.5 ? -1.0 + 4.0 * u : 3.0 - 4.0 * u;
        p.pos_mm[0] = d->point_mm[0] + 0.5f * d->length_mm * (float)tri;
        p.pos_mm[2] = bottom;
        break;
    }
    case SC_EMU_ROCK: {
        const double a = (double)d->angle_deg * M_PI / 180.0 * sin(2.0 * M_PI * t / d->period_s);
        const float r[4] = {(float)cos(a / 2.0), 0.0f, (float)sin(a / 2.0), 0.0f};
        quat_mul(d->base_q, r, p.q); /* about the probe's own y axis */
        p.pos_mm[2] = bottom;
        break;
    }
    case SC_EMU_LIFT:
        p.pos_mm[2] = t < 1.0   ? lerpf(top, bottom, t)
                      : t < 2.0 ? bottom
                      : t < 2.5 ? lerpf(bottom, top, (t - 2.0) * 2.0)
                                : top;
        break;
    case SC_EMU_CSV: {
        const sc_emu_row *r = d->rows;
        size_t i = 0;
        while (i + 1u < d->n_rows && r[i + 1u].t_s <= t) {
            i++;
        }
        const sc_emu_row *a = &r[i];
        const sc_emu_row *b = i + 1u < d->n_rows ? &r[i + 1u] : a;
        double u = b->t_s > a->t_s ? (t - a->t_s) / (b->t_s - a->t_s) : 0.0;
        u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
        float dot = 0.0f;
        for (int k = 0; k < 4; k++) {
            dot += a->q[k] * b->q[k];
        }
        const float sign = dot < 0.0f ? -1.0f : 1.0f;
        float n2 = 0.0f;
        for (int k = 0; k < 4; k++) {
            p.q[k] = lerpf(a->q[k], sign * b->q[k], u);
            n2 += p.q[k] * p.q[k];
        }
        for (int k = 0; k < 4; k++) {
            p.q[k] /= sqrtf(n2);
        }
        for (int k = 0; k < 3; k++) {
            p.pos_mm[k] = lerpf(a->pos_mm[k], b->pos_mm[k], u);
        }
        if (a->force_n >= 0.0f && d->force_valid) {
            p.force_valid = 1;
            p.force_n = b->force_n >= 0.0f ? lerpf(a->force_n, b->force_n, u) : a->force_n;
            return p;
        }
        break;
    }
    case SC_EMU_SCRIPT_COUNT:
        break;
    }
    if (d->force_valid) {
        const float pen = d->point_mm[2] - p.pos_mm[2];
        p.force_valid = 1;
        p.force_n = pen > 0.0f ? d->force_n_per_mm * pen : 0.0f;
        if (p.force_n > 600.0f) {
            p.force_n = 600.0f;
        }
    }
    return p;
}

/* The fault due at this sample, if any: at most one per sample (the first in the list wins,
 * so that every injected fault is observable and counted exactly once). */
static int fault_due(const sc_emu *e, double t_s)
{
    for (size_t i = 0; i < e->def.n_faults; i++) {
        const sc_emu_fault *f = &e->def.faults[i];
        if (f->period > 0u && t_s >= f->start_s && e->sample > 0u && e->sample % f->period == 0u) {
            return (int)f->kind;
        }
    }
    return -1;
}

uint64_t sc_emu_next_time_ns(const sc_emu *e)
{
    return (uint64_t)llround((double)e->sample * 1e9 / e->def.rate_hz);
}

int sc_emu_feed(sc_emu *e, uint64_t until_ns, sc_emu_send_fn send, void *ctx)
{
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    int taken = 0;
    while (sc_emu_next_time_ns(e) <= until_ns) {
        uint64_t t_ns;
        const int n = sc_emu_next(e, f, SC_EMU_MAX_FRAMES, &t_ns);
        if (n < 0) {
            return taken > 0 ? taken : n;
        }
        for (int k = 0; k < n; k++) {
            (void)send(ctx, &f[k]);
        }
        taken++;
    }
    return taken;
}

int sc_emu_next(sc_emu *e, sc_can_frame *out, size_t cap, uint64_t *t_ns)
{
    const double t_s = (double)e->sample / e->def.rate_hz;
    if (t_s >= e->def.duration_s) {
        return SC_ERR_NOT_FOUND;
    }
    if (cap < SC_EMU_MAX_FRAMES) {
        return SC_ERR_NO_SPACE;
    }
    *t_ns = (uint64_t)llround((double)e->sample * 1e9 / e->def.rate_hz);
    const int fault = fault_due(e, t_s);
    e->sample++;
    if (fault == SC_EMU_F_SILENCE) {
        e->silent_until_ns = *t_ns + (uint64_t)llround(e->def.silence_ms * 1e6);
        e->injected[SC_EMU_F_SILENCE]++;
    }
    if (*t_ns < e->silent_until_ns || (e->def.script == SC_EMU_LIFT && t_s >= 2.5)) {
        e->samples_silent++;
        return 0;
    }
    sc_pose_msg p = sc_emu_pose_at(&e->def, t_s);
    if (fault == SC_EMU_F_IMPLAUSIBLE) {
        switch (e->implausible_variant++ % 3u) {
        case 0:
            for (int k = 0; k < 4; k++) {
                p.q[k] *= 1.5f; /* norm 1.5 */
            }
            break;
        case 1:
            p.pos_mm[2] = 1500.0f; /* outside the default workspace, still encodable */
            break;
        default:
            p.pos_mm[0] += 100.0f; /* 100 mm in one period: far above any hand speed */
            break;
        }
        e->injected[SC_EMU_F_IMPLAUSIBLE]++;
    }
    if (fault == SC_EMU_F_COUNTER_JUMP) {
        e->counter = (uint8_t)((e->counter + 5u) % 16u);
        e->injected[SC_EMU_F_COUNTER_JUMP]++;
    }
    size_t n = 0;
    const int rc = sc_canproto_encode_pose(&p, e->counter, e->def.fd, out, cap, &n);
    if (rc != 0) {
        return rc;
    }
    e->counter = (uint8_t)((e->counter + 1u) % 16u);
    if (fault == SC_EMU_F_BAD_CRC) {
        out[e->sample % n].data[3] ^= 0x04u;
        e->injected[SC_EMU_F_BAD_CRC]++;
    }
    if (fault == SC_EMU_F_REPEAT) {
        for (size_t k = 0; k < n; k++) {
            out[n + k] = out[k];
        }
        n *= 2u;
        e->injected[SC_EMU_F_REPEAT]++;
    }
    e->samples_sent++;
    e->frames_sent += n;
    return (int)n;
}

/* One line (its '\n' kept) into buf[cap], NUL-terminated: 1, 0 at the end of the file, -1 for a
 * line of cap - 1 bytes or more or one holding a NUL byte (the rest of it is consumed). */
static int read_line(FILE *fp, char *buf, size_t cap)
{
    size_t n = 0;
    int bad = 0, c = EOF;
    while ((c = getc(fp)) != EOF) {
        if (c == 0 || n + 2u > cap) {
            bad = 1;
        } else {
            buf[n++] = (char)c;
        }
        if (c == '\n') {
            break;
        }
    }
    buf[n] = '\0';
    if (c == EOF && n == 0u && !bad) {
        return 0;
    }
    return bad ? -1 : 1;
}

int sc_emu_load_csv(FILE *fp, sc_emu_row *rows, size_t cap, size_t *n, size_t *bad_line)
{
    char line[512];
    size_t count = 0, line_no = 0;
    *bad_line = 0;
    int got;
    while ((got = read_line(fp, line, sizeof line)) != 0) {
        line_no++;
        if (got < 0) {
            /* longer than any row, or a NUL byte: refused, not read in pieces that would each
             * count (and might each parse) as a line of their own */
            *bad_line = line_no;
            return SC_ERR_PARSE;
        }
        char *s = line;
        while (*s == ' ' || *s == '\t') {
            s++;
        }
        if (*s == '#' || *s == '\n' || *s == '\r' || *s == '\0') {
            continue;
        }
        if (line_no == 1u && !(*s == '-' || *s == '.' || (*s >= '0' && *s <= '9'))) {
            continue; /* a header line */
        }
        double v[9];
        int nv = 0;
        char *p = s;
        while (nv < 9) {
            char *end;
            v[nv] = strtod(p, &end);
            if (end == p || !isfinite(v[nv])) {
                break;
            }
            nv++;
            p = end;
            while (*p == ' ' || *p == '\t') {
                p++;
            }
            if (*p != ',') {
                break;
            }
            p++;
        }
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') {
            p++;
        }
        if ((nv != 8 && nv != 9) || *p != '\0' || (count > 0u && !(v[0] > rows[count - 1u].t_s))) {
            *bad_line = line_no;
            return SC_ERR_PARSE;
        }
        if (count >= cap) {
            *bad_line = line_no;
            return SC_ERR_NO_SPACE;
        }
        sc_emu_row *r = &rows[count++];
        r->t_s = v[0];
        for (int k = 0; k < 3; k++) {
            r->pos_mm[k] = (float)v[1 + k];
        }
        for (int k = 0; k < 4; k++) {
            r->q[k] = (float)v[4 + k];
        }
        r->force_n = nv == 9 ? (float)v[8] : -1.0f;
    }
    *n = count;
    return count > 0u ? 0 : SC_ERR_PARSE;
}

/* ---- the tracked needle --------------------------------------------------------------------- */

sc_emu_needle_def sc_emu_needle_default_def(void)
{
    return (sc_emu_needle_def){.rate_hz = 100.0,
                               .start_s = 0.5,
                               .entry_mm = {0.0f, 0.0f, 0.0f},
                               .dir = {0.0f, 0.0f, 1.0f},
                               .speed_mm_s = 10.0f,
                               .max_depth_mm = 25.0f,
                               .hold_s = 1.0};
}

int sc_emu_needle_init(sc_emu_needle *n, const sc_emu_needle_def *def)
{
    if (n == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const float nn =
        sqrtf(def->dir[0] * def->dir[0] + def->dir[1] * def->dir[1] + def->dir[2] * def->dir[2]);
    if (!isfinite(def->rate_hz) || !isfinite(def->start_s) || !isfinite(def->hold_s) ||
        !isfinite(nn) || !isfinite(def->speed_mm_s) || !isfinite(def->max_depth_mm) ||
        !isfinite(def->entry_mm[0]) || !isfinite(def->entry_mm[1]) || !isfinite(def->entry_mm[2])) {
        return SC_ERR_NOT_FINITE;
    }
    if (!(def->rate_hz > 0.0 && def->rate_hz <= 1000.0) || def->start_s < 0.0 ||
        def->hold_s < 0.0 || !(nn > 0.0f) || !(def->speed_mm_s > 0.0f && def->speed_mm_s <= 200.0f) ||
        !(def->max_depth_mm > 0.0f && def->max_depth_mm <= 200.0f)) {
        return SC_ERR_RANGE;
    }
    memset(n, 0, sizeof *n);
    n->def = *def;
    for (unsigned i = 0; i < 3u; i++) {
        n->def.dir[i] = def->dir[i] / nn;
    }
    return 0;
}

sc_needle_msg sc_emu_needle_at(const sc_emu_needle_def *d, double t_s)
{
    const double in_s = (double)d->max_depth_mm / (double)d->speed_mm_s;
    const double cycle = 2.0 * in_s + d->hold_s;
    double u = t_s - d->start_s;
    double depth = 0.0;
    if (u > 0.0) {
        u = fmod(u, cycle);
        depth = u < in_s ? u * d->speed_mm_s
                         : (u < in_s + d->hold_s ? d->max_depth_mm
                                                 : (cycle - u) * d->speed_mm_s);
    }
    sc_needle_msg m;
    memset(&m, 0, sizeof m);
    for (unsigned i = 0; i < 3u; i++) {
        m.tip_mm[i] = d->entry_mm[i] + (float)depth * d->dir[i];
        m.dir[i] = d->dir[i];
    }
    m.depth_mm = (float)depth;
    m.tracking = SC_TRACKING_OK;
    return m;
}

int sc_emu_needle_next(sc_emu_needle *n, sc_can_frame *out, size_t cap, uint64_t *t_ns)
{
    const double t_s = (double)n->sample / n->def.rate_hz;
    *t_ns = (uint64_t)(t_s * 1e9 + 0.5);
    const sc_needle_msg m = sc_emu_needle_at(&n->def, t_s);
    size_t nf = 0;
    const int rc = sc_canproto_encode_needle(&m, n->counter, out, cap, &nf);
    if (rc != 0) {
        return rc;
    }
    for (size_t i = 0; i < nf; i++) {
        out[i].ts_ns = *t_ns;
    }
    n->sample++;
    n->counter = (uint8_t)((n->counter + 1u) & 0x0Fu);
    return (int)nf;
}
