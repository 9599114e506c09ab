/* test_case_switch.c: case switches between frames, on the host simulator at 60 Hz, through
 * every installed phantom case (the case builder's output in the build tree) and a corrupted
 * one. While a switch is prepared the running case keeps running (a complete frame every
 * period, its case id in the status), each frame does at most one bounded slice of the switch
 * (at most case_check_slice_bytes validated), the swap happens between two frames, refusals are
 * counted and reported on CAN, and no frame misses its deadline on the virtual clock. The host
 * CPU time of the frames is printed (a figure, not a check: timed tests flake on shared
 * machines). */
#define _POSIX_C_SOURCE 200809L
#include "sc_test.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "sc_canproto.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_storage_linux.h"
#include "sc_test_cmd.h"

#define CASE_CAP (16u << 20)
#define MAX_INSTALLED 4u

static sc_hs_rig rig;
static uint8_t case_bytes[MAX_INSTALLED + 1u][CASE_CAP];
static char names[MAX_INSTALLED][SC_STORAGE_LINUX_NAME_MAX];
static uint32_t installed;
static const char *const k_broken = "broken.scase";

static size_t read_case(const char *name, uint8_t *buf)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/cases/%s", SC_BINARY_DIR, name);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    const size_t n = fread(buf, 1, CASE_CAP, f);
    assert_true(feof(f)); /* the whole file fits */
    fclose(f);
    return n;
}

static double thread_cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static void rig_up(void)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/cases", SC_BINARY_DIR);
    const int rc = sc_storage_linux_list(dir, ".scase", names, MAX_INSTALLED, &installed);
    assert_int_equal(rc, SC_OK);
    assert_true(installed >= 3u); /* neck-ijv, femoral, femoral-dvt */
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0;
    for (uint32_t i = 0; i < installed; i++) {
        def.case_names[i] = names[i];
    }
    def.case_names[installed] = k_broken;
    def.case_count = installed + 1u;
    assert_int_equal(sc_hs_rig_init(&rig, &def, 7u, 0), SC_OK);
    size_t n = 0;
    for (uint32_t i = 0; i < installed; i++) {
        n = read_case(names[i], case_bytes[i]);
        assert_int_equal(sc_hs_storage_add(&rig.storage, names[i], case_bytes[i], n), SC_OK);
    }
    /* the last installed case with one voxel bit flipped: its section CRC refuses it */
    memcpy(case_bytes[installed], case_bytes[installed - 1u], n);
    case_bytes[installed][n / 2u] ^= 0x04u;
    assert_int_equal(sc_hs_storage_add(&rig.storage, k_broken, case_bytes[installed], n), SC_OK);
    assert_int_equal(sc_engine_load_case(&rig.engine, names[0]), SC_OK);
}

static void send_select(uint8_t id, uint8_t counter)
{
    const sc_cmd c = {.kind = SC_CMD_SELECT_CASE, .case_id = id};
    (void)counter; /* the signer keeps the E2E counters */
    assert_int_equal(sc_test_send_cmd(&rig.peer, &c), SC_OK);
}

static uint64_t slices(void)
{
    const sc_engine_counters *c = sc_engine_get_counters(&rig.engine);
    uint64_t s = 0;
    for (uint32_t k = 0; k < SC_ENGINE_SLICE_COUNT; k++) {
        s += c->control_slices[k];
    }
    return s;
}

/* Host CPU time of the heaviest frame that ran each kind of slice (all switches). */
static double worst_by_kind_ms[SC_ENGINE_SLICE_COUNT];
_Static_assert(SC_ENGINE_SLICE_COUNT == 10, "slice kinds and their names");
static const char *const k_kind_names[SC_ENGINE_SLICE_COUNT] = {
    "open",          "validate",   "build mesh", "build labels",  "build springs",
    "build msds",    "msds scale", "build fem",  "build contact", "swap",
};

typedef struct switch_run {
    uint32_t frames;       /* until the new case ran */
    double worst_frame_ms; /* host CPU time of the heaviest frame during the switch */
} switch_run;

/* One frame with the checks that hold in every frame of a switch. */
static void frame_checked(uint8_t running_id, double *worst_ms)
{
    const uint64_t slices_before = slices();
    uint64_t by_kind[SC_ENGINE_SLICE_COUNT];
    memcpy(by_kind, sc_engine_get_counters(&rig.engine)->control_slices, sizeof by_kind);
    const uint64_t complete_before = rig.display.frames_complete;
    const double t0 = thread_cpu_ms();
    sc_frame_result r;
    sc_engine_step(&rig.engine, &r);
    const double dt = thread_cpu_ms() - t0;
    *worst_ms = dt > *worst_ms ? dt : *worst_ms;
    assert_false(r.missed);
    assert_true(slices() - slices_before <= 1u); /* at most one slice of a switch per frame */
    for (uint32_t k = 0; k < SC_ENGINE_SLICE_COUNT; k++) {
        if (sc_engine_get_counters(&rig.engine)->control_slices[k] != by_kind[k] &&
            dt > worst_by_kind_ms[k]) {
            worst_by_kind_ms[k] = dt;
        }
    }
    assert_int_equal(rig.display.frames_complete, complete_before + 1u); /* the image goes on */
    assert_true(sc_engine_get_counters(&rig.engine)->case_check_bytes_worst <=
                rig.engine.def.case_check_slice_bytes);
    sc_engine_status st;
    sc_engine_get_status(&rig.engine, &st);
    assert_true(st.case_loaded);
    if (st.switching) {
        assert_int_equal(st.case_id, running_id); /* the running case keeps running */
    }
}

