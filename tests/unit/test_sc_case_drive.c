/* test_sc_case_drive.c: the case file's DRIV section (core/case/sc_case_drive.h), the patient's
 * vessel drive: the encoder and parser round trip; every rule refused by name
 * (SC_ERR_CASE_DRIVE: size, version, reserved word, waveform, non-finite and out-of-range
 * values; a second DRIV: SC_ERR_CASE_SECTION); the loader, whole and sliced, agreeing; a case
 * without DRIV loads with none; a case switch to a bad DRIV refused and counted by the slot, the
 * running case kept;
 * the phantoms' DRIV from sc-casebuild: a plausible, different heart rate per case. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_case.h"
#include "sc_case_drive.h"
#include "sc_err.h"
#include "sc_hs_storage.h"
#include "sc_labels.h"
#include "sc_test_case.h"

static void wr32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void wrf(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    wr32(p, u);
}

static sc_lumen_drive a_drive(void)
{
    sc_lumen_drive d = sc_lumen_drive_default();
    d.heart_rate_bpm = 84.0f;
    d.pulse_pa = 6.5e3f;
    d.wave = (uint8_t)SC_LUMEN_WAVE_SINE;
    d.resp_rate_bpm = 18.0f;
    d.resp_pa = 0.25e3f;
    d.valsalva_pa = 3.0e3f;
    d.valsalva = 1u; /* the held manoeuvre is not a case property: never stored */
    return d;
}

static void encoder_and_parser_round_trip(void **state)
{
    (void)state;
    uint8_t p[SC_CASE_DRIVE_SIZE];
    const sc_lumen_drive d = a_drive();
    assert_int_equal(sc_case_drive_encode(&d, p), SC_OK);
    sc_case_drive v;
    memset(&v, 0, sizeof v);
    assert_int_equal(sc_case_drive_parse(p, sizeof p, &v), SC_OK);
    assert_int_equal(v.present, 1u);
    assert_float_equal(v.d.heart_rate_bpm, 84.0f, 0.0f);
    assert_float_equal(v.d.pulse_pa, 6.5e3f, 0.0f);
    assert_int_equal(v.d.wave, SC_LUMEN_WAVE_SINE);
    assert_float_equal(v.d.resp_rate_bpm, 18.0f, 0.0f);
    assert_float_equal(v.d.resp_pa, 0.25e3f, 0.0f);
    assert_float_equal(v.d.valsalva_pa, 3.0e3f, 0.0f);
    assert_int_equal(v.d.valsalva, 0u);
    /* no pulse and no breathing are valid (0) */
    sc_lumen_drive z = d;
    z.heart_rate_bpm = 0.0f;
    z.resp_rate_bpm = 0.0f;
    assert_int_equal(sc_case_drive_encode(&z, p), SC_OK);
    assert_int_equal(sc_case_drive_parse(p, sizeof p, &v), SC_OK);
    /* the encoder refuses what the parser would */
    z.heart_rate_bpm = 300.0f;
    assert_int_equal(sc_case_drive_encode(&z, p), SC_ERR_RANGE);
    assert_int_equal(sc_case_drive_encode(NULL, p), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_case_drive_parse(NULL, 32u, &v), SC_ERR_INVALID_ARG);
}

