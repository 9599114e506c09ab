/*
 * gateway.c: sc-gateway, the instructor console's gateway (docs/console.md). It serves the
 * console page (static files built at build time) over HTTP and bridges, over WebSockets:
 *   - the engine's state stream (UDP records, core/sc_state.h) to every client, as is;
 *   - the display link (UDP line packets, platform/dlink) assembled into B-scan frames, at most
 *     --bscan-hz per client (the newest frame; older ones are skipped, never queued);
 *   - client commands (gw_msg.h: only what the CAN protocol defines, each validated) to the
 *     engine as authenticated CAN frames (sc_cmdsign: AES-CMAC, freshness), on SocketCAN
 *     (--can IFACE, the appliance) or CAN over UDP (--can-udp HOST:PORT, sc-hostsim --live on a
 *     host without SocketCAN). Refused messages are answered with an error and counted.
 * Several clients at once; viewing is open, the controls need the pass phrase when one is set
 * (--pass / --pass-file). The gateway is a separate process: nothing it or its clients do
 * reaches the engine's frame but CAN frames, so the engine's deadline does not depend on it.
 *
 * Recorded sessions (--sessions DIR, a folder of session bundles, docs/session-bundle.md): the
 * "sessions" op lists them (validated by sc_bundle_parse, refused ones with their reason); the
 * "replay" op starts `sc-hostsim --replay DIR/FILE --live` as a second engine whose state stream
 * and display link come to two more UDP ports of the gateway; while it runs the gateway forwards
 * the replay's stream instead of the live engine's (whose packets are drained and counted; the
 * live engine runs on untouched) and refuses commands; when it exits the console is back on the
 * live engine. One replay at a time; controls locked like the commands.
 *
 * Threads: a receive thread (UDP state + display link) fills a ring and the newest frame under
 * a mutex and wakes libwebsockets' service thread (lws_cancel_service), which alone writes to
 * clients and sends CAN frames.
 */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <libwebsockets.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <dirent.h>
#include <time.h>
#include <unistd.h>

#include "gw_msg.h"
#include "sc_bundle.h"
#include "sc_case.h"
#include "sc_cmdsign.h"
#include "sc_dlink.h"
#include "gw_bscan.h"
#include "sc_err.h"
#include "sc_socketcan.h"
#include "sc_state.h"
#include "sc_udp_state.h"
#include "sc_udpcan.h"

#define RING 2048u
#define MAX_CAT 32u
#define BSCAN_MAX GW_BSCAN_MAX /* with the colour box, parameters and spectrum (gw_bscan.h) */
#define TEXT_MAX 16384u
#define SESS_MAX 64u                  /* bundles listed */
#define SESS_JSON_MAX 49152u          /* the list's JSON */
#define BUNDLE_READ_MAX ((size_t)1 << 30)
_Static_assert(SESS_JSON_MAX <= BSCAN_MAX + TEXT_MAX, "the sessions list fits a client's buffer");

typedef struct gw_opts {
    int port;
    const char *www;
    uint16_t state_port, dlink_port;
    const char *can_iface, *can_udp;
    uint8_t key[16];
    unsigned sender;
    char pass[GW_MSG_PASS_MAX];
    int have_pass;
    const char *cases_dir;
    double bscan_hz;
    double seconds;
    const char *sessions_dir; /* --sessions */
    const char *hostsim;      /* --hostsim */
} gw_opts;

/* ---- shared between the receive thread and the service thread (under g.lock) -------------- */
static struct {
    pthread_mutex_t lock;
    uint8_t ring[RING][SC_STATE_RECORD_MAX + 1u]; /* 'S' + record */
    uint16_t ring_len[RING];
    uint64_t ring_head; /* records pushed so far */
    uint8_t bscan[BSCAN_MAX];
    uint32_t bscan_len;
    uint64_t bscan_gen;
    char cat_file[MAX_CAT][256];
    char cat_json[TEXT_MAX];
    uint64_t cat_gen;
    uint32_t cat_count;
    /* counters */
    uint64_t state_records, state_rejected, state_gaps, dlink_frames, dlink_rejected;
    uint32_t last_seq;
    int have_seq;
    int replay_on;          /* forward the replay engine's stream, drain the live one's */
    uint64_t other_dropped; /* packets of the engine not shown (counted) */
} g = {.lock = PTHREAD_MUTEX_INITIALIZER};

/* ---- service-thread state ----------------------------------------------------------------- */
static gw_opts opt;
static struct lws_context *ctx;
static volatile sig_atomic_t stop;
static sc_cmdsign signer;
static sc_can_dev can_dev;
static sc_socketcan can_sock;
static sc_udpcan can_udp;
static uint64_t cmds_sent, cmds_refused, can_tx_failed, clients_now, clients_total;
static int udp_state_fd = -1, udp_dlink_fd = -1;
static const struct lws_protocols *console_protocol;
static int udp_rstate_fd = -1, udp_rdlink_fd = -1; /* the replay engine's (--sessions) */
static uint16_t rstate_port, rdlink_port;
/* the replay (service thread only) */
static pid_t replay_pid = -1;
static char replay_name[GW_MSG_FILE_MAX];
static char replay_json[1024];
static uint64_t replay_gen, replays_started, replays_failed;
static char sess_json[SESS_JSON_MAX];

typedef struct client {
    uint64_t next_rec;   /* ring index of the next record to send */
    uint64_t bscan_gen;  /* last frame sent */
    double bscan_t;      /* when */
    uint64_t cat_gen;
    uint64_t replay_gen; /* last replay status sent */
    int want_sessions;   /* the sessions list is due */
    int unlocked;
    uint64_t refused, skipped;
    char rx[GW_MSG_MAX + 1u];
    size_t rx_len;
    int rx_overflow;
    char out[8][512];    /* replies waiting (ack / error / hello) */
    int out_n;
    uint8_t *buf;        /* LWS_PRE + largest message */
} client;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- catalogue: names from the engine's CATALOGUE records, text from the case files --------- */

