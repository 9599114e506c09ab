/* sc-tracker-emu: sends scripted probe motions as the tracker would, over SocketCAN or into a
 * candump -l log file that the host runner replays, with faults injected on command.
 *
 *   sc-tracker-emu --script press|sweep|rock|lift | --csv FILE
 *                  [--rate-hz 100] [--duration-s 10] [--fd]
 *                  [--point X,Y,Z] [--depth-mm 10] [--hover-mm 30] [--length-mm 60]
 *                  [--period-s 4] [--angle-deg 15] [--no-force]
 *                  [--fault KIND[:PERIOD[:START_S]]]...  KIND: bad-crc counter-jump repeat
 *                                                        silence implausible
 *                  [--silence-ms 300]
 *                  [--command KIND=VALUE[@T_S]]... [--auth-key bench|HEX32] [--sender 0..3]
 *                  [--needle X,Y,Z:DX,DY,DZ[:DEPTH_MM[:SPEED_MM_S]]]
 *                  (--iface vcan0 | --udp HOST:PORT | --log FILE|- [--log-iface vcan0] [--t0 ...])
 * --needle adds the tracked needle (frames 0x120..0x122, its own E2E counter) at the probe's
 * rate: from its skin entry point X,Y,Z along DX,DY,DZ (tracker frame) in to DEPTH_MM (25) at
 * SPEED_MM_S (10) from 0.5 s, held 1 s, out again, repeated (platform/trkemu sc_emu_needle).
 * Commands (the console's messages, docs/can-protocol.md) are authenticated: a freshness sync
 * before the first, then each command and its cryptographic PDU, signed with Mbed TLS's
 * AES-CMAC (sc_cmdsign.h) under the given key (default: the bench key). KIND=VALUE:
 *   case=N  method=msds|fem  reset=tissue|faults|all
 *   imaging=DEPTH_MM:GAIN_DB:DYN_RANGE_DB:TGC_DB_PER_CM:linear|curvilinear
 *   vessels=HR_BPM:RR_PER_MIN:VALSALVA(0|1):PULSE(0|1)   doppler=on|off:PRF_HZ:STEER_DEG:GAIN_DB
 *   material=LABEL:E_KPA:NU[:DAMPING_S:CG_ITERATIONS:COROTATED(0|1)]  (CmdMaterial; LABEL skin,
 *     fat, muscle, vein, artery, nerve, thrombus; without the last three: 0.1 s, 10, 0)
 * Summary (samples, frames, injected faults) on stderr; exit 0, 2 on a usage error, 1 on an
 * I/O error. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_candump.h"
#include "sc_cmdsign.h"
#include "sc_err.h"
#include "sc_socketcan.h"
#include "sc_udp_state.h"
#include "sc_udpcan.h"
#include "sc_trkemu.h"

#define MAX_ROWS 100000u
#define MAX_CMDS 32u

typedef struct timed_cmd {
    sc_cmd cmd;
    uint64_t t_ns;
} timed_cmd;

static sc_emu_row rows[MAX_ROWS];

static void usage(void)
{
    fprintf(stderr,
            "usage: sc-tracker-emu --script press|sweep|rock|lift | --csv FILE\n"
            "       [--rate-hz HZ] [--duration-s S] [--fd] [--point X,Y,Z] [--depth-mm MM]\n"
            "       [--hover-mm MM] [--length-mm MM] [--period-s S] [--angle-deg DEG]\n"
            "       [--no-force] [--fault KIND[:PERIOD[:START_S]]]... [--silence-ms MS]\n"
            "       [--command KIND=VALUE[@T_S]]... [--auth-key bench|HEX32] [--sender 0..3]\n"
            "       [--needle X,Y,Z:DX,DY,DZ[:DEPTH_MM[:SPEED_MM_S]]]\n"
            "       (--iface IFNAME | --udp HOST:PORT | --log FILE|- [--log-iface IFNAME]\n"
            "        [--t0 SECONDS])   (--udp: CAN over UDP to sc-hostsim --live --can-udp)\n"
            "faults: bad-crc counter-jump repeat silence implausible\n"
            "commands: case=N method=msds|fem reset=tissue|faults|all\n"
            "          imaging=DEPTH_MM:GAIN_DB:DYN_RANGE_DB:TGC_DB_PER_CM:linear|curvilinear\n"
            "          assess=reset call=normal|dvt (the compression exam's assessment)\n"
            "          vessels=HR_BPM:RR_PER_MIN:VALSALVA(0|1):PULSE(0|1) (heart rate 30..200,\n"
            "            respiration 0 or 4..40, Valsalva held, arterial pulse on)\n"
            "          doppler=on|off:PRF_HZ:STEER_DEG:GAIN_DB (colour Doppler, scale 100..20000,\n"
            "            steering -30..30, gain -30..30)\n"
            "          material=LABEL:E_KPA:NU[:DAMPING_S:CG_ITERATIONS:COROTATED] (a tissue's\n"
            "            material, LABEL skin|fat|muscle|vein|artery|nerve|thrombus, E 0.1..6553.4\n"
            "            kPa, nu 0..0.49; damping 0.01..0.5 s (0.1), CG iterations 1..63 (10),\n"
            "            corotated 0|1 (0); the engine rebuilds the running case with it)\n");
}

/* A whole, finite number (NaN and infinities compare false with every range below). */
static int parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || errno != 0 || !isfinite(v)) {
        return -1;
    }
    *out = v;
    return 0;
}

