/* fuzz_sc_posecsv.c: the pose CSV reader of the host simulator and the tracker emulator
 * (sc-hostsim --csv, sc-tracker-emu --csv: t_s,x,y,z,qw,qx,qy,qz[,force]) takes any bytes,
 * never crashes, and either refuses them with a line number inside the text or returns rows
 * that are finite, strictly increasing in time, and that the emulator then accepts or refuses
 * as a definition without crashing; an accepted one is run for a few samples. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_err.h"
#include "sc_fuzz.h"
#include "sc_trkemu.h"

#define ROWS_CAP 64u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0u) {
        return 0;
    }
    FILE *fp = fmemopen((void *)(uintptr_t)data, size, "r");
    SC_FUZZ_CHECK(fp != NULL);
    static sc_emu_row rows[ROWS_CAP];
    size_t n = 0, bad = 0;
    const int rc = sc_emu_load_csv(fp, rows, ROWS_CAP, &n, &bad);
    fclose(fp);
    size_t lines = 1;
    for (size_t i = 0; i < size; i++) {
        lines += data[i] == '\n';
    }
    if (rc != 0) {
        SC_FUZZ_CHECK(rc == SC_ERR_PARSE || rc == SC_ERR_NO_SPACE);
        SC_FUZZ_CHECK(bad <= lines);
        return 0;
    }
    SC_FUZZ_CHECK(n >= 1u && n <= ROWS_CAP && bad == 0u);
    for (size_t i = 0; i < n; i++) {
        SC_FUZZ_CHECK(isfinite(rows[i].t_s));
        SC_FUZZ_CHECK(i == 0u || rows[i].t_s > rows[i - 1u].t_s);
    }
    sc_emu_def def = sc_emu_default_def();
    def.script = SC_EMU_CSV;
    def.rows = rows;
    def.n_rows = n;
    def.duration_s = 0.05;
    static sc_emu emu;
    if (sc_emu_init(&emu, &def) != 0) {
        return 0;
    }
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    for (int s = 0; s < 5; s++) {
        uint64_t t_ns = 0;
        const int nf = sc_emu_next(&emu, f, SC_EMU_MAX_FRAMES, &t_ns);
        if (nf < 0) {
            /* past the end, or a row whose pose the protocol cannot carry (a zero quaternion,
             * a position or force out of the signal's range or beyond float's): refused when it
             * comes up */
            SC_FUZZ_CHECK(nf == SC_ERR_NOT_FOUND || nf == SC_ERR_CAN_SIGNAL ||
                          nf == SC_ERR_NOT_FINITE);
            break;
        }
        SC_FUZZ_CHECK(nf <= (int)SC_EMU_MAX_FRAMES);
        for (int k = 0; k < nf; k++) {
            SC_FUZZ_CHECK(f[k].len <= SC_CAN_MAX_DLEN);
        }
    }
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const seeds[] = {
        "t_s,x,y,z,qw,qx,qy,qz,force\n0,0,0,10,0,1,0,0,0.5\n0.5,0,0,2,0,1,0,0,3\n1,0,0,10,0,1,0,0\n",
        "# comment\n0.0, 1.5, -2, 30, 1, 0, 0, 0\r\n  0.25,1.5,-2,20,0.7071,0.7071,0,0\n",
        "0,0,0,0,0,1,0,0\n1e-3,0,0,0,0,1,0,0,-1\n",
    };
    if (i >= sizeof seeds / sizeof seeds[0]) {
        return 0;
    }
    const size_t n = strlen(seeds[i]);
    if (n > cap) {
        return 0;
    }
    memcpy(buf, seeds[i], n);
    return n;
}