static void json_str(char *dst, size_t cap, const char *s)
{
    size_t n = 0;
    if (cap < 3u) {
        return;
    }
    dst[n++] = '"';
    for (; *s && n + 8u < cap; s++) {
        const unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') {
            dst[n++] = '\\';
            dst[n++] = (char)c;
        } else if (c == '\n') {
            dst[n++] = '\\';
            dst[n++] = 'n';
        } else if (c < 0x20u || c >= 0x7fu) {
            n += (size_t)snprintf(dst + n, cap - n, "\\u%04x", c < 0x20u ? c : '?');
        } else {
            dst[n++] = (char)c;
        }
    }
    dst[n++] = '"';
    dst[n] = '\0';
}

/* name and description of a case file's INFO section (the first section), best effort */
static void case_info(const char *file, char *name, size_t ncap, char *desc, size_t dcap)
{
    snprintf(name, ncap, "%s", file);
    desc[0] = '\0';
    if (opt.cases_dir == NULL || strchr(file, '/') != NULL) {
        return;
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", opt.cases_dir, file);
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        snprintf(desc, dcap, "(case file not readable by the gateway)");
        return;
    }
    uint8_t b[SC_CASE_HEADER_SIZE + SC_CASE_SECTION_HEADER_SIZE + SC_CASE_INFO_SIZE];
    const size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    const uint8_t *h = b + SC_CASE_HEADER_SIZE;
    if (n != sizeof b || memcmp(b, SC_CASE_MAGIC, SC_CASE_MAGIC_LEN) != 0 ||
        memcmp(h, "INFO", 4) != 0) {
        snprintf(desc, dcap, "(not a case file)");
        return;
    }
    const char *nm = (const char *)(h + SC_CASE_SECTION_HEADER_SIZE);
    const char *ds = nm + SC_CASE_NAME_LEN;
    const size_t nl = strnlen(nm, SC_CASE_NAME_LEN), dl = strnlen(ds, SC_CASE_DESCRIPTION_LEN);
    if (nl > 0u && nl < SC_CASE_NAME_LEN && nl < ncap) {
        memcpy(name, nm, nl);
        name[nl] = '\0';
    }
    if (dl < SC_CASE_DESCRIPTION_LEN && dl < dcap) {
        memcpy(desc, ds, dl);
        desc[dl] = '\0';
    }
}

static void catalogue_entry(uint32_t index, uint32_t count, const char *file)
{
    if (index >= MAX_CAT || count > MAX_CAT) {
        return;
    }
    if (g.cat_count == count && strcmp(g.cat_file[index], file) == 0) {
        return;
    }
    g.cat_count = count;
    snprintf(g.cat_file[index], sizeof g.cat_file[index], "%s", file);
    size_t n = (size_t)snprintf(g.cat_json, sizeof g.cat_json, "{\"type\":\"catalogue\",\"entries\":[");
    for (uint32_t i = 0; i < count && n < sizeof g.cat_json - 3000u; i++) {
        char name[128], desc[1024], jf[600], jn[300], jd[2400];
        if (g.cat_file[i][0] == '\0') {
            continue;
        }
        case_info(g.cat_file[i], name, sizeof name, desc, sizeof desc);
        json_str(jf, sizeof jf, g.cat_file[i]);
        json_str(jn, sizeof jn, name);
        json_str(jd, sizeof jd, desc);
        n += (size_t)snprintf(g.cat_json + n, sizeof g.cat_json - n,
                              "%s{\"index\":%u,\"file\":%s,\"name\":%s,\"description\":%s}",
                              n > 33u ? "," : "", i, jf, jn, jd);
    }
    snprintf(g.cat_json + n, sizeof g.cat_json - n, "]}");
    g.cat_gen++;
}

/* ---- receive thread ------------------------------------------------------------------------ */

static int bind_udp(uint16_t port)
{
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        if (fd >= 0) {
            close(fd);
        }
        return -1;
    }
    int rcv = 4 << 20;
    (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcv, sizeof rcv);
    return fd;
}

/* a packet of the engine not shown (the live one during a replay, the replay's stragglers) */
static void drop_other(void)
{
    pthread_mutex_lock(&g.lock);
    g.other_dropped++;
    pthread_mutex_unlock(&g.lock);
}

static void on_state(const uint8_t *b, size_t n)
{
    uint32_t seq = 0, fno = 0;
    const int type = n <= SC_STATE_RECORD_MAX ? sc_state_check(b, (uint32_t)n, &seq, &fno) : -1;
    pthread_mutex_lock(&g.lock);
    if (type <= 0) {
        g.state_rejected++;
        pthread_mutex_unlock(&g.lock);
        return;
    }
    if (g.have_seq && seq != g.last_seq + 1u) {
        g.state_gaps++;
    }
    g.have_seq = 1;
    g.last_seq = seq;
    g.state_records++;
    if (type == SC_STATE_CATALOGUE && n >= SC_STATE_HEADER_SIZE + 12u + 240u) {
        const uint8_t *p = b + SC_STATE_HEADER_SIZE;
        const uint32_t idx = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        const uint32_t cnt = (uint32_t)p[4] | (uint32_t)p[5] << 8 | (uint32_t)p[6] << 16 | (uint32_t)p[7] << 24;
        char file[241];
        memcpy(file, p + 12, 240);
        file[240] = '\0';
        catalogue_entry(idx, cnt, file);
    }
    const uint64_t slot = g.ring_head % RING;
    g.ring[slot][0] = 'S';
    memcpy(g.ring[slot] + 1, b, n);
    g.ring_len[slot] = (uint16_t)(n + 1u);
    g.ring_head++;
    pthread_mutex_unlock(&g.lock);
}