static switch_run switch_to(uint8_t id, uint8_t counter)
{
    switch_run out = {0, 0.0};
    const uint8_t from = rig.engine.case_id;
    send_select(id, counter);
    sc_engine_status st;
    do {
        frame_checked(from, &out.worst_frame_ms);
        out.frames++;
        sc_engine_get_status(&rig.engine, &st);
        assert_true(out.frames < 600u);
    } while (st.switching || out.frames == 1u);
    return out;
}

static void switches_through_every_installed_case_with_no_miss_and_bounded_slices(void **state)
{
    (void)state;
    rig_up();
    double idle_ms = 0.0;
    for (uint32_t i = 0; i < 10u; i++) {
        frame_checked(0, &idle_ms);
    }
    print_message("%-20s %8s %12s %14s\n", "switch to", "frames", "check B/slice",
                  "worst CPU ms");
    uint8_t counter = 0;
    for (uint32_t k = 1; k <= installed; k++) {
        const uint8_t id = (uint8_t)(k % installed); /* every case, then back to the first */
        const uint64_t loads = sc_engine_get_counters(&rig.engine)->case_loads;
        const switch_run s = switch_to(id, counter++);
        assert_int_equal(sc_engine_get_counters(&rig.engine)->case_loads, loads + 1u);
        assert_int_equal(rig.engine.case_id, id);
        assert_string_equal(sc_engine_get_case(&rig.engine)->name,
                            rig.engine.slot.c.name); /* the view is the swapped-in case's */
        /* sliced: open, the validation in >= 2 slices of at most 1 MiB, build, swap */
        assert_true(s.frames >= 5u);
        print_message("%-20s %8u %12llu %14.2f\n", names[id], s.frames,
                      (unsigned long long)sc_engine_get_counters(&rig.engine)
                          ->case_check_bytes_worst,
                      s.worst_frame_ms);
    }
    print_message("frames without a switch: worst CPU %.2f ms\n", idle_ms);
    print_message("worst host CPU of a frame that ran a slice of this kind (whole frame):\n");
    for (uint32_t k = 0; k < SC_ENGINE_SLICE_COUNT; k++) {
        print_message("  %-14s %8.2f ms  (%llu slices)\n", k_kind_names[k], worst_by_kind_ms[k],
                      (unsigned long long)sc_engine_get_counters(&rig.engine)->control_slices[k]);
    }
    assert_int_equal(sc_engine_get_sched(&rig.engine)->misses, 0);
    assert_int_equal(sc_engine_get_counters(&rig.engine)->case_load_failures, 0);
}

static void refused_switches_are_counted_reported_and_the_running_case_stays(void **state)
{
    (void)state;
    rig_up();
    const uint64_t hash_id = rig.engine.slot.c.case_id;
    /* a corrupted case: prepared in slices, refused by its CRC, the running case stays */
    const switch_run s = switch_to((uint8_t)installed, 0);
    const sc_engine_counters *c = sc_engine_get_counters(&rig.engine);
    assert_true(s.frames >= 2u);
    assert_int_equal(c->case_load_failures, 1);
    assert_int_equal(c->last_case_error, SC_ERR_CASE_CRC);
    assert_int_equal(rig.engine.case_id, 0);
    assert_int_equal(rig.engine.slot.c.case_id, hash_id);
    assert_true(rig.engine.health.active & (1u << SC_FAULT_CONFIG));
    /* an index beyond the catalogue: refused at once */
    const uint64_t refused = c->commands_refused;
    send_select(200u, 1);
    double worst = 0.0;
    frame_checked(0, &worst);
    assert_int_equal(c->commands_refused, refused + 1u);
    /* a second select while a switch runs: refused, the first one completes */
    send_select(1u, 2);
    frame_checked(0, &worst);
    assert_int_equal(sc_engine_select_case(&rig.engine, names[2]), SC_ERR_STATE);
    assert_int_equal(c->commands_refused, refused + 2u);
    for (uint32_t i = 0; i < 200u && rig.engine.sw.phase != SC_SWITCH_IDLE; i++) {
        frame_checked(rig.engine.case_id, &worst);
    }
    assert_int_equal(rig.engine.case_id, 1);
    /* by name, outside the catalogue: unlisted id; a name too long: refused */
    char long_name[SC_ENGINE_CASE_NAME_MAX + 1u];
    memset(long_name, 'a', sizeof long_name - 1u);
    long_name[sizeof long_name - 1u] = '\0';
    assert_int_equal(sc_engine_select_case(&rig.engine, long_name), SC_ERR_RANGE);
    assert_int_equal(sc_engine_select_case(&rig.engine, "missing.scase"), SC_OK);
    for (uint32_t i = 0; i < 10u; i++) {
        frame_checked(1, &worst);
    }
    assert_int_equal(c->last_case_error, SC_ERR_NOT_FOUND);
    assert_int_equal(rig.engine.case_id, 1);
    /* the status frames on CAN carry the refusal (the CONFIG fault bit) and the running case */
    sc_can_frame f;
    sc_status_msg last = {0};
    int seen = 0;
    while (sc_can_recv(&rig.peer, &f) == SC_OK) { /* the newest EngineStatus counts */
        sc_status_msg m;
        if (f.id == SC_CANID_STATUS && sc_canproto_decode_status_part(&f, &m) == SC_OK) {
            seen = 1;
            last = m;
        }
    }
    assert_true(seen);
    assert_true(last.fault_bits & (1u << SC_FAULT_CONFIG));
    assert_int_equal(last.case_id, 1);
    assert_int_equal(sc_engine_get_sched(&rig.engine)->misses, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(switches_through_every_installed_case_with_no_miss_and_bounded_slices),
        cmocka_unit_test(refused_switches_are_counted_reported_and_the_running_case_stays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
