/* test_gw_bscan.c: the console's B-scan message (tools/gateway/gw_bscan.h): the image rows of
 * the display-link assembler (fixed stride) arrive line after line; the imaging parameters, the
 * colour box with its values and the spectrum columns (the last 16, oldest first) are carried
 * and read back exactly; a frame without colour carries none; malformed messages are refused. */
#include "sc_test.h"

#include <stdlib.h>
#include <string.h>

#include "gw_bscan.h"

static uint8_t image[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
static int8_t colour[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
static uint8_t msg[GW_BSCAN_MAX];

static int same(float a, float b) /* bit for bit */
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* a 6-line, 20-sample frame (fewer samples than the assembler's stride) */
static sc_dlink_done frame(uint32_t no, int with_colour)
{
    sc_dlink_done d;
    memset(&d, 0, sizeof d);
    d.frame = (sc_dlink_frame){.frame_no = no, .flags = 1, .line_count = 6, .samples = 20,
                               .geometry_id = 1};
    d.begin = (sc_dlink_begin){.depth_mm = 40.0f, .width_mm = 60.0f, .radius_mm = 40.0f};
    d.end = (sc_dlink_end){.lines_sent = 6, .compression_pm = 120, .artery_compression_pm = 7};
    for (uint32_t l = 0; l < 6u; l++) {
        for (uint32_t k = 0; k < SC_MAX_SCAN_SAMPLES; k++) {
            image[l * SC_MAX_SCAN_SAMPLES + k] = (uint8_t)(k < 20u ? 10u * l + k : 0xEEu);
            colour[l * SC_MAX_SCAN_SAMPLES + k] = (int8_t)((int)(l * 20u + k) - 60);
        }
    }
    d.image = image;
    d.params_known = 1;
    d.params = (sc_dlink_params){.gain_db = 6.0f, .dynamic_range_db = 60.0f, .focus_mm = 20.0f,
                                 .frequency_mhz = 7.5f, .tgc_db = {0, 1, 2, 3, 4, 5, 6, 7}};
    if (with_colour) {
        d.colour = colour;
        d.doppler_seen = 1;
        d.doppler = (sc_dlink_doppler){.box_line_lo = 1, .box_line_hi = 4, .box_sample_lo = 5,
                                       .box_sample_hi = 15, .nyquist_mm_s = 300.0f,
                                       .steer_deg = -10.0f, .gate_velocity_mm_s = 120.0f,
                                       .gate_line = 2, .gate_sample_lo = 8, .gate_sample_hi = 10,
                                       .bins = 8};
        memset(d.doppler.spectrum, (int)(no & 0xFFu), 8);
    }
    return d;
}

static void image_params_and_colour_box_read_back(void **state)
{
    (void)state;
    gw_spectrum_hist h;
    gw_spectrum_clear(&h);
    const sc_dlink_done d = frame(100, 1);
    const size_t n = gw_bscan_build(msg, sizeof msg, &d, &h);
    assert_int_equal(n, GW_BSCAN_HDR + 6 * 20 + GW_BSCAN_PARAMS + GW_BSCAN_DOPPLER + (4 + 8) +
                            3 * 10);
    gw_bscan_view v;
    assert_int_equal(gw_bscan_parse(msg, n, &v), 0);
    assert_int_equal(v.flags, GW_BSCAN_HAS_PARAMS | GW_BSCAN_HAS_DOPPLER | GW_BSCAN_HAS_COLOUR);
    assert_int_equal(v.frame_no, 100);
    assert_int_equal(v.lines, 6);
    assert_int_equal(v.samples, 20);
    assert_int_equal(v.geometry_id, 1);
    assert_true(same(v.radius_mm, 40.0f) && same(v.depth_mm, 40.0f) && same(v.width_mm, 60.0f));
    assert_int_equal(v.vein_pm, 120);
    assert_int_equal(v.artery_pm, 7);
    for (uint32_t l = 0; l < 6u; l++) { /* row l is the assembler's row l, not its stride's */
        for (uint32_t k = 0; k < 20u; k++) {
            assert_int_equal(v.image[l * 20u + k], 10u * l + k);
        }
    }
    float f;
    memcpy(&f, v.params + 8, 4);
    assert_true(same(f, 20.0f)); /* focus */
    memcpy(&f, v.params + 16 + 4 * 7, 4);
    assert_true(same(f, 7.0f)); /* deepest TGC band */
    assert_int_equal(v.box_line_lo, 1);
    assert_int_equal(v.box_sample_hi, 15);
    assert_int_equal(v.bins, 8);
    assert_int_equal(v.columns, 1);
    for (uint32_t l = 0; l < 3u; l++) {
        for (uint32_t k = 0; k < 10u; k++) {
            assert_int_equal(v.colour[l * 10u + k], colour[(1u + l) * SC_MAX_SCAN_SAMPLES + 5u + k]);
        }
    }
    /* every byte counts: one less or one more is refused */
    assert_int_equal(gw_bscan_parse(msg, n - 1, &v), -1);
    assert_int_equal(gw_bscan_parse(msg, n + 1, &v), -1);
    /* a buffer too small: no message */
    assert_int_equal(gw_bscan_build(msg, n - 1, &d, &h), 0);
}

static void spectrum_keeps_the_last_columns_oldest_first(void **state)
{
    (void)state;
    gw_spectrum_hist h;
    gw_spectrum_clear(&h);
    size_t n = 0;
    for (uint32_t no = 1; no <= 20u; no++) {
        const sc_dlink_done d = frame(no, 1);
        n = gw_bscan_build(msg, sizeof msg, &d, &h);
        assert_true(n > 0);
    }
    gw_bscan_view v;
    assert_int_equal(gw_bscan_parse(msg, n, &v), 0);
    assert_int_equal(v.columns, GW_BSCAN_COLUMNS);
    for (uint32_t i = 0; i < GW_BSCAN_COLUMNS; i++) {
        const uint8_t *c = v.spectrum + i * (4u + v.bins);
        const uint32_t no = (uint32_t)c[0] | ((uint32_t)c[1] << 8);
        assert_int_equal(no, 20u - GW_BSCAN_COLUMNS + 1u + i);
        assert_int_equal(c[4], no & 0xFFu);
    }
    /* another bin count starts the history afresh */
    sc_dlink_done d = frame(21, 1);
    d.doppler.bins = 16;
    n = gw_bscan_build(msg, sizeof msg, &d, &h);
    assert_int_equal(gw_bscan_parse(msg, n, &v), 0);
    assert_int_equal(v.columns, 1);
    assert_int_equal(v.bins, 16);
}

static void a_frame_without_colour_carries_none(void **state)
{
    (void)state;
    gw_spectrum_hist h;
    gw_spectrum_clear(&h);
    sc_dlink_done d = frame(5, 0);
    d.params_known = 0;
    size_t n = gw_bscan_build(msg, sizeof msg, &d, &h);
    assert_int_equal(n, GW_BSCAN_HDR + 6 * 20);
    assert_int_equal(msg[1], 0); /* exactly the message of a gateway without the extensions */
    gw_bscan_view v;
    assert_int_equal(gw_bscan_parse(msg, n, &v), 0);
    assert_null(v.colour);
    assert_null(v.doppler);
    /* a Doppler record whose box leaves the frame (a later geometry's): not sent */
    d = frame(6, 1);
    d.doppler.box_sample_hi = 21;
    n = gw_bscan_build(msg, sizeof msg, &d, &h);
    assert_int_equal(gw_bscan_parse(msg, n, &v), 0);
    assert_int_equal(v.flags, GW_BSCAN_HAS_PARAMS);
}

static void malformed_messages_are_refused(void **state)
{
    (void)state;
    gw_spectrum_hist h;
    gw_spectrum_clear(&h);
    const sc_dlink_done d = frame(9, 1);
    const size_t n = gw_bscan_build(msg, sizeof msg, &d, &h);
    gw_bscan_view v;
    uint8_t *bad = malloc(n);
    assert_non_null(bad);
    const struct {
        size_t at;
        uint8_t val;
    } edits[] = {
        {0, 'S'},                                              /* not a B-scan */
        {1, 0x0F},                                             /* unknown section */
        {1, GW_BSCAN_HAS_COLOUR | GW_BSCAN_HAS_PARAMS},        /* colour without its box */
        {8, 0},                                                /* no lines */
        {GW_BSCAN_HDR + 120 + GW_BSCAN_PARAMS + 2, 7},         /* box past the lines */
        {GW_BSCAN_HDR + 120 + GW_BSCAN_PARAMS + 28, 17},       /* more columns than kept */
    };
    for (size_t i = 0; i < sizeof edits / sizeof edits[0]; i++) {
        memcpy(bad, msg, n);
        bad[edits[i].at] = edits[i].val;
        assert_int_equal(gw_bscan_parse(bad, n, &v), -1);
    }
    free(bad);
    assert_int_equal(gw_bscan_parse(msg, 10, &v), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(image_params_and_colour_box_read_back),
        cmocka_unit_test(spectrum_keeps_the_last_columns_oldest_first),
        cmocka_unit_test(a_frame_without_colour_carries_none),
        cmocka_unit_test(malformed_messages_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