static void on_frame(const sc_dlink_done *d, int src)
{
    static gw_spectrum_hist spec; /* receive thread only */
    static int spec_src = -1;
    if (src != spec_src) { /* another engine: its frame numbers restart */
        gw_spectrum_clear(&spec);
        spec_src = src;
    }
    pthread_mutex_lock(&g.lock);
    const size_t n = gw_bscan_build(g.bscan, sizeof g.bscan, d, &spec);
    if (n > 0u) {
        g.bscan_len = (uint32_t)n;
        g.bscan_gen++;
        g.dlink_frames++;
    }
    pthread_mutex_unlock(&g.lock);
}

static void *rx_thread(void *arg)
{
    (void)arg;
    static sc_dlink_asm as[2]; /* live, replay */
    static uint8_t buf[65536];
    sc_dlink_asm_init(&as[0]);
    sc_dlink_asm_init(&as[1]);
    const int sources = udp_rstate_fd >= 0 ? 2 : 1;
    while (!stop) {
        struct pollfd pf[4] = {{udp_state_fd, POLLIN, 0}, {udp_dlink_fd, POLLIN, 0},
                               {udp_rstate_fd, POLLIN, 0}, {udp_rdlink_fd, POLLIN, 0}};
        if (poll(pf, (nfds_t)(2 * sources), 100) <= 0) {
            continue;
        }
        pthread_mutex_lock(&g.lock);
        const int shown = g.replay_on ? 1 : 0;
        pthread_mutex_unlock(&g.lock);
        int woke = 0;
        for (int src = 0; src < sources; src++) {
            const int sfd = src ? udp_rstate_fd : udp_state_fd, dfd = src ? udp_rdlink_fd : udp_dlink_fd;
            for (int k = 0; k < 256; k++) {
                const ssize_t n = recv(sfd, buf, sizeof buf, MSG_DONTWAIT);
                if (n < 0) {
                    break;
                }
                if (src != shown) {
                    drop_other();
                    continue;
                }
                on_state(buf, (size_t)n);
                woke = 1;
            }
            for (int k = 0; k < 4096; k++) {
                const ssize_t n = recv(dfd, buf, sizeof buf, MSG_DONTWAIT);
                if (n < 0) {
                    break;
                }
                if (src != shown) {
                    drop_other();
                    continue;
                }
                const int r = sc_dlink_asm_push(&as[src], buf, (size_t)n);
                if (r == 1) {
                    on_frame(&as[src].done, src);
                    woke = 1;
                } else if (r < 0) {
                    pthread_mutex_lock(&g.lock);
                    g.dlink_rejected++;
                    pthread_mutex_unlock(&g.lock);
                }
            }
        }
        if (woke && ctx) {
            lws_cancel_service(ctx);
        }
    }
    return NULL;
}

/* ---- commands ------------------------------------------------------------------------------ */

static int send_frames(const sc_can_frame *f, int n)
{
    for (int i = 0; i < n; i++) {
        int rc = sc_can_send(&can_dev, &f[i]);
        for (int retry = 0; rc == SC_ERR_WOULD_BLOCK && retry < 10; retry++) {
            const struct timespec ws = {0, 200000};
            nanosleep(&ws, NULL);
            rc = sc_can_send(&can_dev, &f[i]);
        }
        if (rc != SC_OK) {
            can_tx_failed++;
            return rc;
        }
    }
    return SC_OK;
}

/* a freshness sync then the command: the engine accepts it whether or not it saw this sender */
static int send_command(const sc_cmd *c)
{
    sc_can_frame f[4];
    int rc = sc_cmdsign_sync(&signer, &f[0]);
    if (rc == SC_OK) {
        rc = sc_cmdsign_command(&signer, c, &f[2]);
    }
    if (rc == SC_OK) {
        rc = send_frames(f, 4);
    }
    return rc;
}

static void reply(client *cl, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void reply(client *cl, const char *fmt, ...)
{
    if (cl->out_n >= 8) {
        return; /* a client that floods gets no more replies until it reads */
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cl->out[cl->out_n++], sizeof cl->out[0], fmt, ap);
    va_end(ap);
}

static void refuse(client *cl, const char *op, const char *why)
{
    cl->refused++;
    cmds_refused++;
    char jw[400];
    json_str(jw, sizeof jw, why);
    reply(cl, "{\"type\":\"error\",\"op\":\"%s\",\"reason\":%s,\"refused\":%" PRIu64 "}", op, jw,
          cl->refused);
}

static int pass_ok(const char *p)
{
    /* constant time over the longer of the two */
    const size_t a = strlen(p), b = strlen(opt.pass), n = a > b ? a : b;
    unsigned d = (unsigned)(a != b);
    for (size_t i = 0; i < n; i++) {
        d |= (unsigned)((i < a ? p[i] : 0) ^ (i < b ? opt.pass[i] : 0));
    }
    return d == 0u;
}

/* ---- recorded sessions -------------------------------------------------------------------- */

static int name_cmp(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Read and validate DIR/name: 0 with *info, or -1 with *why. */
static int bundle_check(const char *name, sc_bundle_info *info, char *why, size_t wcap)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", opt.sessions_dir, name);
    struct stat sb;
    if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        snprintf(why, wcap, "no such bundle in the sessions folder");
        return -1;
    }
    uint8_t *buf = NULL;
    size_t len = 0;
    sc_bundle_reject r = SC_BDL_OK;
    uint64_t line = 0;
    int rc = sc_bundle_read_file(path, BUNDLE_READ_MAX, &buf, &len);
    if (rc == SC_OK) {
        rc = sc_bundle_parse(buf, len, info, &r, &line);
        free(buf);
    }
    if (rc != SC_OK) {
        if (r != SC_BDL_OK) {
            snprintf(why, wcap, "%s (line %" PRIu64 ")", sc_bundle_reject_name(r), line);
        } else {
            snprintf(why, wcap, "%s", sc_err_str(rc));
        }
        return -1;
    }
    return 0;
}

