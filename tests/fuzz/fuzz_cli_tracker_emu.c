/* fuzz_cli_tracker_emu.c: sc-tracker-emu's command line (parse_cli in tools/tracker_emu/main.c)
 * takes any argument vector and never crashes; a definition it accepts is then accepted or
 * refused by the emulator (sc_emu_init) as the program does, and an accepted one generates
 * its first samples without crashing (no CSV file is read: a --csv script runs without rows,
 * which the emulator must refuse). */
#define _GNU_SOURCE
#include "sc_fuzz_argv.h"

#define main tracker_emu_main
#include "../../tools/tracker_emu/main.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_argv av;
    sc_fuzz_argv_split(data, size, "sc-tracker-emu", &av);
    emu_cli a;
    sc_fuzz_quiet(1);
    const int rc = parse_cli(av.argc, av.argv, &a);
    sc_fuzz_quiet(0);
    SC_FUZZ_CHECK(rc == -1 || rc == 0 || rc == 2);
    if (rc < 0) {
        /* exactly one output, as parse_cli requires: the bus, a log, or CAN over UDP */
        SC_FUZZ_CHECK((a.iface != NULL) + (a.log_path != NULL) + (a.udp != NULL) == 1);
        SC_FUZZ_CHECK(a.t0_s >= 0.0 && a.t0_s < 1e11);
        SC_FUZZ_CHECK(a.def.n_faults <= SC_EMU_MAX_FAULTS);
        for (size_t f = 0; f < a.def.n_faults; f++) {
            SC_FUZZ_CHECK(a.def.faults[f].period >= 1u && isfinite(a.def.faults[f].start_s));
        }
        /* every command it took is one the protocol's encoder sends (CmdMaterial included) */
        SC_FUZZ_CHECK(a.n_cmds <= MAX_CMDS);
        for (uint32_t k = 0; k < a.n_cmds; k++) {
            sc_can_frame cf;
            SC_FUZZ_CHECK(sc_canproto_encode_cmd(&a.cmds[k].cmd, 0, &cf) == 0);
        }
        SC_FUZZ_CHECK(isfinite(a.def.rate_hz) && isfinite(a.def.duration_s) &&
                      isfinite(a.def.period_s) && isfinite(a.def.silence_ms));
        static sc_emu emu;
        if (sc_emu_init(&emu, &a.def) == 0) {
            SC_FUZZ_CHECK(a.def.script != SC_EMU_CSV);
            sc_can_frame fr[SC_EMU_MAX_FRAMES];
            uint64_t t_ns;
            for (int s = 0; s < 8; s++) {
                const int n = sc_emu_next(&emu, fr, SC_EMU_MAX_FRAMES, &t_ns);
                if (n < 0) {
                    break;
                }
                SC_FUZZ_CHECK(n <= (int)SC_EMU_MAX_FRAMES);
            }
        }
    }
    sc_fuzz_argv_free(&av);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const lines[] = {
        "--script|press|--log|-|--rate-hz|100|--duration-s|2|--depth-mm|10|--hover-mm|30",
        "--script|sweep|--iface|vcan0|--fd|--length-mm|60|--period-s|4|--point|1,2,3",
        "--script|rock|--log|x.log|--log-iface|can1|--t0|1700000000|--angle-deg|15|--no-force",
        "--script|lift|--log|-|--fault|bad-crc:10:0.5|--fault|repeat|--fault|silence:50",
        "--csv|p.csv|--log|-|--silence-ms|300|--fault|counter-jump:7|--fault|implausible:3:1",
        "--script|press|--log|-|--command|material=fat:0.7:0.45@1|--command|reset=tissue@3",
        "--script|press|--log|-|--command|material=thrombus:40:0.45:0.2:20:1@2",
        "--help",
    };
    return sc_fuzz_argv_seed(lines, sizeof lines / sizeof lines[0], i, buf, cap);
}
