/*
 * main.c: the bare-metal link proof. A minimal HAL (DWT cycle counter clock, CAN and display
 * that accept and discard, empty storage) drives the real engine: init, then frame steps.
 * On hardware this runs; here it proves the core links with no heap and no OS.
 */
#include <stdint.h>

#include "sc_assert.h"
#include "sc_engine.h"
#include "sc_err.h"

#define CORE_HZ 480000000ull /* STM32H7 at full speed */

static volatile uint32_t *const dwt_ctrl = (volatile uint32_t *)0xE0001000u;
static volatile uint32_t *const dwt_cyccnt = (volatile uint32_t *)0xE0001004u;
static volatile uint32_t *const dem_cr = (volatile uint32_t *)0xE000EDFCu;

static uint64_t cycles_hi;
static uint32_t cycles_last;

static uint64_t m7_now_ns(void *ctx)
{
    (void)ctx;
    uint32_t c = *dwt_cyccnt;
    if (c < cycles_last) {
        cycles_hi += 1ull << 32;
    }
    cycles_last = c;
    return ((cycles_hi | c) * 1000000000ull) / CORE_HZ;
}

static int m7_sleep_until_ns(void *ctx, uint64_t t_ns)
{
    while (m7_now_ns(ctx) < t_ns) {
        __asm volatile("wfe");
    }
    return SC_OK;
}

static int m7_can_send(void *ctx, const sc_can_frame *f)
{
    (void)ctx;
    (void)f;
    return SC_OK;
}

static int m7_can_recv(void *ctx, sc_can_frame *f)
{
    (void)ctx;
    (void)f;
    return SC_ERR_WOULD_BLOCK;
}

static int m7_begin(void *ctx, const sc_display_frame_info *info)
{
    (void)ctx;
    (void)info;
    return SC_OK;
}

static int m7_line(void *ctx, uint32_t frame_no, uint16_t line, const uint8_t *s, uint16_t n)
{
    (void)ctx;
    (void)frame_no;
    (void)line;
    (void)s;
    (void)n;
    return SC_OK;
}

static int m7_end(void *ctx, const sc_display_end_info *end)
{
    (void)ctx;
    (void)end;
    return SC_OK;
}

static int m7_open(void *ctx, const char *name, const uint8_t **data, size_t *size)
{
    (void)ctx;
    (void)name;
    (void)data;
    (void)size;
    return SC_ERR_NOT_FOUND;
}

static void m7_close(void *ctx, const uint8_t *data, size_t size)
{
    (void)ctx;
    (void)data;
    (void)size;
}

void sc_assert_failed(const char *file, int line, const char *expr)
{
    (void)file;
    (void)line;
    (void)expr;
    __asm volatile("bkpt #0");
    for (;;) {
    }
}

static const sc_clock_ops clock_ops = {.now_ns = m7_now_ns, .sleep_until_ns = m7_sleep_until_ns};
static const sc_can_ops can_ops = {.send = m7_can_send, .recv = m7_can_recv};
static const sc_display_ops display_ops = {
    .frame_begin = m7_begin, .line = m7_line, .frame_end = m7_end};
static const sc_storage_ops storage_ops = {.open = m7_open, .close = m7_close};

static sc_engine engine; /* the whole engine state, in .bss (SRAM) */

int main(void)
{
    *dem_cr |= 1u << 24; /* TRCENA */
    *dwt_cyccnt = 0;
    *dwt_ctrl |= 1u;     /* CYCCNTENA */
    static const sc_hal hal = {
        .clock = {.ops = &clock_ops},
        .can = {.ops = &can_ops},
        .display = {.ops = &display_ops},
        .storage = {.ops = &storage_ops},
    };
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0;
    if (sc_engine_init(&engine, &def, &hal) != SC_OK) {
        return 1;
    }
    for (;;) {
        sc_engine_step(&engine, 0);
    }
}
