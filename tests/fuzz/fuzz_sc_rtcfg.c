/* fuzz_sc_rtcfg.c: the runtime configuration parser takes any bytes (it reads a file an
 * operator edits): never crashes, reports at most one error per line, keeps every line number
 * within the text, and leaves every numeric setting within its documented range. */
#include <string.h>

#include "sc_config.h"
#include "sc_fuzz.h"
#include "sc_rtcfg.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static sc_rtcfg cfg;
    sc_rtcfg_default(&cfg);
    sc_rtcfg_error errs[16];
    uint32_t stored = 0;
    uint32_t bad = sc_rtcfg_parse(&cfg, (const char *)data, size, errs, 16u, &stored);
    uint32_t lines = 1;
    for (size_t i = 0; i < size; i++) {
        lines += data[i] == '\n';
    }
    SC_FUZZ_CHECK(stored <= 16u && stored <= bad && bad <= lines);
    for (uint32_t i = 0; i < stored; i++) {
        SC_FUZZ_CHECK(errs[i].err < 0 && errs[i].line >= 1u && errs[i].line <= lines);
        SC_FUZZ_CHECK(i == 0u || errs[i].line > errs[i - 1u].line);
        SC_FUZZ_CHECK(memchr(errs[i].reason, 0, sizeof errs[i].reason) != NULL);
        SC_FUZZ_CHECK(memchr(errs[i].key, 0, sizeof errs[i].key) != NULL);
    }
    SC_FUZZ_CHECK(cfg.frame_rate_hz >= SC_FRAME_RATE_MIN_HZ &&
                  cfg.frame_rate_hz <= SC_FRAME_RATE_MAX_HZ);
    SC_FUZZ_CHECK(cfg.image_lines <= SC_MAX_SCAN_LINES && cfg.image_samples <= SC_MAX_SCAN_SAMPLES);
    SC_FUZZ_CHECK(cfg.physics_iterations >= 1u && cfg.physics_iterations <= SC_PHYS_ITERATIONS_MAX);
    SC_FUZZ_CHECK(cfg.physics_dt_s >= 0.0001f && cfg.physics_dt_s <= 0.1f);
    SC_FUZZ_CHECK(cfg.physics_cg_iterations >= 1u &&
                  cfg.physics_cg_iterations <= SC_PHYS_ITERATIONS_MAX);
    SC_FUZZ_CHECK(cfg.rt_cpu >= -1 && cfg.rt_cpu <= 1023);
    SC_FUZZ_CHECK(cfg.display_port <= 65535u);
    for (uint32_t b = 0; b < SC_BSCAN_TGC_BANDS; b++) {
        SC_FUZZ_CHECK(cfg.image_tgc_db[b] >= -20.0f && cfg.image_tgc_db[b] <= 20.0f);
    }
    SC_FUZZ_CHECK(memchr(cfg.case_path, 0, sizeof cfg.case_path) != NULL);
    SC_FUZZ_CHECK(memchr(cfg.display_host, 0, sizeof cfg.display_host) != NULL);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const seeds[] = {
        "frame_rate_hz = 60\nimage.tgc_db = 0 1 2 3 4 5 6 7\ndisplay.target = udp:127.0.0.1:5600\n",
        "# c\ncase = cases/x.scase # comment\nphysics.dt_s = 2.5e-3\r\nrt.cpu = -1\n",
        "display.target = png:/tmp/a#b\nimage.depth_mm=300\nlog.level = warn\nrt.mlock = off\n",
    };
    if (i >= sizeof seeds / sizeof seeds[0]) {
        return 0;
    }
    size_t n = strlen(seeds[i]);
    if (n > cap) {
        n = cap;
    }
    memcpy(buf, seeds[i], n);
    return n;
}