/* A whole decimal number in lo..hi. */
static int parse_uint(const char *s, unsigned long lo, unsigned long hi, unsigned long *out)
{
    char *end;
    errno = 0;
    if (*s < '0' || *s > '9') {
        return -1;
    }
    const unsigned long v = strtoul(s, &end, 10);
    if (*end != '\0' || errno != 0 || v < lo || v > hi) {
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_fault(char *arg, sc_emu_fault *f)
{
    char *kind = strtok(arg, ":");
    char *period = strtok(NULL, ":");
    char *start = strtok(NULL, ":");
    if (kind == NULL || sc_emu_fault_from_name(kind, &f->kind) != 0) {
        return -1;
    }
    double v = 100.0;
    if (period && (parse_double(period, &v) != 0 || v < 1.0 || v > 1e9)) {
        return -1;
    }
    f->period = (uint32_t)v;
    f->start_s = 0.0;
    if (start && parse_double(start, &f->start_s) != 0) {
        return -1;
    }
    return 0;
}

/* material=LABEL:E_KPA:NU[:DAMPING_S:CG_ITERATIONS:COROTATED] into c; -1 when malformed (the
 * ranges are the encoder's). */
static int parse_material(const char *val, sc_cmd *c)
{
    static const char *const labels[] = {"skin", "fat", "muscle", "vein", "artery", "nerve",
                                         "thrombus"};
    char name[16];
    char tail;
    unsigned it = 10u, co = 0u;
    sc_material_cmd m = {.damping_s = 0.1f};
    const int n = sscanf(val, "%15[a-z]:%f:%f:%f:%u:%u%c", name, &m.e_kpa, &m.poisson,
                         &m.damping_s, &it, &co, &tail);
    if ((n != 3 && n != 6) || it > 63u || co > 1u) {
        return -1;
    }
    for (unsigned i = 0; i < sizeof labels / sizeof labels[0]; i++) {
        if (strcmp(name, labels[i]) == 0) {
            m.label = (uint8_t)(SC_MATERIAL_LABEL_MIN + i);
        }
    }
    if (m.label == 0u) {
        return -1;
    }
    m.cg_iterations = (uint8_t)it;
    m.corotated = (uint8_t)co;
    c->kind = SC_CMD_MATERIAL;
    c->material = m;
    return 0;
}

/* KIND=VALUE[@T_S] into a command and its time; -1 when malformed (ranges are checked by the
 * encoder when it is sent). */
static int parse_command(const char *arg, timed_cmd *out)
{
    char buf[128];
    if (strlen(arg) >= sizeof buf) {
        return -1;
    }
    strcpy(buf, arg);
    double t_s = 0.0;
    char *at = strchr(buf, '@');
    if (at) {
        *at = '\0';
        if (parse_double(at + 1, &t_s) != 0 || !(t_s >= 0.0 && t_s < 1e6)) {
            return -1;
        }
    }
    char *eq = strchr(buf, '=');
    if (!eq) {
        return -1;
    }
    *eq = '\0';
    const char *val = eq + 1;
    sc_cmd c = {0};
    if (strcmp(buf, "case") == 0) {
        unsigned long id;
        if (parse_uint(val, 0u, 254u, &id) != 0) {
            return -1;
        }
        c.kind = SC_CMD_SELECT_CASE;
        c.case_id = (uint8_t)id;
    } else if (strcmp(buf, "method") == 0) {
        c.kind = SC_CMD_SET_METHOD;
        if (strcmp(val, "msds") == 0) {
            c.method = SC_METHOD_MSDS;
        } else if (strcmp(val, "fem") == 0) {
            c.method = SC_METHOD_FEM;
        } else {
            return -1;
        }
    } else if (strcmp(buf, "reset") == 0) {
        c.kind = SC_CMD_RESET;
        c.reset_target = strcmp(val, "tissue") == 0   ? SC_RESET_TISSUE
                         : strcmp(val, "faults") == 0 ? SC_RESET_FAULTS
                         : strcmp(val, "all") == 0    ? SC_RESET_ALL
                                                      : 0u;
        if (c.reset_target == 0u) {
            return -1;
        }
    } else if (strcmp(buf, "assess") == 0 && strcmp(val, "reset") == 0) {
        c.kind = SC_CMD_ASSESS;
        c.assess_action = SC_ASSESS_ACTION_RESET;
    } else if (strcmp(buf, "call") == 0) {
        c.kind = SC_CMD_ASSESS;
        c.assess_action = SC_ASSESS_ACTION_CALL;
        if (strcmp(val, "normal") == 0) {
            c.assess_call = SC_ASSESS_CALL_NORMAL;
        } else if (strcmp(val, "dvt") == 0) {
            c.assess_call = SC_ASSESS_CALL_DVT;
        } else {
            return -1;
        }
    } else if (strcmp(buf, "vessels") == 0) {
        /* vessels=HR:RR:VALSALVA(0|1):PULSE(0|1) */
        unsigned va, pu;
        char tail;
        c.kind = SC_CMD_VESSELS;
        if (sscanf(val, "%f:%f:%u:%u%c", &c.vessels.heart_rate_bpm, &c.vessels.resp_rate_bpm, &va,
                   &pu, &tail) != 4 ||
            va > 1u || pu > 1u) {
            return -1;
        }
        c.vessels.valsalva = (uint8_t)va;
        c.vessels.pulse = (uint8_t)pu;
    } else if (strcmp(buf, "doppler") == 0) {
        /* doppler=on|off:PRF_HZ:STEER_DEG:GAIN_DB */
        char onoff[4];
        char tail;
        c.kind = SC_CMD_DOPPLER;
        if (sscanf(val, "%3[a-z]:%f:%f:%f%c", onoff, &c.doppler.prf_hz, &c.doppler.steer_deg,
                   &c.doppler.gain_db, &tail) != 4) {
            return -1;
        }
        if (strcmp(onoff, "on") == 0) {
            c.doppler.on = 1u;
        } else if (strcmp(onoff, "off") != 0) {
            return -1;
        }
    } else if (strcmp(buf, "material") == 0) {
        if (parse_material(val, &c) != 0) {
            return -1;
        }
    } else if (strcmp(buf, "imaging") == 0) {
        char geom[16];
        char tail;
        c.kind = SC_CMD_SET_IMAGING;
        if (sscanf(val, "%f:%f:%f:%f:%15[a-z]%c", &c.imaging.depth_mm, &c.imaging.gain_db,
                   &c.imaging.dyn_range_db, &c.imaging.tgc_db_per_cm, geom, &tail) != 5) {
            return -1;
        }
        if (strcmp(geom, "linear") == 0) {
            c.imaging.geometry = SC_SCAN_LINEAR;
        } else if (strcmp(geom, "curvilinear") == 0) {
            c.imaging.geometry = SC_SCAN_CURVILINEAR;
        } else {
            return -1;
        }
    } else {
        return -1;
    }
    sc_can_frame probe;
    if (sc_canproto_encode_cmd(&c, 0, &probe) != 0) {
        return -1; /* outside the DBC ranges */
    }
    out->cmd = c;
    out->t_ns = (uint64_t)llround(t_s * 1e9);
    return 0;
}

typedef struct emu_cli {
    sc_emu_def def;
    const char *iface, *log_path, *log_iface, *csv;
    const char *udp; /* --udp HOST:PORT: CAN over UDP (sc_udpcan.h), paced like --iface */
    double t0_s;
    timed_cmd cmds[MAX_CMDS];
    uint32_t n_cmds;
    uint8_t auth_key[16];
    unsigned long sender;
    int have_needle;
    sc_emu_needle_def needle;
} emu_cli;

static void sleep_until(const struct timespec *t0, uint64_t t_ns)
{
    struct timespec t = *t0;
    t.tv_sec += (time_t)(t_ns / 1000000000u);
    t.tv_nsec += (long)(t_ns % 1000000000u);
    if (t.tv_nsec >= 1000000000L) {
        t.tv_sec++;
        t.tv_nsec -= 1000000000L;
    }
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, NULL) == EINTR) {
    }
}

