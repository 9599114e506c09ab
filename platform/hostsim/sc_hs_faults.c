/* sc_hs_faults.c: fault injection plans on the host simulator; see sc_hs_faults.h. */
#include "sc_hs_faults.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_health.h"

#define NS_PER_S 1000000000.0

static const char *const k_kind_names[SC_HS_EP_KIND_COUNT] = {"busoff", "silence", "flood",
                                                              "linkdown", "random"};

const char *sc_hs_episode_kind_name(sc_hs_episode_kind k)
{
    return (unsigned)k < SC_HS_EP_KIND_COUNT ? k_kind_names[k] : "?";
}

static void set_why(char *why, size_t n, const char *a, const char *b)
{
    if (why && n) {
        snprintf(why, n, "%s%s", a, b);
    }
}

static int parse_u64(const char *s, uint64_t max, uint64_t *out)
{
    char *end;
    errno = 0;
    if (*s < '0' || *s > '9') {
        return -1;
    }
    const unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end || v > max) {
        return -1;
    }
    *out = v;
    return 0;
}

/* "A:B" seconds, 0 <= A, 0 < B (or A < B for a window), each <= 1e5. */
static int parse_span(const char *s, double *a, double *b)
{
    char *end;
    errno = 0;
    *a = strtod(s, &end);
    if (errno || end == s || *end != ':' || !isfinite(*a) || *a < 0.0 || *a > 1e5) {
        return -1;
    }
    const char *t = end + 1;
    *b = strtod(t, &end);
    if (errno || end == t || *end || !isfinite(*b) || *b < 0.0 || *b > 1e5) {
        return -1;
    }
    return 0;
}

int sc_hs_fault_plan_parse(const char *spec, sc_hs_fault_plan *p, char *why, size_t why_len)
{
    memset(p, 0, sizeof(*p));
    p->random_end_ns = UINT64_MAX;
    p->bitrate = 500000u;
    char buf[512];
    if (strlen(spec) >= sizeof(buf)) {
        set_why(why, why_len, "the list is too long", "");
        return -1;
    }
    strcpy(buf, spec);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        char *eq = strchr(tok, '=');
        if (!eq) {
            set_why(why, why_len, "expected NAME=VALUE: ", tok);
            return -1;
        }
        *eq = '\0';
        const char *v = eq + 1;
        uint64_t u;
        double a, b;
        if (strcmp(tok, "drop") == 0 || strcmp(tok, "corrupt") == 0 || strcmp(tok, "dup") == 0 ||
            strcmp(tok, "reorder") == 0) {
            if (parse_u64(v, 1000000u, &u)) {
                set_why(why, why_len, tok, " wants 0..1000000 (parts per million)");
                return -1;
            }
            uint32_t *dst = strcmp(tok, "drop") == 0      ? &p->random.drop_ppm
                            : strcmp(tok, "corrupt") == 0 ? &p->random.corrupt_ppm
                            : strcmp(tok, "dup") == 0     ? &p->random.duplicate_ppm
                                                          : &p->random.reorder_ppm;
            *dst = (uint32_t)u;
        } else if (strcmp(tok, "delay") == 0) {
            if (parse_u64(v, 1000000000u, &u)) {
                set_why(why, why_len, "delay wants 0..1000000000 ns", "");
                return -1;
            }
            p->random.delay_ns = u;
        } else if (strcmp(tok, "bitrate") == 0) {
            if (parse_u64(v, 1000000u, &u) || u < 10000u) {
                set_why(why, why_len, "bitrate wants 10000..1000000 bit/s", "");
                return -1;
            }
            p->bitrate = (uint32_t)u;
        } else if (strcmp(tok, "random") == 0) {
            if (parse_span(v, &a, &b) || !(b > a)) {
                set_why(why, why_len, "random wants START_S:END_S with START < END", "");
                return -1;
            }
            p->random_start_ns = (uint64_t)llround(a * NS_PER_S);
            p->random_end_ns = (uint64_t)llround(b * NS_PER_S);
        } else {
            int kind = -1;
            for (int k = 0; k < (int)SC_HS_EP_RANDOM; k++) {
                if (strcmp(tok, k_kind_names[k]) == 0) {
                    kind = k;
                }
            }
            if (kind < 0) {
                set_why(why, why_len, "unknown fault: ", tok);
                return -1;
            }
            if (parse_span(v, &a, &b) || !(b > 0.0)) {
                set_why(why, why_len, tok, " wants START_S:DURATION_S with DURATION > 0");
                return -1;
            }
            if (p->n >= SC_HS_FAULTS_MAX_EPISODES) {
                set_why(why, why_len, "too many episodes", "");
                return -1;
            }
            sc_hs_episode *e = &p->ep[p->n++];
            e->kind = (sc_hs_episode_kind)kind;
            e->start_ns = (uint64_t)llround(a * NS_PER_S);
            e->end_ns = e->start_ns + (uint64_t)llround(b * NS_PER_S);
            e->recover_frames = -1;
        }
    }
    const int any_random = p->random.drop_ppm || p->random.corrupt_ppm || p->random.duplicate_ppm ||
                           p->random.reorder_ppm || p->random.delay_ns;
    if (any_random && p->n < SC_HS_FAULTS_MAX_EPISODES) {
        /* the random window as an episode of its own, for the results */
        sc_hs_episode *e = &p->ep[p->n++];
        e->kind = SC_HS_EP_RANDOM;
        e->start_ns = p->random_start_ns;
        e->end_ns = p->random_end_ns;
        e->recover_frames = -1;
    }
    return 0;
}