static void parser_refuses_every_rule(void **state)
{
    (void)state;
    uint8_t good[SC_CASE_DRIVE_SIZE];
    const sc_lumen_drive d = a_drive();
    assert_int_equal(sc_case_drive_encode(&d, good), SC_OK);
    struct {
        uint32_t off;
        int is_float;
        float f;
        uint32_t u;
        const char *why;
    } bad[] = {
        {0, 0, 0.0f, 2u, "version 2"},
        {4, 1, 10.0f, 0u, "heart rate 10 / min"},
        {4, 1, 251.0f, 0u, "heart rate 251 / min"},
        {4, 1, -60.0f, 0u, "negative heart rate"},
        {4, 1, NAN, 0u, "heart rate NaN"},
        {8, 1, 20.5e3f, 0u, "pulse pressure 20.5 kPa"},
        {8, 1, -1.0f, 0u, "negative pulse pressure"},
        {8, 1, INFINITY, 0u, "pulse pressure infinite"},
        {12, 0, 0.0f, 2u, "waveform 2"},
        {12, 0, 0.0f, 0xFFFFFFFFu, "waveform 2^32-1"},
        {16, 1, 2.0f, 0u, "breathing 2 / min"},
        {16, 1, 61.0f, 0u, "breathing 61 / min"},
        {20, 1, 5.5e3f, 0u, "venous swing 5.5 kPa"},
        {24, 1, 10.5e3f, 0u, "Valsalva 10.5 kPa"},
        {24, 1, NAN, 0u, "Valsalva NaN"},
        {28, 0, 0.0f, 1u, "reserved word"},
    };
    sc_case_drive v;
    memset(&v, 0x5A, sizeof v);
    const sc_case_drive untouched = v;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint8_t p[SC_CASE_DRIVE_SIZE];
        memcpy(p, good, sizeof p);
        if (bad[i].is_float) {
            wrf(p + bad[i].off, bad[i].f);
        } else {
            wr32(p + bad[i].off, bad[i].u);
        }
        const int rc = sc_case_drive_parse(p, sizeof p, &v);
        if (rc != SC_ERR_CASE_DRIVE) {
            fail_msg("%s: %s", bad[i].why, sc_err_name(rc));
        }
        assert_memory_equal(&v, &untouched, sizeof v);
    }
    assert_int_equal(sc_case_drive_parse(good, SC_CASE_DRIVE_SIZE - 4u, &v), SC_ERR_CASE_DRIVE);
    assert_int_equal(sc_case_drive_parse(good, SC_CASE_DRIVE_SIZE + 4u, &v), SC_ERR_CASE_DRIVE);
}

/* a case with 0, 1 (good or bad) or 2 DRIV sections */
static uint8_t *with_drive(const sc_test_case *tc, int sections, int broken, size_t *n)
{
    const size_t cap = tc->size + 4u * 128u;
    uint8_t *b = malloc(cap);
    assert_non_null(b);
    memcpy(b, tc->bytes, tc->size);
    *n = tc->size;
    uint8_t p[SC_CASE_DRIVE_SIZE];
    const sc_lumen_drive d = a_drive();
    assert_int_equal(sc_case_drive_encode(&d, p), SC_OK);
    if (broken) {
        wrf(p + 4, 400.0f); /* heart rate 400 / min */
    }
    for (int s = 0; s < sections; s++) {
        assert_int_equal(sc_case_append_section(b, cap, n, SC_CASE_TAG_DRIV_U32, p, sizeof p),
                         SC_OK);
    }
    return b;
}

static int load_sliced(const uint8_t *b, size_t n, sc_case *c)
{
    static sc_case_check k;
    int rc = sc_case_check_begin(&k, b, n);
    if (rc != SC_OK) {
        return rc;
    }
    while ((rc = sc_case_check_step(&k, 1u << 16)) == 0) {
    }
    return rc == 1 ? sc_case_check_finish(&k, c) : rc;
}

static void loader_whole_and_sliced_agree(void **state)
{
    (void)state;
    sc_test_case tc;
    assert_int_equal(sc_test_case_make(&tc, 5, 5, 5, SC_LABEL_VEIN, "drive"), SC_OK);
    sc_case c;
    assert_int_equal(sc_case_load(tc.bytes, tc.size, &c), SC_OK);
    assert_int_equal(c.drive.present, 0u); /* a case without DRIV is valid, with none */
    const struct {
        int sections, broken, want;
    } v[] = {{1, 0, SC_OK}, {1, 1, SC_ERR_CASE_DRIVE}, {2, 0, SC_ERR_CASE_SECTION}};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        size_t n;
        uint8_t *b = with_drive(&tc, v[i].sections, v[i].broken, &n);
        memset(&c, 0, sizeof c);
        assert_int_equal(sc_case_load(b, n, &c), v[i].want);
        if (v[i].want == SC_OK) {
            assert_int_equal(c.drive.present, 1u);
            assert_float_equal(c.drive.d.heart_rate_bpm, 84.0f, 0.0f);
        }
        sc_case c2;
        memset(&c2, 0, sizeof c2);
        assert_int_equal(load_sliced(b, n, &c2), v[i].want);
        if (v[i].want == SC_OK) {
            assert_memory_equal(&c2.drive, &c.drive, sizeof c.drive);
        }
        free(b);
    }
    free(tc.bytes);
}