/* The sessions list as JSON into sess_json (the same fields as sc-hostsim --list-bundles). */
static void sessions_build(void)
{
    size_t n = (size_t)snprintf(sess_json, sizeof sess_json, "{\"type\":\"sessions\",\"entries\":[");
    uint32_t count = 0, refused = 0, more = 0;
    DIR *d = opt.sessions_dir ? opendir(opt.sessions_dir) : NULL;
    if (d != NULL) {
        static char names[SESS_MAX][GW_MSG_FILE_MAX];
        const char *sorted[SESS_MAX];
        uint32_t k = 0;
        const struct dirent *de;
        while ((de = readdir(d)) != NULL) {
            const size_t l = strlen(de->d_name);
            if (l > 4u && strcmp(de->d_name + l - 4u, ".scb") == 0) {
                if (k < SESS_MAX && l < GW_MSG_FILE_MAX) {
                    memcpy(names[k], de->d_name, l + 1u); /* l < GW_MSG_FILE_MAX */
                    sorted[k] = names[k];
                    k++;
                } else {
                    more++; /* not listed: too many, or a name too long to ask for */
                }
            }
        }
        closedir(d);
        qsort(sorted, k, sizeof sorted[0], name_cmp);
        for (uint32_t i = 0; i < k && n + 1200u < sizeof sess_json; i++) {
            char jf[2 * GW_MSG_FILE_MAX + 8], why[160], jw[400], jc[300], jd[300];
            sc_bundle_info info;
            json_str(jf, sizeof jf, sorted[i]);
            n += (size_t)snprintf(sess_json + n, sizeof sess_json - n, "%s{\"file\":%s",
                                  count ? "," : "", jf);
            count++;
            if (!gw_msg_bundle_name_ok(sorted[i])) {
                refused++;
                n += (size_t)snprintf(sess_json + n, sizeof sess_json - n,
                                      ",\"error\":\"not a plain file name (cannot be replayed)\"}");
            } else if (bundle_check(sorted[i], &info, why, sizeof why) != 0) {
                refused++;
                json_str(jw, sizeof jw, why);
                n += (size_t)snprintf(sess_json + n, sizeof sess_json - n, ",\"error\":%s}", jw);
            } else {
                const sc_bundle_meta *m = &info.meta;
                json_str(jc, sizeof jc, m->case_name);
                json_str(jd, sizeof jd, m->date);
                n += (size_t)snprintf(
                    sess_json + n, sizeof sess_json - n,
                    ",\"case\":%s,\"case_id\":\"0x%08x\",\"method\":\"%s\",\"date\":%s,"
                    "\"frames\":%" PRIu64 ",\"rate_hz\":%u,\"seconds\":%.3f,\"score\":%u,"
                    "\"score_max\":%u,\"criteria_met\":%u,\"call\":\"%s\",\"finding\":\"%s\"}",
                    jc, m->case_id, m->method ? "fem" : "msds", jd, m->frames, m->rate_hz,
                    m->rate_hz ? (double)m->frames / (double)m->rate_hz : 0.0, m->score,
                    m->score_max, m->criteria, sc_bundle_call_name(m->call),
                    sc_bundle_call_name(m->finding));
            }
        }
    }
    snprintf(sess_json + n, sizeof sess_json - n,
             "],\"count\":%u,\"refused\":%u,\"not_listed\":%u,\"folder\":%s}", count, refused,
             more, d != NULL || opt.sessions_dir == NULL ? "true" : "false");
}

