/* fuzz_sc_can_replay.c: sonocomp --can-replay FILE (platform/linux/sc_can_replay.c): any log
 * file opens or is refused without crashing; an opened one holds every line as a frame or a
 * counted refusal, and plays every frame exactly once, in file order, none before its time
 * (a virtual clock stepping through the log), then reports the end. */
#define _GNU_SOURCE
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "sc_can_replay.h"
#include "sc_err.h"
#include "sc_fuzz.h"

static uint64_t fake_now;

static uint64_t now_fn(void *ctx)
{
    (void)ctx;
    return fake_now;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const int fd = memfd_create("fuzz_can_replay", 0);
    SC_FUZZ_CHECK(fd >= 0);
    SC_FUZZ_CHECK(size == 0u || write(fd, data, size) == (ssize_t)size);
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    static sc_can_replay r;
    fake_now = 5000000000u;
    const int rc = sc_can_replay_open(&r, path, now_fn, NULL);
    close(fd);
    if (rc != 0) {
        SC_FUZZ_CHECK(rc == SC_ERR_PARSE || rc == SC_ERR_NO_SPACE || rc == SC_ERR_IO);
        SC_FUZZ_CHECK(r.frames == NULL && r.count == 0u);
        sc_can_replay_close(&r);
        return 0;
    }
    SC_FUZZ_CHECK(r.count >= 1u && r.count + r.rejected == r.lines);
    SC_FUZZ_CHECK(r.rejected == 0u || (r.last_reject_line >= 1u && r.last_reject_line <= r.lines));
    sc_can_dev dev = sc_can_replay_dev(&r);
    size_t got = 0;
    uint64_t start = 0;
    /* step the clock through the log in at most 64 steps (the replay starts at the first poll) */
    const uint64_t step = r.duration_ns / 64u + 1u;
    for (int s = 0; s <= 70 && got < r.count; s++) {
        sc_can_frame f;
        int k;
        while ((k = sc_can_recv(&dev, &f)) == 0) {
            if (got == 0u) {
                start = fake_now;
            }
            SC_FUZZ_CHECK(got < r.count);
            SC_FUZZ_CHECK(f.id == r.frames[got].id && f.len == r.frames[got].len);
            SC_FUZZ_CHECK(f.ts_ns <= fake_now && f.ts_ns >= start);
            got++;
        }
        SC_FUZZ_CHECK(k == SC_ERR_WOULD_BLOCK);
        fake_now += step;
    }
    SC_FUZZ_CHECK(got == r.count && r.received == r.count && sc_can_replay_done(&r));
    sc_can_replay_close(&r);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const seeds[] = {
        "(1700000000.000000) vcan0 100#0130000000000000\n(1700000000.000100) vcan0 "
        "101#0230000000000000\n(1700000000.010000) vcan0 102#0330000000000000\n",
        "(1.000000) can0 110##1" "0011223344556677889900112233445566778899001122334455667788990011\n"
        "(0.500000) can0 123#R\n(2.000000) can0 1F334455#DEADBEEF\nnot a line\n",
        "(1700000000.000000) vcan0 080#0000000000000000\n\n(1700000000.5) vcan0 7FF#\n",
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