static sc_hs_storage g_storage;

static void a_switch_to_a_bad_drive_is_refused_counted_and_the_running_case_stays(void **state)
{
    (void)state;
    sc_test_case tc;
    assert_int_equal(sc_test_case_make(&tc, 5, 5, 5, SC_LABEL_VEIN, "drive"), SC_OK);
    size_t n_good, n_bad;
    uint8_t *good = with_drive(&tc, 1, 0, &n_good);
    uint8_t *bad = with_drive(&tc, 1, 1, &n_bad);
    sc_hs_storage_init(&g_storage);
    assert_int_equal(sc_hs_storage_add(&g_storage, "good", good, n_good), SC_OK);
    assert_int_equal(sc_hs_storage_add(&g_storage, "bad", bad, n_bad), SC_OK);
    const sc_storage_dev dev = sc_hs_storage_dev(&g_storage);
    sc_case_slot slot;
    sc_case_slot_init(&slot);
    assert_int_equal(sc_case_slot_switch(&slot, &dev, "good"), SC_OK);
    assert_int_equal(slot.c.drive.present, 1u);
    const uint32_t id = slot.c.case_id;
    assert_int_equal(sc_case_slot_switch(&slot, &dev, "bad"), SC_ERR_CASE_DRIVE);
    assert_int_equal(slot.refused, 1u);
    assert_int_equal(slot.last_error, SC_ERR_CASE_DRIVE);
    assert_int_equal(slot.loaded, 1);
    assert_int_equal(slot.c.case_id, id); /* the running case stays */
    assert_float_equal(slot.c.drive.d.heart_rate_bpm, 84.0f, 0.0f);
    sc_case_slot_close(&slot);
    free(good);
    free(bad);
    free(tc.bytes);
}

static void phantoms_carry_a_different_plausible_drive_each(void **state)
{
    (void)state;
    const char *names[3] = {"neck-ijv", "femoral", "femoral-dvt"};
    const float want_bpm[3] = {60.0f, 78.0f, 96.0f};
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/cases/%s.scase", SC_BINARY_DIR, names[i]);
        FILE *f = fopen(path, "rb");
        if (f == NULL) {
            skip(); /* the cases target builds them with every build */
        }
        fseek(f, 0, SEEK_END);
        const long size = ftell(f);
        fseek(f, 0, SEEK_SET);
        uint8_t *b = malloc((size_t)size);
        assert_non_null(b);
        assert_int_equal(fread(b, 1, (size_t)size, f), (size_t)size);
        fclose(f);
        sc_case c;
        assert_int_equal(sc_case_load(b, (size_t)size, &c), SC_OK);
        assert_int_equal(c.drive.present, 1u);
        print_message("%s: heart %.0f / min, pulse %.1f kPa, breathing %.0f / min\n", names[i],
                      (double)c.drive.d.heart_rate_bpm, (double)c.drive.d.pulse_pa * 1e-3,
                      (double)c.drive.d.resp_rate_bpm);
        assert_float_equal(c.drive.d.heart_rate_bpm, want_bpm[i], 0.0f);
        assert_true(c.drive.d.pulse_pa >= 4.0e3f && c.drive.d.pulse_pa <= 8.0e3f);
        assert_int_equal(c.drive.d.wave, SC_LUMEN_WAVE_ARTERIAL);
        assert_true(c.drive.d.resp_rate_bpm >= 10.0f && c.drive.d.resp_rate_bpm <= 25.0f);
        free(b);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(encoder_and_parser_round_trip),
        cmocka_unit_test(parser_refuses_every_rule),
        cmocka_unit_test(loader_whole_and_sliced_agree),
        cmocka_unit_test(a_switch_to_a_bad_drive_is_refused_counted_and_the_running_case_stays),
        cmocka_unit_test(phantoms_carry_a_different_plausible_drive_each),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