int sc_hs_fault_run_init(sc_hs_fault_run *r, const sc_hs_fault_plan *plan, sc_hs_rig *rig)
{
    memset(r, 0, sizeof(*r));
    r->plan = *plan;
    r->rig = rig;
    r->t0_ns = rig->clock.now_ns;
    r->flood_node = -1;
    for (uint32_t i = 0; i < plan->n; i++) {
        if (plan->ep[i].kind == SC_HS_EP_FLOOD && r->flood_node < 0) {
            r->flood_node = sc_hs_can_add_node(&rig->bus);
            if (r->flood_node < 0) {
                return SC_ERR_NO_SPACE;
            }
            r->flood_dev = sc_hs_can_dev(&rig->bus, (uint32_t)r->flood_node);
        }
    }
    return SC_OK;
}

static int active(const sc_hs_episode *e, uint64_t t)
{
    return t >= e->start_ns && t < e->end_ns;
}

static sc_fault fault_of(sc_hs_episode_kind k)
{
    switch (k) {
    case SC_HS_EP_BUS_OFF:
        return SC_FAULT_CAN_BUS_OFF;
    case SC_HS_EP_SILENCE:
        return SC_FAULT_TRACKER_TIMEOUT;
    case SC_HS_EP_LINK_DOWN:
        return SC_FAULT_DISPLAY_LINK;
    case SC_HS_EP_FLOOD: /* a flood must raise nothing: watch the tracker's faults */
        return SC_FAULT_TRACKER_TIMEOUT;
    case SC_HS_EP_RANDOM:
    case SC_HS_EP_KIND_COUNT:
        break;
    }
    return SC_FAULT_TRACKER_DATA;
}

/* foreign ids next to the protocol's (0x085..0x087 and 0x08D..0x08F are CmdVessels,
 * CmdDoppler, CmdAssessment and their MACs; 0x095..0x097 and 0x09D..0x09F differ from them in
 * one bit and are unused ids of the second command block, whose CmdMaterial 0x090 and its MAC
 * 0x098 the engine's filter passes exactly) */
static const uint16_t k_flood_ids[] = {0x095, 0x096, 0x097, 0x09D, 0x09E, 0x09F,
                                       0x103, 0x104, 0x111, 0x555, 0x7FF};

static void flood(sc_hs_fault_run *r, const sc_hs_episode *e, uint64_t t)
{
    /* frames due from the episode's start to t at the bus's capacity */
    const uint64_t end = t < e->end_ns ? t : e->end_ns;
    if (end <= e->start_ns) {
        return;
    }
    const double per_s = (double)r->plan.bitrate / (double)SC_HS_FLOOD_FRAME_BITS;
    const uint64_t due = (uint64_t)((double)(end - e->start_ns) * 1e-9 * per_s);
    sc_hs_episode *me = (sc_hs_episode *)e;
    while (me->injected < due) {
        sc_can_frame f = {.id = k_flood_ids[r->flood_seq % (sizeof k_flood_ids / 2u)], .len = 8};
        for (unsigned i = 0; i < 8u; i++) {
            f.data[i] = (uint8_t)(r->flood_seq * 37u + i * 11u);
        }
        r->flood_seq++;
        (void)sc_can_send(&r->flood_dev, &f);
        me->injected++;
        r->flood_sent++;
    }
}

