/*
 * test_alloc.c: the engine allocates nothing once initialised.
 *
 * Linked with -Wl,--wrap=malloc,calloc,realloc,free (tests/alloc.cmake): every call to the
 * heap from the core, the host simulator and this test goes through the counters below. The
 * whole engine runs 10,000 frames on the host simulator with tracker traffic on the bus; the
 * count must stay zero. The second test proves the counter sees an allocation made inside a
 * frame, so the first test can fail.
 */
#include "sc_test.h"

#include <stdlib.h>

#include "sc_err.h"
#include "sc_hs_rig.h"

static unsigned long allocs;
static int counting;

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t m);
void *__real_realloc(void *p, size_t n);
void __real_free(void *p);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t m);
void *__wrap_realloc(void *p, size_t n);
void __wrap_free(void *p);

void *__wrap_malloc(size_t n)
{
    allocs += (unsigned long)counting;
    return __real_malloc(n);
}

void *__wrap_calloc(size_t n, size_t m)
{
    allocs += (unsigned long)counting;
    return __real_calloc(n, m);
}

void *__wrap_realloc(void *p, size_t n)
{
    allocs += (unsigned long)counting;
    return __real_realloc(p, n);
}

void __wrap_free(void *p)
{
    allocs += (unsigned long)(counting && p);
    __real_free(p);
}

static sc_hs_rig rig;

static void send_peer_traffic(uint32_t i)
{
    sc_can_frame f = {.id = 0x100u + (i % 4u), .len = 8};
    for (uint32_t b = 0; b < 8u; b++) {
        f.data[b] = (uint8_t)(i + b);
    }
    (void)sc_can_send(&rig.peer, &f);
}

static void run_frames(uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        send_peer_traffic(i);
        sc_engine_step(&rig.engine, NULL);
    }
}

static void engine_allocates_nothing_over_10000_frames(void **state)
{
    (void)state;
    sc_engine_def def = sc_engine_default_def();
    assert_int_equal(sc_hs_rig_init(&rig, &def, 1u, 0), SC_OK);
    run_frames(10); /* warm-up: first-use paths */
    allocs = 0;
    counting = 1;
    run_frames(10000);
    counting = 0;
    assert_int_equal(rig.engine.sched.frames, 10010);
    assert_true(rig.engine.counters.can_rx_frames >= 10000u);
    assert_int_equal(allocs, 0);
}

static void leaky_stage(void *user)
{
    (void)user;
    free(malloc(16));
}

static void counter_sees_an_allocation_inside_a_frame(void **state)
{
    (void)state;
    sc_engine_def def = sc_engine_default_def();
    assert_int_equal(sc_hs_rig_init(&rig, &def, 1u, 0), SC_OK);
    assert_int_equal(sc_engine_add_stage(&rig.engine, "leaky", leaky_stage), SC_OK);
    allocs = 0;
    counting = 1;
    run_frames(100);
    counting = 0;
    assert_int_equal(allocs, 200); /* one malloc and one free per frame */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(engine_allocates_nothing_over_10000_frames),
        cmocka_unit_test(counter_sees_an_allocation_inside_a_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
