/* fuzz_cli_hostsim.c: sc-hostsim's command line (parse_args in platform/hostsim/main_hostsim.c)
 * takes any argument vector, never crashes, and leaves every option it accepts within the
 * ranges the simulator then relies on. */
#define _GNU_SOURCE
#include "sc_fuzz_argv.h"

#define main hostsim_main
#include "../../platform/hostsim/main_hostsim.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_argv av;
    sc_fuzz_argv_split(data, size, "sc-hostsim", &av);
    options o;
    sc_fuzz_quiet(1);
    const int rc = parse_args(av.argc, av.argv, &o);
    sc_fuzz_quiet(0);
    SC_FUZZ_CHECK(rc == 0 || rc == -1 || rc == 2);
    if (rc == 0) {
        SC_FUZZ_CHECK(o.seconds >= 0.01 && o.seconds <= 3600.0);
        SC_FUZZ_CHECK(o.every <= 100000u);
        SC_FUZZ_CHECK(o.png_width >= 16u && o.png_width <= 4096u);
        SC_FUZZ_CHECK(o.png_height >= 16u && o.png_height <= 4096u);
        SC_FUZZ_CHECK(o.depth_mm >= 0.0f && o.depth_mm <= 50.0f);
        SC_FUZZ_CHECK(!o.point_set || (isfinite(o.point_mm[0]) && isfinite(o.point_mm[1]) &&
                                       isfinite(o.point_mm[2])));
        SC_FUZZ_CHECK(o.case_name && o.cases_dir && o.out_dir && o.script);
        SC_FUZZ_CHECK(!(o.replay_path && (o.csv_path || o.record_path || o.bundle_path ||
                                          o.call)));
        SC_FUZZ_CHECK(o.call <= SC_ASSESS_CALL_DVT);
        SC_FUZZ_CHECK(!o.call || o.call_t_s < 0.0 || o.call_t_s <= 3600.0);
    }
    sc_fuzz_argv_free(&av);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const lines[] = {
        "--case|femoral-dvt|--method|fem|--script|sweep|--seconds|2|--quiet",
        "--faults|drop=100000,corrupt=10000,dup=5,reorder=7,delay=1000|--seed|42|--fd",
        "--point|1.5,-2,30|--depth|12|--every|0|--png-size|240x320|--out|out/x",
        "--replay|log.txt|--frame-raw|f.raw|--cases-dir|cases",
        "--csv|poses.csv|--record|rec.log|--seconds=0.5",
        "--help",
        "--version",
    };
    return sc_fuzz_argv_seed(lines, sizeof lines / sizeof lines[0], i, buf, cap);
}
