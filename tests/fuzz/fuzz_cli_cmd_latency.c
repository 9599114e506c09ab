/* fuzz_cli_cmd_latency.c: sc-cmd-latency's command line (parse_cli in tools/cmd_latency/main.c)
 * takes any argument vector and never crashes; what it accepts names the engine's CAN over UDP
 * target as HOST:PORT and a state port, with a tracker rate, a run length and a command
 * interval in their ranges and at most MAX_CMDS commands. */
#define _GNU_SOURCE
#include "sc_fuzz_argv.h"

#define main cmd_latency_main
#include "../../tools/cmd_latency/main.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_argv av;
    sc_fuzz_argv_split(data, size, "sc-cmd-latency", &av);
    lat_cli a;
    sc_fuzz_quiet(1);
    const int rc = parse_cli(av.argc, av.argv, &a);
    sc_fuzz_quiet(0);
    SC_FUZZ_CHECK(rc == -1 || rc == 0 || rc == 2);
    if (rc < 0) {
        char host[256];
        uint16_t port;
        SC_FUZZ_CHECK(a.can_udp != NULL &&
                      sc_udp_parse_target(a.can_udp, host, sizeof host, &port) == 0);
        SC_FUZZ_CHECK(a.state_port >= 1u && a.state_port <= 65535u);
        SC_FUZZ_CHECK(a.rate_hz >= 1.0 && a.rate_hz <= 1000.0);
        SC_FUZZ_CHECK(a.seconds >= 1.0 && a.seconds <= 3600.0);
        SC_FUZZ_CHECK(a.every_ms >= 20.0 && a.every_ms <= 60000.0);
        SC_FUZZ_CHECK(a.seconds * 1000.0 / a.every_ms <= (double)MAX_CMDS);
        /* the tracker emulator takes every rate the parser accepts */
        sc_emu_def def = sc_emu_default_def();
        def.rate_hz = a.rate_hz;
        def.duration_s = a.seconds + 5.0;
        static sc_emu emu;
        SC_FUZZ_CHECK(sc_emu_init(&emu, &def) == 0);
    }
    sc_fuzz_argv_free(&av);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const lines[] = {
        "--can-udp|127.0.0.1:47000|--state-port|47001",
        "--can-udp|localhost:5|--state-port|9|--rate-hz|100|--seconds|20|--every-ms|500",
        "--can-udp|127.0.0.1:47000|--state-port|47001|--rate-hz|1000|--seconds|3600|--every-ms|20",
        "--can-udp|47000|--state-port|0",
        "--can-udp|127.0.0.1:47000|--state-port|1.5|--rate-hz|nan",
        "--help",
    };
    return sc_fuzz_argv_seed(lines, sizeof lines / sizeof lines[0], i, buf, cap);
}