/* The command line into *a (nothing else is touched: tests/fuzz/fuzz_cli_tracker_emu.c calls
 * it). Returns -1 to go on, 0 after --help, 2 for a usage error. */
static int parse_cli(int argc, char **argv, emu_cli *a)
{
    *a = (emu_cli){.def = sc_emu_default_def(), .log_iface = "vcan0", .t0_s = 1700000000.0};
    sc_emu_def *const def = &a->def;
    int have_script = 0;
    optind = 0; /* glibc: a full re-initialisation, so that it can be called again */
    memcpy(a->auth_key, sc_secoc_bench_key, sizeof a->auth_key);
    static const struct option opts[] = {
        {"script", required_argument, 0, 's'},
        {"csv", required_argument, 0, 'c'},
        {"rate-hz", required_argument, 0, 'r'},
        {"duration-s", required_argument, 0, 'd'},
        {"fd", no_argument, 0, 'F'},
        {"point", required_argument, 0, 'p'},
        {"depth-mm", required_argument, 0, 'D'},
        {"hover-mm", required_argument, 0, 'H'},
        {"length-mm", required_argument, 0, 'L'},
        {"period-s", required_argument, 0, 'T'},
        {"angle-deg", required_argument, 0, 'A'},
        {"no-force", no_argument, 0, 'n'},
        {"fault", required_argument, 0, 'f'},
        {"silence-ms", required_argument, 0, 'S'},
        {"iface", required_argument, 0, 'i'},
        {"udp", required_argument, 0, 'U'},
        {"log", required_argument, 0, 'l'},
        {"log-iface", required_argument, 0, 'I'},
        {"t0", required_argument, 0, 't'},
        {"command", required_argument, 0, 'C'},
        {"auth-key", required_argument, 0, 'K'},
        {"sender", required_argument, 0, 'N'},
        {"needle", required_argument, 0, 'E'},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    int c;
    double v = 0.0;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        int bad = 0;
        switch (c) {
        case 's':
            bad = sc_emu_script_from_name(optarg, &def->script) != 0 || def->script == SC_EMU_CSV;
            have_script = 1;
            break;
        case 'c':
            a->csv = optarg;
            def->script = SC_EMU_CSV;
            have_script = 1;
            break;
        case 'r':
            bad = parse_double(optarg, &def->rate_hz) != 0;
            break;
        case 'd':
            bad = parse_double(optarg, &def->duration_s) != 0;
            break;
        case 'F':
            def->fd = 1;
            break;
        case 'p':
            bad = sscanf(optarg, "%f,%f,%f", &def->point_mm[0], &def->point_mm[1],
                         &def->point_mm[2]) != 3;
            break;
        case 'D':
            bad = parse_double(optarg, &v) != 0;
            def->depth_mm = (float)v;
            break;
        case 'H':
            bad = parse_double(optarg, &v) != 0;
            def->hover_mm = (float)v;
            break;
        case 'L':
            bad = parse_double(optarg, &v) != 0;
            def->length_mm = (float)v;
            break;
        case 'T':
            bad = parse_double(optarg, &def->period_s) != 0;
            break;
        case 'A':
            bad = parse_double(optarg, &v) != 0;
            def->angle_deg = (float)v;
            break;
        case 'n':
            def->force_valid = 0;
            break;
        case 'f':
            bad = def->n_faults >= SC_EMU_MAX_FAULTS ||
                  parse_fault(optarg, &def->faults[def->n_faults++]) != 0;
            break;
        case 'S':
            bad = parse_double(optarg, &def->silence_ms) != 0 || def->silence_ms < 0.0;
            break;
        case 'i':
            a->iface = optarg;
            break;
        case 'l':
            a->log_path = optarg;
            break;
        case 'U': {
            char host[256];
            uint16_t port;
            bad = sc_udp_parse_target(optarg, host, sizeof host, &port) != 0;
            a->udp = optarg;
            break;
        }
        case 'I':
            a->log_iface = optarg;
            break;
        case 't':
            bad = parse_double(optarg, &a->t0_s) != 0 || !(a->t0_s >= 0.0 && a->t0_s < 1e11);
            break;
        case 'C':
            bad = a->n_cmds >= MAX_CMDS || parse_command(optarg, &a->cmds[a->n_cmds++]) != 0;
            break;
        case 'K':
            bad = strcmp(optarg, "bench") != 0 && sc_cmdsign_parse_key(optarg, a->auth_key) != 0;
            if (!bad && strcmp(optarg, "bench") == 0) {
                memcpy(a->auth_key, sc_secoc_bench_key, sizeof a->auth_key);
            }
            break;
        case 'N':
            bad = parse_uint(optarg, 0u, SC_SECOC_SENDERS - 1u, &a->sender) != 0;
            break;
        case 'E': {
            sc_emu_needle_def nd = sc_emu_needle_default_def();
            double depth = nd.max_depth_mm, speed = nd.speed_mm_s;
            const int k = sscanf(optarg, "%f,%f,%f:%f,%f,%f:%lf:%lf", &nd.entry_mm[0],
                                 &nd.entry_mm[1], &nd.entry_mm[2], &nd.dir[0], &nd.dir[1],
                                 &nd.dir[2], &depth, &speed);
            nd.max_depth_mm = (float)depth;
            nd.speed_mm_s = (float)speed;
            sc_emu_needle probe_def;
            bad = k < 6 || sc_emu_needle_init(&probe_def, &nd) != 0;
            a->needle = nd;
            a->have_needle = !bad;
            break;
        }
        case 'h':
            usage();
            return 0;
        default:
            bad = 1;
            break;
        }
        if (bad) {
            fprintf(stderr, "sc-tracker-emu: bad option value: %s\n", optarg ? optarg : "?");
            usage();
            return 2;
        }
    }
    if (!have_script ||
        (a->iface != NULL) + (a->log_path != NULL) + (a->udp != NULL) != 1 || optind != argc) {
        usage();
        return 2;
    }
    return -1;
}

