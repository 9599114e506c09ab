/* fuzz_cli_sonocomp.c: sonocomp's command line (parse_cli in platform/linux/main_sonocomp.c)
 * and its --set overrides applied to the default configuration take any argument vector,
 * never crash, and leave the options within what the program then relies on. */
#define _GNU_SOURCE
#include "sc_fuzz_argv.h"

#define main sonocomp_main
#include "../../platform/linux/main_sonocomp.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_argv av;
    sc_fuzz_argv_split(data, size, "sonocomp", &av);
    cli a;
    sc_fuzz_quiet(1);
    const int rc = parse_cli(av.argc, av.argv, &a);
    int set_rc = -1;
    static sc_rtcfg cfg;
    if (rc < 0) {
        sc_rtcfg_default(&cfg);
        set_rc = apply_sets(&a, &cfg);
    }
    sc_fuzz_quiet(0);
    SC_FUZZ_CHECK(rc == -1 || rc == EXIT_OK || rc == EXIT_USAGE);
    if (rc < 0) {
        SC_FUZZ_CHECK(a.set_n <= sizeof a.sets / sizeof a.sets[0]);
        SC_FUZZ_CHECK(a.inject_loss_permille <= 1000u);
        SC_FUZZ_CHECK(a.seconds >= 0.0 && isfinite(a.seconds));
        SC_FUZZ_CHECK(set_rc == 0 || set_rc == EXIT_CONFIG);
        SC_FUZZ_CHECK(cfg.frame_rate_hz >= SC_FRAME_RATE_MIN_HZ &&
                      cfg.frame_rate_hz <= SC_FRAME_RATE_MAX_HZ);
        SC_FUZZ_CHECK(cfg.image_lines <= SC_MAX_SCAN_LINES &&
                      cfg.image_samples <= SC_MAX_SCAN_SAMPLES);
        SC_FUZZ_CHECK(memchr(cfg.case_path, 0, sizeof cfg.case_path) != NULL);
    }
    sc_fuzz_argv_free(&av);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const lines[] = {
        "--config|config/sonocomp.conf|--set|frame_rate_hz=30|-n|100",
        "-c|x.conf|--check-config|--case-dir|cases|--seconds|2.5",
        "--set|display.target=udp:127.0.0.1:5600|--set|image.tgc_db=0 1 2 3 4 5 6 7|-t1",
        "--inject-loss|250|--can-replay|log.txt|--frames=7|-sphysics.method=fem",
        "--help-config",
        "-V",
        "--set|case=cases/neck-ijv.scase|-s|rt.cpu=-1|-s|log.level=warn|--|extra",
    };
    return sc_fuzz_argv_seed(lines, sizeof lines / sizeof lines[0], i, buf, cap);
}