static void replay_status(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void replay_status(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(replay_json, sizeof replay_json, fmt, ap);
    va_end(ap);
    replay_gen++;
    if (ctx) {
        lws_callback_on_writable_all_protocol(ctx, console_protocol);
    }
}

static void replay_switch(int on)
{
    pthread_mutex_lock(&g.lock);
    g.replay_on = on;
    g.have_seq = 0; /* another engine's sequence numbers */
    pthread_mutex_unlock(&g.lock);
}

/* Start the replay of DIR/name: 0, or -1 with *why. */
static int replay_start(const char *name, char *why, size_t wcap)
{
    if (opt.sessions_dir == NULL) {
        snprintf(why, wcap, "no sessions folder (sc-gateway --sessions DIR)");
        return -1;
    }
    if (replay_pid > 0) {
        snprintf(why, wcap, "a replay is running (%s)", replay_name);
        return -1;
    }
    sc_bundle_info info;
    char bwhy[160];
    if (bundle_check(name, &info, bwhy, sizeof bwhy) != 0) {
        snprintf(why, wcap, "%s: %s", name, bwhy);
        return -1;
    }
    char path[4096], out[4096], st[64], dl[64];
    snprintf(path, sizeof path, "%s/%s", opt.sessions_dir, name);
    snprintf(out, sizeof out, "%s/replay-out", opt.sessions_dir);
    (void)mkdir(out, 0755);
    snprintf(st, sizeof st, "127.0.0.1:%u", (unsigned)rstate_port);
    snprintf(dl, sizeof dl, "127.0.0.1:%u", (unsigned)rdlink_port);
    char *argv[16];
    int a = 0;
    argv[a++] = (char *)opt.hostsim;
    argv[a++] = (char *)"--replay";
    argv[a++] = path;
    argv[a++] = (char *)"--live";
    argv[a++] = (char *)"--state-udp";
    argv[a++] = st;
    argv[a++] = (char *)"--dlink-udp";
    argv[a++] = dl;
    argv[a++] = (char *)"--every";
    argv[a++] = (char *)"0";
    argv[a++] = (char *)"--quiet";
    argv[a++] = (char *)"--out";
    argv[a++] = out;
    if (opt.cases_dir) {
        argv[a++] = (char *)"--cases-dir";
        argv[a++] = (char *)opt.cases_dir;
    }
    argv[a] = NULL;
    extern char **environ;
    pid_t pid;
    const int rc = posix_spawn(&pid, opt.hostsim, NULL, NULL, argv, environ);
    if (rc != 0) {
        snprintf(why, wcap, "cannot start %s: %s", opt.hostsim, strerror(rc));
        return -1;
    }
    replay_pid = pid;
    replays_started++;
    snprintf(replay_name, sizeof replay_name, "%s", name);
    replay_switch(1);
    char jn[2 * GW_MSG_FILE_MAX + 8], jc[300];
    json_str(jn, sizeof jn, name);
    json_str(jc, sizeof jc, info.meta.case_name);
    replay_status("{\"type\":\"replay\",\"state\":\"running\",\"name\":%s,\"case\":%s,"
                  "\"frames\":%" PRIu64 ",\"rate_hz\":%u,\"score\":%u,\"score_max\":%u}",
                  jn, jc, info.meta.frames, info.meta.rate_hz, info.meta.score, info.meta.score_max);
    printf("sc-gateway: replay of %s started (pid %d, %" PRIu64 " frames)\n", path, (int)pid,
           info.meta.frames);
    fflush(stdout);
    return 0;
}

/* The replay engine's exit (service loop): back to the live engine. */
static void replay_reap(int wait_it)
{
    if (replay_pid <= 0) {
        return;
    }
    int status = 0;
    const pid_t r = waitpid(replay_pid, &status, wait_it ? 0 : WNOHANG);
    if (r != replay_pid) {
        return;
    }
    replay_pid = -1;
    replay_switch(0);
    const int ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    replays_failed += !ok;
    char jn[2 * GW_MSG_FILE_MAX + 8];
    json_str(jn, sizeof jn, replay_name);
    replay_status("{\"type\":\"replay\",\"state\":\"ended\",\"name\":%s,\"ok\":%s,\"exit\":%d}",
                  jn, ok ? "true" : "false",
                  WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
    printf("sc-gateway: replay of %s ended (%s, status %d); back to the live engine\n",
           replay_name, ok ? "every image hash matched" : "FAILED", status);
    fflush(stdout);
}

static void on_message(client *cl, const char *text, size_t len)
{
    gw_msg m;
    const char *why = NULL;
    if (gw_msg_parse(text, len, &m, &why) != 0) {
        refuse(cl, "?", why);
        return;
    }
    switch (m.op) {
    case GW_OP_PING:
        reply(cl, "{\"type\":\"pong\"}");
        return;
    case GW_OP_AUTH:
        if (!opt.have_pass || pass_ok(m.pass)) {
            cl->unlocked = 1;
            reply(cl, "{\"type\":\"ack\",\"op\":\"auth\",\"controls\":true}");
        } else {
            refuse(cl, "auth", "wrong pass phrase");
        }
        return;
    case GW_OP_SESSIONS:
        if (opt.sessions_dir == NULL) {
            refuse(cl, m.name, "no sessions folder (sc-gateway --sessions DIR)");
            return;
        }
        cl->want_sessions = 1;
        return;
    case GW_OP_REPLAY: {
        if (opt.have_pass && !cl->unlocked) {
            refuse(cl, m.name, "controls locked: send the pass phrase first");
            return;
        }
        char why2[400];
        if (replay_start(m.file, why2, sizeof why2) != 0) {
            refuse(cl, m.name, why2);
            return;
        }
        reply(cl, "{\"type\":\"ack\",\"op\":\"replay\",\"replays\":%" PRIu64 "}", replays_started);
        return;
    }
    case GW_OP_COMMAND:
        if (opt.have_pass && !cl->unlocked) {
            refuse(cl, m.name, "controls locked: send the pass phrase first");
            return;
        }
        if (replay_pid > 0) {
            refuse(cl, m.name, "a replay is running: commands go to the live engine after it");
            return;
        }
        if (send_command(&m.cmd) != SC_OK) {
            refuse(cl, m.name, "CAN transmit failed");
            return;
        }
        cmds_sent++;
        reply(cl, "{\"type\":\"ack\",\"op\":\"%s\",\"sent\":%" PRIu64 "}", m.name, cmds_sent);
        return;
    case GW_OP_NONE:
        break;
    }
    refuse(cl, "?", "unknown");
}

/* ---- WebSocket protocol -------------------------------------------------------------------- */

static int write_msg(struct lws *wsi, client *cl, const void *p, size_t n, enum lws_write_protocol t)
{
    memcpy(cl->buf + LWS_PRE, p, n);
    return lws_write(wsi, cl->buf + LWS_PRE, n, t) < (int)n ? -1 : 0;
}

static int on_writeable(struct lws *wsi, client *cl)
{
    if (cl->out_n > 0) {
        const char *s = cl->out[0];
        if (write_msg(wsi, cl, s, strlen(s), LWS_WRITE_TEXT) != 0) {
            return -1;
        }
        memmove(cl->out[0], cl->out[1], sizeof cl->out[0] * (size_t)(cl->out_n - 1));
        cl->out_n--;
        lws_callback_on_writable(wsi);
        return 0;
    }
    if (cl->replay_gen != replay_gen) {
        cl->replay_gen = replay_gen;
        lws_callback_on_writable(wsi);
        return write_msg(wsi, cl, replay_json, strlen(replay_json), LWS_WRITE_TEXT);
    }
    if (cl->want_sessions) {
        cl->want_sessions = 0;
        sessions_build(); /* read now: the folder may have changed */
        lws_callback_on_writable(wsi);
        return write_msg(wsi, cl, sess_json, strlen(sess_json), LWS_WRITE_TEXT);
    }
    pthread_mutex_lock(&g.lock);
    int rc = 0, more = 0;
    const double t = now_s();
    const int bscan_due = cl->bscan_gen != g.bscan_gen && g.bscan_len > 0u;
    if (bscan_due && t - cl->bscan_t >= 1.0 / opt.bscan_hz) {
        /* the newest frame goes first when due: records never starve the image */
        cl->bscan_gen = g.bscan_gen;
        cl->bscan_t = t;
        rc = write_msg(wsi, cl, g.bscan, g.bscan_len, LWS_WRITE_BINARY);
        more = cl->next_rec < g.ring_head || cl->cat_gen != g.cat_gen;
    } else if (cl->cat_gen != g.cat_gen) {
        cl->cat_gen = g.cat_gen;
        rc = write_msg(wsi, cl, g.cat_json, strlen(g.cat_json), LWS_WRITE_TEXT);
        more = 1;
    } else if (cl->next_rec < g.ring_head) {
        if (g.ring_head - cl->next_rec > RING) {
            cl->skipped += g.ring_head - RING - cl->next_rec;
            cl->next_rec = g.ring_head - RING;
        }
        const uint64_t s = cl->next_rec % RING;
        rc = write_msg(wsi, cl, g.ring[s], g.ring_len[s], LWS_WRITE_BINARY);
        cl->next_rec++;
        more = cl->next_rec < g.ring_head;
    }
    if (rc == 0 && !more && bscan_due && cl->bscan_gen != g.bscan_gen) {
        /* a newer frame waits for its turn: wake up then */
        lws_set_timer_usecs(wsi, (lws_usec_t)((1.0 / opt.bscan_hz - (t - cl->bscan_t)) * 1e6) + 1000);
    }
    pthread_mutex_unlock(&g.lock);
    if (rc == 0 && more) {
        lws_callback_on_writable(wsi);
    }
    return rc;
}

static int cb_console(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                      size_t len)
{
    client *cl = user;
    switch ((int)reason) { /* int: lws has ~100 reasons, -Wswitch-enum */
    case LWS_CALLBACK_ESTABLISHED:
        memset(cl, 0, sizeof *cl);
        cl->buf = malloc(LWS_PRE + BSCAN_MAX + TEXT_MAX);
        if (cl->buf == NULL) {
            return -1;
        }
        pthread_mutex_lock(&g.lock);
        cl->next_rec = g.ring_head > 64u ? g.ring_head - 64u : 0u; /* a little history */
        pthread_mutex_unlock(&g.lock);
        cl->unlocked = !opt.have_pass;
        clients_now++;
        clients_total++;
        reply(cl, "{\"type\":\"hello\",\"version\":1,\"locked\":%s,\"client\":%" PRIu64
                  ",\"sessions\":%s}",
              opt.have_pass ? "true" : "false", clients_total, opt.sessions_dir ? "true" : "false");
        lws_callback_on_writable(wsi);
        break;
    case LWS_CALLBACK_CLOSED:
        free(cl->buf);
        cl->buf = NULL;
        clients_now--;
        break;
    case LWS_CALLBACK_RECEIVE:
        if (lws_frame_is_binary(wsi)) {
            refuse(cl, "?", "binary messages are not accepted");
            lws_callback_on_writable(wsi);
            break;
        }
        if (cl->rx_len + len > GW_MSG_MAX) {
            cl->rx_overflow = 1;
        } else {
            memcpy(cl->rx + cl->rx_len, in, len);
            cl->rx_len += len;
        }
        if (lws_is_final_fragment(wsi)) {
            if (cl->rx_overflow) {
                refuse(cl, "?", "message too long");
            } else {
                on_message(cl, cl->rx, cl->rx_len);
            }
            cl->rx_len = 0;
            cl->rx_overflow = 0;
            lws_callback_on_writable(wsi);
        }
        break;
    case LWS_CALLBACK_SERVER_WRITEABLE:
        return on_writeable(wsi, cl);
    case LWS_CALLBACK_TIMER:
        lws_callback_on_writable(wsi);
        break;
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        lws_callback_on_writable_all_protocol(lws_get_context(wsi), lws_get_protocol(wsi));
        break;
    default:
        break;
    }
    return 0;
}

/* ---- gateway status for tests and the page (GET /status is the page's; this is stdout) ----- */

static void print_stats(FILE *f)
{
    pthread_mutex_lock(&g.lock);
    fprintf(f, "sc-gateway: clients %" PRIu64 " now, %" PRIu64 " total; state records %" PRIu64
               " (%" PRIu64 " gaps, %" PRIu64 " rejected); B-scan frames %" PRIu64 " (%" PRIu64
               " bad packets); commands sent %" PRIu64 ", refused %" PRIu64 ", CAN tx failed %" PRIu64
               "; replays %" PRIu64 " (%" PRIu64 " failed, %s), other engine's packets drained %" PRIu64
               "\n",
            clients_now, clients_total, g.state_records, g.state_gaps, g.state_rejected,
            g.dlink_frames, g.dlink_rejected, cmds_sent, cmds_refused, can_tx_failed,
            replays_started, replays_failed, replay_pid > 0 ? "running" : "none", g.other_dropped);
    pthread_mutex_unlock(&g.lock);
    fflush(f);
}

/* ---- command line ---------------------------------------------------------------------------- */

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sc-gateway [options]\n"
            "The instructor console's gateway: serves the page and bridges the engine's state\n"
            "stream, display link and commands to WebSocket clients (docs/console.md).\n"
            "  --port N            HTTP + WebSocket port (default 8080)\n"
            "  --www DIR           the built console page (default " SC_GATEWAY_WWW ")\n"
            "  --state-port N      UDP port of the state stream (default 47001)\n"
            "  --dlink-port N      UDP port of the display link (default 47002)\n"
            "  --can IFACE         commands on SocketCAN (the appliance)\n"
            "  --can-udp H:P       commands as CAN over UDP (sc-hostsim --live --can-udp P)\n"
            "  --auth-key K        bench | 32 hex digits: the command key (default bench)\n"
            "  --sender N          authenticated sender id 0..3 (default 1)\n"
            "  --pass PHRASE       pass phrase for the controls (viewing stays open)\n"
            "  --pass-file FILE    the same, read from the first line of FILE\n"
            "  --cases-dir DIR     where the case files are (catalogue names, descriptions)\n"
            "  --bscan-hz HZ       B-scan frames per second per client, 1..60 (default 20)\n"
            "  --seconds S         stop after S seconds (default: run until SIGINT/SIGTERM)\n"
            "  --sessions DIR      recorded sessions (*.scb bundles) the console lists and replays\n"
            "  --hostsim PATH      the sc-hostsim that replays them (default " SC_GATEWAY_HOSTSIM ")\n"
            "  --help\n");
}