int main(int argc, char **argv)
{
    emu_cli a;
    const int parsed = parse_cli(argc, argv, &a);
    if (parsed >= 0) {
        return parsed;
    }
    sc_emu_def def = a.def;
    const char *const log_path = a.log_path, *const log_iface = a.log_iface;
    /* a live bus: SocketCAN or CAN over UDP (paced in real time either way) */
    const char *const iface = a.iface ? a.iface : a.udp;
    const char *const csv = a.csv;
    const double t0_s = a.t0_s;
    timed_cmd *const cmds = a.cmds;
    const uint32_t n_cmds = a.n_cmds;
    const uint8_t *const auth_key = a.auth_key;
    const unsigned long sender = a.sender;
    if (csv) {
        FILE *fp = fopen(csv, "r");
        if (fp == NULL) {
            fprintf(stderr, "sc-tracker-emu: %s: %s\n", csv, strerror(errno));
            return 1;
        }
        size_t bad_line = 0;
        const int rc = sc_emu_load_csv(fp, rows, MAX_ROWS, &def.n_rows, &bad_line);
        fclose(fp);
        if (rc != 0) {
            fprintf(stderr,
                    "sc-tracker-emu: %s:%zu: %s (want t_s,x,y,z,qw,qx,qy,qz[,force_n] "
                    "with increasing t_s)\n",
                    csv, bad_line, sc_err_str(rc));
            return 2;
        }
        def.rows = rows;
    }
    sc_emu emu;
    if (sc_emu_init(&emu, &def) != 0) {
        fprintf(stderr, "sc-tracker-emu: invalid settings (rate, duration, period)\n");
        return 2;
    }

    sc_socketcan node;
    sc_can_dev dev = {0};
    FILE *log = NULL;
    static sc_udpcan udp;
    if (a.udp) {
        char host[256];
        uint16_t port = 0;
        if (sc_udp_parse_target(a.udp, host, sizeof host, &port) != 0 ||
            sc_udpcan_open_tx(&udp, host, port) != SC_OK) {
            fprintf(stderr, "sc-tracker-emu: cannot open UDP CAN to %s\n", a.udp);
            return 1;
        }
        dev = sc_udpcan_dev(&udp);
    } else if (iface) {
        const int rc = sc_socketcan_open(&node, sc_socketcan_sys_posix(), NULL, iface);
        if (rc != 0) {
            fprintf(stderr, "sc-tracker-emu: cannot open CAN interface %s: %s (%s)\n", iface,
                    sc_err_str(rc), strerror(errno));
            return 1;
        }
        if (def.fd && !node.fd_capable) {
            fprintf(stderr, "sc-tracker-emu: %s is not CAN FD (MTU 72 needed)\n", iface);
            return 1;
        }
        dev = sc_socketcan_dev(&node);
    } else {
        log = strcmp(log_path, "-") == 0 ? stdout : fopen(log_path, "w");
        if (log == NULL) {
            fprintf(stderr, "sc-tracker-emu: %s: %s\n", log_path, strerror(errno));
            return 1;
        }
    }

    struct timespec start;
    clock_gettime(CLOCK_MONOTONIC, &start);
    const uint64_t t0_us = (uint64_t)llround(t0_s * 1e6);
    uint64_t tx_failed = 0;
    sc_can_frame fr[SC_EMU_MAX_FRAMES + 4u + 3u];
    sc_emu_needle needle;
    if (a.have_needle) {
        a.needle.rate_hz = a.def.rate_hz; /* one needle sample per probe sample */
        if (sc_emu_needle_init(&needle, &a.needle) != 0) {
            fprintf(stderr, "sc-tracker-emu: bad --needle for this rate\n");
            return 2;
        }
    }
    uint64_t t_ns;
    int n;
    /* commands in time order (stable: equal times keep their command-line order) */
    for (uint32_t i = 1; i < n_cmds; i++) {
        for (uint32_t j = i; j > 0 && cmds[j - 1u].t_ns > cmds[j].t_ns; j--) {
            const timed_cmd tmp = cmds[j];
            cmds[j] = cmds[j - 1u];
            cmds[j - 1u] = tmp;
        }
    }
    sc_cmdsign signer;
    (void)sc_cmdsign_init(&signer, auth_key, (uint8_t)sender, sc_cmdsign_fv_now(), 1);
    uint32_t next_cmd = 0, cmds_sent = 0;
    while ((n = sc_emu_next(&emu, fr, SC_EMU_MAX_FRAMES, &t_ns)) >= 0) {
        if (iface) {
            sleep_until(&start, t_ns);
        }
        /* a due command goes out before this sample, with a sync before the first one */
        if (next_cmd < n_cmds && cmds[next_cmd].t_ns <= t_ns) {
            memmove(&fr[4], &fr[0], (size_t)n * sizeof fr[0]);
            int extra = 0, rc = 0;
            if (cmds_sent == 0u) {
                rc = sc_cmdsign_sync(&signer, &fr[0]);
                extra = 2;
            }
            if (rc == 0) {
                rc = sc_cmdsign_command(&signer, &cmds[next_cmd].cmd, &fr[extra]);
                extra += 2;
            }
            if (rc != 0) {
                fprintf(stderr, "sc-tracker-emu: cannot sign a command: %s\n", sc_err_str(rc));
                return 1;
            }
            if (extra < 4) {
                memmove(&fr[extra], &fr[4], (size_t)n * sizeof fr[0]);
            }
            n += extra;
            next_cmd++;
            cmds_sent++;
        }
        if (a.have_needle) {
            uint64_t tn;
            const int k = sc_emu_needle_next(&needle, &fr[n], 3u, &tn);
            if (k > 0) {
                for (int j = 0; j < k; j++) {
                    fr[n + j].ts_ns = t_ns;
                }
                n += k;
            }
        }
        for (int k = 0; k < n; k++) {
            if (iface) {
                int rc = sc_can_send(&dev, &fr[k]);
                for (int retry = 0; rc == SC_ERR_WOULD_BLOCK && retry < 20; retry++) {
                    const struct timespec ws = {0, 200000};
                    nanosleep(&ws, NULL);
                    rc = sc_can_send(&dev, &fr[k]);
                }
                tx_failed += rc != 0;
            } else {
                /* frames of one sample 100 us apart, as back-to-back frames on a busy bus */
                sc_candump_rec rec;
                memset(&rec, 0, sizeof rec);
                snprintf(rec.iface, sizeof rec.iface, "%s", log_iface);
                rec.ts_us = t0_us + t_ns / 1000u + (uint64_t)k * 100u;
                rec.frame = fr[k];
                rec.frame.ts_ns = rec.ts_us * 1000u;
                if (sc_candump_write(log, &rec) != 0) {
                    fprintf(stderr, "sc-tracker-emu: cannot write the log\n");
                    return 1;
                }
            }
        }
    }
    if (n != SC_ERR_NOT_FOUND) {
        fprintf(stderr, "sc-tracker-emu: cannot encode a pose: %s\n", sc_err_str(n));
        return 1;
    }
    if (log && log != stdout) {
        if (fclose(log) != 0) {
            fprintf(stderr, "sc-tracker-emu: cannot write the log\n");
            return 1;
        }
    }
    if (a.udp) {
        sc_udpcan_close(&udp);
    } else if (iface) {
        sc_socketcan_close(&node);
    }
    fprintf(stderr,
            "sc-tracker-emu: script %s, %.1f Hz, %s: samples_sent=%llu "
            "samples_silent=%llu frames=%llu tx_failed=%llu commands_sent=%u",
            sc_emu_script_name(def.script), def.rate_hz, def.fd ? "fd" : "classic",
            (unsigned long long)emu.samples_sent, (unsigned long long)emu.samples_silent,
            (unsigned long long)emu.frames_sent, (unsigned long long)tx_failed,
            (unsigned)cmds_sent);
    for (int k = 0; k < (int)SC_EMU_F_COUNT; k++) {
        fprintf(stderr, " %s=%llu", sc_emu_fault_name((sc_emu_fault_kind)k),
                (unsigned long long)emu.injected[k]);
    }
    fprintf(stderr, "\n");
    return tx_failed ? 1 : 0;
}
