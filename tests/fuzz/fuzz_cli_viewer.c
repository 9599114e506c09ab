/* fuzz_cli_viewer.c: sc-viewer's command line (parse_opts in tools/viewer/sc_viewer.c) takes
 * any argument vector, never crashes, and leaves every option it accepts within the ranges the
 * viewer then relies on (a port, finite non-negative times, a window size it can allocate). */
#define _GNU_SOURCE
#include "sc_fuzz_argv.h"

#define main viewer_main
#include "../../tools/viewer/sc_viewer.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_argv av;
    sc_fuzz_argv_split(data, size, "sc-viewer", &av);
    vw_opts o;
    sc_fuzz_quiet(1);
    const int rc = parse_opts(av.argc, av.argv, &o);
    sc_fuzz_quiet(0);
    SC_FUZZ_CHECK(rc == -1 || rc == 0 || rc == 2);
    if (rc < 0) {
        SC_FUZZ_CHECK(o.port >= 1u);
        SC_FUZZ_CHECK(o.bind_addr != NULL);
        SC_FUZZ_CHECK(isfinite(o.seconds) && o.seconds >= 0.0);
        SC_FUZZ_CHECK(isfinite(o.idle_s) && o.idle_s >= 0.0);
        SC_FUZZ_CHECK(isfinite(o.hold_s) && o.hold_s >= 0.0 && o.hold_s <= 3600.0);
        SC_FUZZ_CHECK(o.png_every >= 1u && o.gif_every >= 1u);
        SC_FUZZ_CHECK(o.width >= 64u && o.width <= 4096u && o.height >= 64u && o.height <= 4096u);
    }
    sc_fuzz_argv_free(&av);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const lines[] = {
        "--port|5600|--bind|127.0.0.1|--headless|--frames|100|--seconds|5|--quiet",
        "-p5601|-b|0.0.0.0|--idle|1.5|--record-png|out|--png-every|3|--gif|a.gif|--gif-every|2",
        "--screenshot|s.png|--size|800x600|--hold|2|-n|7|-t|0.25",
        "--help",
        "-V",
    };
    return sc_fuzz_argv_seed(lines, sizeof lines / sizeof lines[0], i, buf, cap);
}