void sc_hs_fault_run_before(sc_hs_fault_run *r, uint64_t release_ns)
{
    sc_hs_rig *rig = r->rig;
    const uint64_t t = release_ns - r->t0_ns;
    int bus_off = 0, link_down = 0, silent = 0;
    for (uint32_t i = 0; i < r->plan.n; i++) {
        sc_hs_episode *e = &r->plan.ep[i];
        const int on = active(e, t);
        if (on && !e->started) {
            e->started = 1;
            e->edges_at_start = rig->engine.health.raised[fault_of(e->kind)];
            e->filtered_at_start = rig->bus.nodes[rig->engine_node].rx_filtered;
            e->frames_at_start = rig->display.frames_complete;
            e->refused_at_start = rig->bus.nodes[rig->peer_node].tx_refused;
            e->display_refused_at_start = rig->display.calls_refused;
        }
        switch (e->kind) {
        case SC_HS_EP_BUS_OFF:
            bus_off |= on;
            break;
        case SC_HS_EP_SILENCE:
            silent |= on;
            break;
        case SC_HS_EP_LINK_DOWN:
            link_down |= on;
            break;
        case SC_HS_EP_FLOOD:
            if (e->started) {
                flood(r, e, t);
            }
            break;
        case SC_HS_EP_RANDOM:
        case SC_HS_EP_KIND_COUNT:
            break;
        }
    }
    const int random_on = t >= r->plan.random_start_ns && t < r->plan.random_end_ns;
    const sc_hs_can_faults none = {0};
    sc_hs_can_set_faults(&rig->bus, random_on ? &r->plan.random : &none);
    if (!random_on) {
        sc_hs_can_flush(&rig->bus); /* a frame held back for reordering goes out */
    }
    sc_hs_can_set_bus_off(&rig->bus, bus_off);
    rig->display.link_down = (uint8_t)link_down;
    r->silent = (uint8_t)silent;
}

void sc_hs_fault_run_after(sc_hs_fault_run *r, uint64_t release_ns)
{
    sc_hs_rig *rig = r->rig;
    const uint64_t t = release_ns - r->t0_ns;
    sc_engine_status st;
    sc_engine_get_status(&rig->engine, &st);
    for (uint32_t i = 0; i < r->plan.n; i++) {
        sc_hs_episode *e = &r->plan.ep[i];
        if (!e->started) {
            continue;
        }
        const sc_fault f = fault_of(e->kind);
        e->edges = rig->engine.health.raised[f] - e->edges_at_start;
        if (active(e, t)) {
            e->untracked_frames += st.probe_tracked ? 0u : 1u;
            if (e->kind == SC_HS_EP_BUS_OFF) {
                e->injected = rig->bus.nodes[rig->peer_node].tx_refused - e->refused_at_start;
            } else if (e->kind == SC_HS_EP_LINK_DOWN) {
                e->injected = rig->display.calls_refused - e->display_refused_at_start;
            }
            e->filtered = rig->bus.nodes[rig->engine_node].rx_filtered - e->filtered_at_start;
            e->complete_at_end = rig->display.frames_complete; /* as of its last frame */
            continue;
        }
        if (!e->ended) {
            e->ended = 1;
            e->recover_frames = -1;
            e->filtered = rig->bus.nodes[rig->engine_node].rx_filtered - e->filtered_at_start;
        }
        if (e->recover_frames >= 0 || e->end_ns == UINT64_MAX) {
            continue;
        }
        e->frames_since_end++;
        /* frames run since the clearing, this one included */
        int ok = st.probe_tracked;
        if (e->kind == SC_HS_EP_BUS_OFF) {
            ok = ok && !(st.faults & (1u << SC_FAULT_CAN_BUS_OFF));
        } else if (e->kind == SC_HS_EP_LINK_DOWN) {
            ok = !(st.faults & (1u << SC_FAULT_DISPLAY_LINK)) &&
                 rig->display.frames_complete > e->complete_at_end;
        }
        if (ok) {
            e->recover_frames = (int32_t)e->frames_since_end;
        }
    }
}

int sc_hs_fault_run_silenced(sc_hs_fault_run *r)
{
    if (r->silent) {
        r->silenced++;
        return 1;
    }
    return 0;
}