static int parse_port(const char *s, int lo, long *out)
{
    char *e;
    errno = 0;
    const long v = strtol(s, &e, 10);
    if (errno || e == s || *e || v < lo || v > 65535) {
        return -1;
    }
    *out = v;
    return 0;
}

/* 0 go on, -1 after --help (exit 0), 2 usage error */
static int parse_args(int argc, char **argv, gw_opts *o)
{
    *o = (gw_opts){.port = 8080, .www = SC_GATEWAY_WWW, .state_port = 47001, .dlink_port = 47002,
                   .sender = 1u, .bscan_hz = 20.0,
                   .hostsim = SC_GATEWAY_HOSTSIM};
    memcpy(o->key, sc_secoc_bench_key, sizeof o->key);
    enum { O_PORT = 256, O_WWW, O_SP, O_DP, O_CAN, O_CANUDP, O_KEY, O_SENDER, O_PASS, O_PASSF,
           O_CASES, O_BHZ, O_SEC, O_HELP, O_SESS, O_HOSTSIM };
    static const struct option lo[] = {
        {"port", required_argument, 0, O_PORT},      {"www", required_argument, 0, O_WWW},
        {"state-port", required_argument, 0, O_SP},  {"dlink-port", required_argument, 0, O_DP},
        {"can", required_argument, 0, O_CAN},        {"can-udp", required_argument, 0, O_CANUDP},
        {"auth-key", required_argument, 0, O_KEY},   {"sender", required_argument, 0, O_SENDER},
        {"pass", required_argument, 0, O_PASS},      {"pass-file", required_argument, 0, O_PASSF},
        {"cases-dir", required_argument, 0, O_CASES}, {"bscan-hz", required_argument, 0, O_BHZ},
        {"seconds", required_argument, 0, O_SEC},    {"help", no_argument, 0, O_HELP},
        {"sessions", required_argument, 0, O_SESS},   {"hostsim", required_argument, 0, O_HOSTSIM},
        {0, 0, 0, 0}};
    int c;
    opterr = 0;
    optind = 0;
    while ((c = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        long v;
        char *e;
        switch (c) {
        case O_PORT:
            if (parse_port(optarg, 1, &v)) {
                fprintf(stderr, "sc-gateway: --port wants 1..65535, got '%s'\n", optarg);
                return 2;
            }
            o->port = (int)v;
            break;
        case O_WWW: o->www = optarg; break;
        case O_SP:
        case O_DP:
            if (parse_port(optarg, 1, &v)) {
                fprintf(stderr, "sc-gateway: UDP ports are 1..65535, got '%s'\n", optarg);
                return 2;
            }
            if (c == O_SP) {
                o->state_port = (uint16_t)v;
            } else {
                o->dlink_port = (uint16_t)v;
            }
            break;
        case O_CAN: o->can_iface = optarg; break;
        case O_CANUDP: {
            char host[256];
            uint16_t port;
            if (sc_udp_parse_target(optarg, host, sizeof host, &port) != 0) {
                fprintf(stderr, "sc-gateway: --can-udp wants HOST:PORT, got '%s'\n", optarg);
                return 2;
            }
            o->can_udp = optarg;
            break;
        }
        case O_KEY:
            if (strcmp(optarg, "bench") == 0) {
                memcpy(o->key, sc_secoc_bench_key, sizeof o->key);
            } else if (sc_cmdsign_parse_key(optarg, o->key) != 0) {
                fprintf(stderr, "sc-gateway: --auth-key wants bench or 32 hex digits\n");
                return 2;
            }
            break;
        case O_SENDER:
            if (parse_port(optarg, 0, &v) || v >= (long)SC_SECOC_SENDERS) {
                fprintf(stderr, "sc-gateway: --sender wants 0..%u\n", SC_SECOC_SENDERS - 1u);
                return 2;
            }
            o->sender = (unsigned)v;
            break;
        case O_PASS:
            if (strlen(optarg) == 0u || strlen(optarg) >= sizeof o->pass) {
                fprintf(stderr, "sc-gateway: --pass wants 1..%u bytes\n", GW_MSG_PASS_MAX - 1u);
                return 2;
            }
            snprintf(o->pass, sizeof o->pass, "%s", optarg);
            o->have_pass = 1;
            break;
        case O_PASSF: {
            FILE *f = fopen(optarg, "r");
            if (f == NULL || fgets(o->pass, sizeof o->pass, f) == NULL) {
                fprintf(stderr, "sc-gateway: cannot read a pass phrase from %s\n", optarg);
                if (f) {
                    fclose(f);
                }
                return 2;
            }
            fclose(f);
            o->pass[strcspn(o->pass, "\r\n")] = '\0';
            if (o->pass[0] == '\0') {
                fprintf(stderr, "sc-gateway: %s: empty pass phrase\n", optarg);
                return 2;
            }
            o->have_pass = 1;
            break;
        }
        case O_CASES: o->cases_dir = optarg; break;
        case O_SESS: o->sessions_dir = optarg; break;
        case O_HOSTSIM: o->hostsim = optarg; break;
        case O_BHZ:
        case O_SEC: {
            errno = 0;
            const double d = strtod(optarg, &e);
            const double hi = c == O_BHZ ? 60.0 : 86400.0;
            if (errno || e == optarg || *e || !isfinite(d) || d < (c == O_BHZ ? 1.0 : 0.1) || d > hi) {
                fprintf(stderr, "sc-gateway: --%s out of range: '%s'\n",
                        c == O_BHZ ? "bscan-hz" : "seconds", optarg);
                return 2;
            }
            if (c == O_BHZ) {
                o->bscan_hz = d;
            } else {
                o->seconds = d;
            }
            break;
        }
        case O_HELP: usage(stdout); return -1;
        default:
            fprintf(stderr, "sc-gateway: unknown or incomplete option '%s'\n", argv[optind - 1]);
            usage(stderr);
            return 2;
        }
    }
    if (optind != argc) {
        fprintf(stderr, "sc-gateway: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    if ((o->can_iface != NULL) == (o->can_udp != NULL)) {
        fprintf(stderr, "sc-gateway: give exactly one of --can IFACE and --can-udp HOST:PORT\n");
        return 2;
    }
    return 0;
}

static void on_sigchld(int s)
{
    (void)s;
    if (ctx) {
        lws_cancel_service(ctx);
    }
}

static void on_signal(int s)
{
    (void)s;
    stop = 1;
    if (ctx) {
        lws_cancel_service(ctx);
    }
}

int main(int argc, char **argv)
{
    const int pr = parse_args(argc, argv, &opt);
    if (pr) {
        return pr < 0 ? 0 : pr;
    }
    if (opt.can_udp) {
        char host[256];
        uint16_t port = 0;
        (void)sc_udp_parse_target(opt.can_udp, host, sizeof host, &port);
        if (sc_udpcan_open_tx(&can_udp, host, port) != SC_OK) {
            fprintf(stderr, "sc-gateway: cannot open CAN over UDP to %s\n", opt.can_udp);
            return 1;
        }
        can_dev = sc_udpcan_dev(&can_udp);
    } else {
        const int rc = sc_socketcan_open(&can_sock, sc_socketcan_sys_posix(), NULL, opt.can_iface);
        if (rc != SC_OK) {
            fprintf(stderr, "sc-gateway: cannot open CAN interface %s: %s (%s)\n", opt.can_iface,
                    sc_err_str(rc), strerror(errno));
            return 1;
        }
        can_dev = sc_socketcan_dev(&can_sock);
    }
    (void)sc_cmdsign_init(&signer, opt.key, (uint8_t)opt.sender, sc_cmdsign_fv_now(), 1);
    udp_state_fd = bind_udp(opt.state_port);
    udp_dlink_fd = bind_udp(opt.dlink_port);
    if (opt.sessions_dir != NULL) {
        /* the replay engine's ports: any free ones on localhost */
        udp_rstate_fd = bind_udp(0);
        udp_rdlink_fd = bind_udp(0);
        struct sockaddr_in a;
        socklen_t al = sizeof a;
        if (udp_rstate_fd < 0 || udp_rdlink_fd < 0 ||
            getsockname(udp_rstate_fd, (struct sockaddr *)&a, &al) != 0) {
            fprintf(stderr, "sc-gateway: cannot bind the replay's UDP ports: %s\n", strerror(errno));
            return 1;
        }
        rstate_port = ntohs(a.sin_port);
        al = sizeof a;
        if (getsockname(udp_rdlink_fd, (struct sockaddr *)&a, &al) != 0) {
            fprintf(stderr, "sc-gateway: cannot bind the replay's UDP ports: %s\n", strerror(errno));
            return 1;
        }
        rdlink_port = ntohs(a.sin_port);
        DIR *d = opendir(opt.sessions_dir);
        if (d == NULL) {
            fprintf(stderr, "sc-gateway: --sessions %s: %s\n", opt.sessions_dir, strerror(errno));
            return 1;
        }
        closedir(d);
    }
    if (udp_state_fd < 0 || udp_dlink_fd < 0) {
        fprintf(stderr, "sc-gateway: cannot bind UDP ports %u/%u on 127.0.0.1: %s\n",
                (unsigned)opt.state_port, (unsigned)opt.dlink_port, strerror(errno));
        return 1;
    }

    static const struct lws_http_mount mount = {
        .mountpoint = "/",
        .mountpoint_len = 1,
        .origin_protocol = LWSMPRO_FILE,
        .def = "index.html",
    };
    struct lws_http_mount m = mount;
    m.origin = opt.www;
    static struct lws_protocols protocols[] = {
        {"http", lws_callback_http_dummy, 0, 0, 0, NULL, 0},
        {"sonocomp-console", cb_console, sizeof(client), GW_MSG_MAX, 0, NULL, 0},
        {NULL, NULL, 0, 0, 0, NULL, 0}};
    console_protocol = &protocols[1];
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = opt.port;
    info.mounts = &m;
    info.protocols = protocols;
    info.options = 0; /* lws's "best practices" CSP would refuse the page's inline import map */
    lws_set_log_level(LLL_ERR, NULL);
    ctx = lws_create_context(&info);
    if (ctx == NULL) {
        fprintf(stderr, "sc-gateway: cannot start the server on port %d\n", opt.port);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sa.sa_handler = on_sigchld; /* a replay's end wakes the service loop */
    sa.sa_flags = SA_NOCLDSTOP;
    sigaction(SIGCHLD, &sa, NULL);
    pthread_t th;
    if (pthread_create(&th, NULL, rx_thread, NULL) != 0) {
        fprintf(stderr, "sc-gateway: cannot start the receive thread\n");
        return 1;
    }
    printf("sc-gateway: console at http://127.0.0.1:%d/ (state UDP %u, display link UDP %u, "
           "commands on %s%s%s)\n",
           opt.port, (unsigned)opt.state_port, (unsigned)opt.dlink_port,
           opt.can_udp ? "CAN over UDP " : "SocketCAN ", opt.can_udp ? opt.can_udp : opt.can_iface,
           opt.have_pass ? ", controls locked by a pass phrase" : "");
    fflush(stdout);
    const double t0 = now_s();
    double last_stats = t0;
    while (!stop && lws_service(ctx, 0) >= 0) {
        const double t = now_s();
        if (opt.seconds > 0.0 && t - t0 >= opt.seconds) {
            break;
        }
        replay_reap(0);
        if (t - last_stats >= 5.0) {
            last_stats = t;
            print_stats(stdout);
        }
    }
    stop = 1;
    if (replay_pid > 0) {
        kill(replay_pid, SIGTERM);
        replay_reap(1);
    }
    pthread_join(th, NULL);
    print_stats(stdout);
    lws_context_destroy(ctx);
    if (opt.can_udp) {
        sc_udpcan_close(&can_udp);
    } else {
        sc_socketcan_close(&can_sock);
    }
    return 0;
}
