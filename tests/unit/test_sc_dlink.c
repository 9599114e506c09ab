/* test_sc_dlink.c: display link codec (round trip, every corruption refused by name) and the
 * receiver-side frame assembler (lost, late, duplicate lines counted exactly). */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_crc32.h"
#include "sc_dlink.h"
#include "sc_err.h"

static const sc_dlink_frame k_frame = {
    .frame_no = 0x01020304u, .flags = 1u, .line_count = 128u, .samples = 200u, .geometry_id = 1u};

static void fill_line(uint8_t *s, uint16_t n, uint32_t seed)
{
    for (uint16_t i = 0; i < n; i++) {
        s[i] = (uint8_t)((seed * 31u + i * 7u) & 0xFFu);
    }
}

/* Recompute the CRC of a packet after a test modified it, so that a later check is reached. */
static void refresh_crc(uint8_t *pkt, size_t len)
{
    uint32_t c = sc_crc32_update(SC_CRC32_INIT, pkt, 24u);
    c = sc_crc32_final(sc_crc32_update(c, pkt + SC_DLINK_HEADER_SIZE, len - SC_DLINK_HEADER_SIZE));
    pkt[24] = (uint8_t)c;
    pkt[25] = (uint8_t)(c >> 8);
    pkt[26] = (uint8_t)(c >> 16);
    pkt[27] = (uint8_t)(c >> 24);
}

static void round_trip_preserves_every_field_of_all_three_packet_types(void **state)
{
    (void)state;
    uint8_t buf[SC_DLINK_MAX_PACKET];
    uint8_t samples[200];
    fill_line(samples, 200u, 9u);
    sc_dlink_header h;
    const uint8_t *pl;

    const sc_dlink_begin b = {
        .depth_mm = 47.5f, .width_mm = 60.25f, .radius_mm = 40.0f};
    int n = sc_dlink_encode_begin(buf, sizeof buf, &k_frame, &b);
    assert_int_equal(n, SC_DLINK_HEADER_SIZE + SC_DLINK_BEGIN_PAYLOAD);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), 0);
    assert_int_equal(h.type, SC_DLINK_FRAME_BEGIN);
    assert_int_equal(h.version, SC_DLINK_VERSION);
    assert_int_equal(h.frame_no, k_frame.frame_no);
    assert_int_equal(h.flags, k_frame.flags);
    assert_int_equal(h.line_count, k_frame.line_count);
    assert_int_equal(h.samples, k_frame.samples);
    assert_int_equal(h.geometry_id, k_frame.geometry_id);
    sc_dlink_begin b2;
    sc_dlink_parse_begin(pl, &b2);
    assert_memory_equal(&b2.depth_mm, &b.depth_mm, sizeof(float)); /* bit-exact */
    assert_memory_equal(&b2.width_mm, &b.width_mm, sizeof(float));
    assert_memory_equal(&b2.radius_mm, &b.radius_mm, sizeof(float));

    n = sc_dlink_encode_line(buf, sizeof buf, &k_frame, 127u, samples, 200u);
    assert_int_equal(n, SC_DLINK_HEADER_SIZE + 200);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), 0);
    assert_int_equal(h.type, SC_DLINK_LINE);
    assert_int_equal(h.line_index, 127u);
    assert_int_equal(h.payload_len, 200u);
    assert_memory_equal(pl, samples, 200u);

    const sc_dlink_end e = {.lines_sent = 120u, .lines_dropped = 8u, .compression_pm = 734u,
                            .artery_compression_pm = SC_DLINK_COMPRESSION_UNKNOWN};
    n = sc_dlink_encode_end(buf, sizeof buf, &k_frame, &e);
    assert_int_equal(n, SC_DLINK_HEADER_SIZE + SC_DLINK_END_PAYLOAD);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), 0);
    assert_int_equal(h.type, SC_DLINK_FRAME_END);
    sc_dlink_end e2;
    sc_dlink_parse_end(pl, &e2);
    assert_int_equal(e2.lines_sent, 120u);
    assert_int_equal(e2.lines_dropped, 8u);
    assert_int_equal(e2.compression_pm, 734u);
    assert_int_equal(e2.artery_compression_pm, SC_DLINK_COMPRESSION_UNKNOWN);
}

static void compression_measure_is_permille_of_the_area_lost(void **state)
{
    (void)state;
    assert_int_equal(sc_dlink_compression_pm(1.0f), 0u);
    assert_int_equal(sc_dlink_compression_pm(0.25f), 750u);
    assert_int_equal(sc_dlink_compression_pm(0.0f), 1000u);
    assert_int_equal(sc_dlink_compression_pm(1.4f), 0u); /* a vessel pushed into view */
    assert_int_equal(sc_dlink_compression_pm(-1.0f), SC_DLINK_COMPRESSION_UNKNOWN);
    assert_int_equal(sc_dlink_compression_pm(NAN), SC_DLINK_COMPRESSION_UNKNOWN);
}

static void wire_bytes_match_the_documented_layout(void **state)
{
    (void)state;
    uint8_t buf[SC_DLINK_MAX_PACKET];
    uint8_t s[4] = {10, 20, 30, 40};
    const sc_dlink_frame f = {.frame_no = 0xA1B2C3D4u,
                              .flags = 0x0201u,
                              .line_count = 9u,
                              .samples = 4u,
                              .geometry_id = 0u};
    int n = sc_dlink_encode_line(buf, sizeof buf, &f, 5u, s, 4u);
    assert_int_equal(n, 32);
    const uint8_t expect[24] = {'S', 'C', 'D', 'L', 2, 2, 0x01, 0x02, 0xD4, 0xC3, 0xB2, 0xA1,
                                5,   0,   9,   0,   4, 0, 0,    0,    4,    0,    0,    0};
    assert_memory_equal(buf, expect, 24u);
    assert_memory_equal(buf + 28, s, 4u);
    uint32_t crc = sc_crc32_final(sc_crc32_update(sc_crc32_update(SC_CRC32_INIT, buf, 24u), s, 4u));
    assert_int_equal((uint32_t)buf[24] | ((uint32_t)buf[25] << 8) | ((uint32_t)buf[26] << 16) |
                         ((uint32_t)buf[27] << 24),
                     crc);
}

/* Expected rejection of a single flipped bit at byte offset i of a line packet. */
static int expected_error_at(size_t i, unsigned bit)
{
    if (i < 4u) {
        return SC_ERR_DLINK_MAGIC;
    }
    if (i == 4u) {
        /* 2 -> 3 is a version this receiver knows (colour): then the CRC refuses it */
        return (2u ^ (1u << bit)) == SC_DLINK_VERSION_COLOUR ? SC_ERR_DLINK_CRC
                                                              : SC_ERR_DLINK_VERSION;
    }
    if (i == 20u || i == 21u) {
        return SC_ERR_DLINK_LENGTH; /* payload_len no longer matches the datagram */
    }
    return SC_ERR_DLINK_CRC;
}

static void every_single_bit_flip_is_rejected_with_its_named_error(void **state)
{
    (void)state;
    uint8_t good[SC_DLINK_MAX_PACKET];
    uint8_t pkt[SC_DLINK_MAX_PACKET];
    uint8_t samples[200];
    fill_line(samples, 200u, 3u);
    int n = sc_dlink_encode_line(good, sizeof good, &k_frame, 17u, samples, 200u);
    assert_true(n > 0);
    sc_dlink_header h;
    const uint8_t *pl;
    for (size_t i = 0; i < (size_t)n; i++) {
        for (unsigned bit = 0; bit < 8u; bit++) {
            memcpy(pkt, good, (size_t)n);
            pkt[i] = (uint8_t)(pkt[i] ^ (1u << bit));
            int rc = sc_dlink_decode(pkt, (size_t)n, &h, &pl);
            if (rc != expected_error_at(i, bit)) {
                print_error("byte %zu bit %u: got %s\n", i, bit, sc_err_name(rc));
            }
            assert_int_equal(rc, expected_error_at(i, bit));
        }
    }
}

static void truncated_and_extended_datagrams_are_length_errors(void **state)
{
    (void)state;
    uint8_t pkt[SC_DLINK_MAX_PACKET + 8];
    uint8_t samples[200];
    fill_line(samples, 200u, 4u);
    int n = sc_dlink_encode_line(pkt, sizeof pkt, &k_frame, 0u, samples, 200u);
    sc_dlink_header h;
    const uint8_t *pl;
    for (size_t len = 0; len < (size_t)n; len++) {
        int rc = sc_dlink_decode(pkt, len, &h, &pl);
        assert_int_equal(rc, SC_ERR_DLINK_LENGTH);
    }
    assert_int_equal(sc_dlink_decode(pkt, (size_t)n + 1u, &h, &pl), SC_ERR_DLINK_LENGTH);
    assert_int_equal(sc_dlink_decode(pkt, (size_t)n, &h, &pl), 0);
}

static void valid_crc_with_bad_type_or_fields_is_still_rejected(void **state)
{
    (void)state;
    uint8_t good[SC_DLINK_MAX_PACKET];
    uint8_t pkt[SC_DLINK_MAX_PACKET];
    uint8_t samples[200];
    fill_line(samples, 200u, 5u);
    int n = sc_dlink_encode_line(good, sizeof good, &k_frame, 3u, samples, 200u);
    size_t len = (size_t)n;
    sc_dlink_header h;
    const uint8_t *pl;
    struct {
        size_t off;
        uint8_t value;
        int err;
    } cases[] = {
        {5u, 0u, SC_ERR_DLINK_TYPE},
        {5u, 4u, SC_ERR_DLINK_TYPE},
        {5u, 0xFFu, SC_ERR_DLINK_TYPE},
        {5u, 1u, SC_ERR_DLINK_LENGTH},    /* a line's payload is not a FRAME_BEGIN payload */
        {12u, 128u, SC_ERR_DLINK_FIELD},  /* line index == line count */
        {13u, 1u, SC_ERR_DLINK_FIELD},    /* line index 259 */
        {14u, 0u, SC_ERR_DLINK_FIELD},    /* line count 0 (index 3 too) */
        {15u, 0x7Fu, SC_ERR_DLINK_FIELD}, /* line count above the limit */
        {18u, 2u, SC_ERR_DLINK_FIELD},    /* geometry 2 */
        {22u, 1u, SC_ERR_DLINK_FIELD},    /* reserved not zero */
        {23u, 0x80u, SC_ERR_DLINK_FIELD},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        memcpy(pkt, good, len);
        pkt[cases[c].off] = cases[c].value;
        refresh_crc(pkt, len);
        assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), cases[c].err);
    }
    /* samples above the limit: payload length and sample count agree, the range check fails */
    uint8_t big[SC_DLINK_HEADER_SIZE + SC_MAX_SCAN_SAMPLES + 1u];
    memset(big, 0x55, sizeof big);
    memcpy(big, good, SC_DLINK_HEADER_SIZE);
    const uint16_t too_many = (uint16_t)(SC_MAX_SCAN_SAMPLES + 1u);
    big[16] = (uint8_t)too_many;
    big[17] = (uint8_t)(too_many >> 8);
    big[20] = (uint8_t)too_many;
    big[21] = (uint8_t)(too_many >> 8);
    refresh_crc(big, sizeof big);
    assert_int_equal(sc_dlink_decode(big, sizeof big, &h, &pl), SC_ERR_DLINK_FIELD);
}

static void begin_and_end_payload_fields_are_range_checked(void **state)
{
    (void)state;
    uint8_t pkt[SC_DLINK_MAX_PACKET];
    sc_dlink_header h;
    const uint8_t *pl;
    const sc_dlink_begin b = {
        .depth_mm = 40.0f, .width_mm = 38.0f, .radius_mm = 0.0f};
    int n = sc_dlink_encode_begin(pkt, sizeof pkt, &k_frame, &b);
    size_t len = (size_t)n;
    /* depth = NaN (0x7FC00000) */
    pkt[28] = 0x00;
    pkt[29] = 0x00;
    pkt[30] = 0xC0;
    pkt[31] = 0x7F;
    refresh_crc(pkt, len);
    assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), SC_ERR_DLINK_FIELD);
    /* radius -1.0f (0xBF800000) */
    n = sc_dlink_encode_begin(pkt, sizeof pkt, &k_frame, &b);
    pkt[36] = 0x00;
    pkt[37] = 0x00;
    pkt[38] = 0x80;
    pkt[39] = 0xBF;
    refresh_crc(pkt, len);
    assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), SC_ERR_DLINK_FIELD);
    /* compression 1001 */
    n = sc_dlink_encode_begin(pkt, sizeof pkt, &k_frame, &b);
    pkt[40] = 0xE9;
    pkt[41] = 0x03;
    refresh_crc(pkt, len);
    assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), SC_ERR_DLINK_FIELD);
    /* a FRAME_BEGIN with a line index */
    n = sc_dlink_encode_begin(pkt, sizeof pkt, &k_frame, &b);
    pkt[12] = 1u;
    refresh_crc(pkt, len);
    assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), SC_ERR_DLINK_FIELD);

    const sc_dlink_end e = {.lines_sent = 128u, .lines_dropped = 0u};
    n = sc_dlink_encode_end(pkt, sizeof pkt, &k_frame, &e);
    len = (size_t)n;
    assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), 0);
    pkt[30] = 1u; /* dropped 1: sent + dropped above the line count */
    refresh_crc(pkt, len);
    assert_int_equal(sc_dlink_decode(pkt, len, &h, &pl), SC_ERR_DLINK_FIELD);
    (void)n;
}

static void encoders_refuse_out_of_range_fields_and_small_buffers(void **state)
{
    (void)state;
    uint8_t buf[SC_DLINK_MAX_PACKET];
    uint8_t s[SC_MAX_SCAN_SAMPLES] = {0};
    sc_dlink_frame f = k_frame;
    assert_int_equal(sc_dlink_encode_line(buf, sizeof buf, &f, 128u, s, 200u), SC_ERR_DLINK_FIELD);
    assert_int_equal(sc_dlink_encode_line(buf, sizeof buf, &f, 0u, s, 199u), SC_ERR_DLINK_FIELD);
    assert_int_equal(sc_dlink_encode_line(buf, 200u, &f, 0u, s, 200u), SC_ERR_NO_SPACE);
    assert_int_equal(sc_dlink_encode_line(NULL, 1000u, &f, 0u, s, 200u), SC_ERR_INVALID_ARG);
    f.geometry_id = 2u;
    assert_int_equal(sc_dlink_encode_line(buf, sizeof buf, &f, 0u, s, 200u), SC_ERR_DLINK_FIELD);
    f = k_frame;
    f.line_count = 0u;
    assert_int_equal(sc_dlink_encode_line(buf, sizeof buf, &f, 0u, s, 200u), SC_ERR_DLINK_FIELD);
    f = k_frame;
    f.line_count = (uint16_t)(SC_MAX_SCAN_LINES + 1u);
    const sc_dlink_begin ok_b = {40.0f, 38.0f, 0.0f};
    assert_int_equal(sc_dlink_encode_begin(buf, sizeof buf, &f, &ok_b), SC_ERR_DLINK_FIELD);
    f = k_frame;
    sc_dlink_begin bad_b = {INFINITY, 38.0f, 0.0f};
    assert_int_equal(sc_dlink_encode_begin(buf, sizeof buf, &f, &bad_b), SC_ERR_NOT_FINITE);
    bad_b.depth_mm = 40.0f;
    bad_b.radius_mm = -1.0f;
    assert_int_equal(sc_dlink_encode_begin(buf, sizeof buf, &f, &bad_b), SC_ERR_DLINK_FIELD);
    assert_int_equal(sc_dlink_encode_begin(buf, 43u, &f, &ok_b), SC_ERR_NO_SPACE);
    const sc_dlink_end bad_e = {100u, 29u, 0u, 0u};
    assert_int_equal(sc_dlink_encode_end(buf, sizeof buf, &f, &bad_e), SC_ERR_DLINK_FIELD);
    const sc_dlink_end bad_c = {100u, 0u, 1001u, 0u};
    assert_int_equal(sc_dlink_encode_end(buf, sizeof buf, &f, &bad_c), SC_ERR_DLINK_FIELD);
    const sc_dlink_end bad_a = {100u, 0u, 0u, 1001u};
    assert_int_equal(sc_dlink_encode_end(buf, sizeof buf, &f, &bad_a), SC_ERR_DLINK_FIELD);
}

/* ---- assembler -------------------------------------------------------------------------- */

static sc_dlink_asm g_asm; /* 512 KiB: static storage, as on the target */

typedef struct sender {
    sc_dlink_frame f;
    uint8_t buf[SC_DLINK_MAX_PACKET];
} sender;

static int push_begin(sender *s)
{
    const sc_dlink_begin b = {40.0f, 38.0f, 0.0f};
    int n = sc_dlink_encode_begin(s->buf, sizeof s->buf, &s->f, &b);
    assert_true(n > 0);
    return sc_dlink_asm_push(&g_asm, s->buf, (size_t)n);
}

static int push_line(sender *s, uint16_t i)
{
    uint8_t smp[SC_MAX_SCAN_SAMPLES];
    fill_line(smp, s->f.samples, s->f.frame_no * 1000u + i);
    int n = sc_dlink_encode_line(s->buf, sizeof s->buf, &s->f, i, smp, s->f.samples);
    assert_true(n > 0);
    return sc_dlink_asm_push(&g_asm, s->buf, (size_t)n);
}

static int push_end(sender *s, uint16_t sent)
{
    const sc_dlink_end e = {sent, 0u, 500u, 0u};
    int n = sc_dlink_encode_end(s->buf, sizeof s->buf, &s->f, &e);
    assert_true(n > 0);
    return sc_dlink_asm_push(&g_asm, s->buf, (size_t)n);
}

static int row_is(const uint8_t *img, uint16_t row, uint16_t samples, uint32_t seed)
{
    uint8_t smp[SC_MAX_SCAN_SAMPLES];
    fill_line(smp, samples, seed);
    return memcmp(img + (size_t)row * SC_MAX_SCAN_SAMPLES, smp, samples) == 0;
}

static void complete_frames_assemble_without_loss(void **state)
{
    (void)state;
    sc_dlink_asm_init(&g_asm);
    assert_null(sc_dlink_asm_done(&g_asm));
    sender s = {.f = {.frame_no = 1u, .flags = 1u, .line_count = 64u, .samples = 100u}};
    for (uint32_t fr = 1; fr <= 3u; fr++) {
        s.f.frame_no = fr;
        assert_int_equal(push_begin(&s), 0);
        for (uint16_t i = 0; i < 64u; i++) {
            /* out of order: odd lines first, then even */
            uint16_t li = (uint16_t)(i < 32u ? 2u * i + 1u : 2u * (i - 32u));
            assert_int_equal(push_line(&s, li), 0);
        }
        assert_int_equal(push_end(&s, 64u), 1);
        const sc_dlink_done *d = sc_dlink_asm_done(&g_asm);
        assert_non_null(d);
        assert_int_equal(d->frame.frame_no, fr);
        assert_int_equal(d->lines_received, 64u);
        assert_int_equal(d->lines_lost, 0u);
        assert_true(d->begin_seen && d->end_seen);
        assert_int_equal(d->end.compression_pm, 500u);
        assert_int_equal(d->end.artery_compression_pm, 0u);
        for (uint16_t i = 0; i < 64u; i++) {
            assert_true(row_is(d->image, i, 100u, fr * 1000u + i));
        }
    }
    assert_int_equal(g_asm.stats.frames_complete, 3u);
    assert_int_equal(g_asm.stats.lines_received, 192u);
    assert_int_equal(g_asm.stats.lines_lost + g_asm.stats.lines_late + g_asm.stats.rejected, 0u);
}

/* FRAME_PARAMS (the display's imaging parameters, an additive extension): round trip, the
 * assembler keeps them for the frame and the frames after, values out of range refused. */
static void frame_params_round_trip_reach_the_closed_frame_and_are_range_checked(void **state)
{
    (void)state;
    sc_dlink_asm_init(&g_asm);
    sender s = {.f = {.frame_no = 1u, .flags = 1u, .line_count = 4u, .samples = 16u}};
    sc_dlink_params p = {.gain_db = 6.0f, .dynamic_range_db = 60.0f, .focus_mm = 20.0f,
                         .frequency_mhz = 7.5f};
    for (uint32_t i = 0; i < SC_DLINK_PARAMS_TGC; i++) {
        p.tgc_db[i] = 1.5f * (float)i;
    }
    assert_int_equal(push_begin(&s), 0);
    int n = sc_dlink_encode_params(s.buf, sizeof s.buf, &s.f, &p);
    assert_int_equal(n, (int)(SC_DLINK_HEADER_SIZE + SC_DLINK_PARAMS_PAYLOAD));
    sc_dlink_header h;
    const uint8_t *pl = NULL;
    assert_int_equal(sc_dlink_decode(s.buf, (size_t)n, &h, &pl), 0);
    assert_int_equal(h.type, SC_DLINK_FRAME_PARAMS);
    sc_dlink_params q;
    sc_dlink_parse_params(pl, &q);
    assert_memory_equal(&p, &q, sizeof p);
    assert_int_equal(sc_dlink_asm_push(&g_asm, s.buf, (size_t)n), 0);
    for (uint16_t i = 0; i < 4u; i++) {
        assert_int_equal(push_line(&s, i), 0);
    }
    assert_int_equal(push_end(&s, 4u), 1);
    const sc_dlink_done *d = sc_dlink_asm_done(&g_asm);
    assert_true(d->params_known);
    assert_memory_equal(&d->params, &p, sizeof p);
    /* the next frame without FRAME_PARAMS keeps the last ones */
    s.f.frame_no = 2u;
    assert_int_equal(push_begin(&s), 0);
    assert_int_equal(push_end(&s, 0u), 1);
    assert_true(sc_dlink_asm_done(&g_asm)->params_known);
    assert_true(fabsf(sc_dlink_asm_done(&g_asm)->params.focus_mm - 20.0f) < 1e-6f);
    /* ranges */
    sc_dlink_params bad = p;
    bad.dynamic_range_db = 130.0f;
    assert_int_equal(sc_dlink_encode_params(s.buf, sizeof s.buf, &s.f, &bad), SC_ERR_DLINK_FIELD);
    bad = p;
    bad.tgc_db[7] = NAN;
    assert_int_equal(sc_dlink_encode_params(s.buf, sizeof s.buf, &s.f, &bad), SC_ERR_NOT_FINITE);
    /* a NaN written on the wire with a valid CRC: refused by the decoder */
    n = sc_dlink_encode_params(s.buf, sizeof s.buf, &s.f, &p);
    const float nan_v = NAN;
    memcpy(s.buf + SC_DLINK_HEADER_SIZE + 8u, &nan_v, sizeof nan_v);
    refresh_crc(s.buf, (size_t)n);
    assert_int_equal(sc_dlink_decode(s.buf, (size_t)n, &h, &pl), SC_ERR_DLINK_FIELD);
}

static void dropped_lines_are_counted_exactly_and_show_the_previous_row(void **state)
{
    (void)state;
    sc_dlink_asm_init(&g_asm);
    sender s = {.f = {.frame_no = 10u, .line_count = 50u, .samples = 64u}};
    push_begin(&s);
    for (uint16_t i = 0; i < 50u; i++) {
        push_line(&s, i);
    }
    push_end(&s, 50u);
    s.f.frame_no = 11u;
    push_begin(&s);
    uint32_t dropped = 0;
    for (uint16_t i = 0; i < 50u; i++) {
        if (i % 7u == 3u) {
            dropped++;
            continue;
        }
        push_line(&s, i);
    }
    assert_int_equal(push_end(&s, 50u), 1);
    const sc_dlink_done *d = sc_dlink_asm_done(&g_asm);
    assert_int_equal(d->lines_lost, dropped);
    assert_int_equal(g_asm.stats.lines_lost, dropped);
    assert_int_equal(g_asm.stats.frames_incomplete, 1u);
    for (uint16_t i = 0; i < 50u; i++) {
        uint32_t from = (i % 7u == 3u) ? 10u : 11u;
        assert_true(row_is(d->image, i, 64u, from * 1000u + i));
    }
}

static void late_duplicate_and_missing_markers_are_counted(void **state)
{
    (void)state;
    sc_dlink_asm_init(&g_asm);
    sender s = {.f = {.frame_no = 5u, .line_count = 8u, .samples = 16u}};
    push_begin(&s);
    for (uint16_t i = 0; i < 8u; i++) {
        push_line(&s, i);
    }
    assert_int_equal(push_line(&s, 2u), 0); /* duplicate */
    assert_int_equal(g_asm.stats.lines_duplicate, 1u);
    /* frame 5's END lost: frame 6's first line closes frame 5, begin of 6 missing */
    s.f.frame_no = 6u;
    assert_int_equal(push_line(&s, 0u), 1);
    assert_int_equal(sc_dlink_asm_done(&g_asm)->frame.frame_no, 5u);
    assert_int_equal(g_asm.stats.ends_missing, 1u);
    assert_int_equal(g_asm.stats.begins_missing, 1u);
    /* a late line of frame 5 */
    s.f.frame_no = 5u;
    assert_int_equal(push_line(&s, 7u), 0);
    assert_int_equal(g_asm.stats.lines_late, 1u);
    s.f.frame_no = 6u;
    for (uint16_t i = 1; i < 8u; i++) {
        push_line(&s, i);
    }
    assert_int_equal(push_end(&s, 8u), 1);
    assert_int_equal(sc_dlink_asm_done(&g_asm)->lines_lost, 0u);
    /* late line for closed frame 6 and a late FRAME_END of frame 6 */
    assert_int_equal(push_line(&s, 3u), 0);
    assert_int_equal(push_end(&s, 8u), 0);
    assert_int_equal(g_asm.stats.lines_late, 2u);
    assert_int_equal(g_asm.stats.frames_late, 1u);
    /* the last frame of a stream without END is closed by flush */
    s.f.frame_no = 7u;
    push_begin(&s);
    push_line(&s, 0u);
    assert_int_equal(sc_dlink_asm_flush(&g_asm), 1);
    assert_int_equal(sc_dlink_asm_done(&g_asm)->lines_lost, 7u);
    assert_int_equal(sc_dlink_asm_flush(&g_asm), 0);
    assert_int_equal(g_asm.stats.lines_lost, 7u);
}

static void frame_numbers_wrap_and_a_restarted_sender_resynchronises(void **state)
{
    (void)state;
    sc_dlink_asm_init(&g_asm);
    sender s = {.f = {.frame_no = 0xFFFFFFFFu, .line_count = 4u, .samples = 8u}};
    push_begin(&s);
    for (uint16_t i = 0; i < 4u; i++) {
        push_line(&s, i);
    }
    push_end(&s, 4u);
    s.f.frame_no = 0u; /* wrapped: newer than 0xFFFFFFFF */
    assert_int_equal(push_begin(&s), 0);
    assert_int_equal(g_asm.stats.frames_late, 0u);
    for (uint16_t i = 0; i < 4u; i++) {
        push_line(&s, i);
    }
    assert_int_equal(push_end(&s, 4u), 1);
    assert_int_equal(sc_dlink_asm_done(&g_asm)->frame.frame_no, 0u);
    s.f.frame_no = 1000000u;
    push_begin(&s);
    push_end(&s, 0u);
    /* the sender restarts at frame 1: far older than the last frame, so a restart */
    s.f.frame_no = 1u;
    assert_int_equal(push_begin(&s), 0);
    assert_int_equal(g_asm.stats.frames_late, 0u);
    push_line(&s, 0u);
    assert_int_equal(g_asm.stats.lines_late, 0u);
    assert_int_equal(g_asm.stats.lines_received, 9u);
}

static void rejected_packets_are_counted_by_reason_and_change_nothing(void **state)
{
    (void)state;
    sc_dlink_asm_init(&g_asm);
    sender s = {.f = {.frame_no = 2u, .line_count = 4u, .samples = 8u}};
    push_begin(&s);
    uint8_t smp[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    int n = sc_dlink_encode_line(s.buf, sizeof s.buf, &s.f, 1u, smp, 8u);
    s.buf[30] ^= 0x10u;
    assert_int_equal(sc_dlink_asm_push(&g_asm, s.buf, (size_t)n), SC_ERR_DLINK_CRC);
    s.buf[0] = 'X';
    assert_int_equal(sc_dlink_asm_push(&g_asm, s.buf, (size_t)n), SC_ERR_DLINK_MAGIC);
    assert_int_equal(sc_dlink_asm_push(&g_asm, s.buf, 3u), SC_ERR_DLINK_LENGTH);
    /* same frame number, different geometry: inconsistent, refused */
    sc_dlink_frame other = s.f;
    other.samples = 9u;
    uint8_t smp9[9] = {0};
    n = sc_dlink_encode_line(s.buf, sizeof s.buf, &other, 1u, smp9, 9u);
    assert_int_equal(sc_dlink_asm_push(&g_asm, s.buf, (size_t)n), SC_ERR_DLINK_FIELD);
    assert_int_equal(g_asm.stats.rejected, 4u);
    assert_int_equal(g_asm.stats.rej_crc, 1u);
    assert_int_equal(g_asm.stats.rej_magic, 1u);
    assert_int_equal(g_asm.stats.rej_length, 1u);
    assert_int_equal(g_asm.stats.rej_field, 1u);
    assert_int_equal(g_asm.stats.packets, 5u);
    assert_int_equal(g_asm.stats.lines_received, 0u);
    assert_int_equal(push_end(&s, 4u), 1);
    assert_int_equal(sc_dlink_asm_done(&g_asm)->lines_lost, 4u);
}

/* ---- version 3: colour Doppler ---------------------------------------------------------- */

static sc_dlink_doppler sample_doppler(void)
{
    sc_dlink_doppler d;
    memset(&d, 0, sizeof d);
    d.box_line_lo = 10u;
    d.box_line_hi = 100u;
    d.box_sample_lo = 5u;
    d.box_sample_hi = 150u;
    d.nyquist_mm_s = 308.0f;
    d.steer_deg = -20.0f;
    d.gate_velocity_mm_s = 273.5f;
    d.gate_line = 64u;
    d.gate_sample_lo = 70u;
    d.gate_sample_hi = 80u;
    d.bins = 128u;
    for (uint32_t i = 0; i < 128u; i++) {
        d.spectrum[i] = (uint8_t)(i * 2u);
    }
    return d;
}

static void colour_packets_round_trip_as_version_3(void **state)
{
    (void)state;
    uint8_t buf[SC_DLINK_MAX_PACKET];
    int8_t vals[145];
    for (uint32_t i = 0; i < 145u; i++) {
        vals[i] = (int8_t)((int32_t)i - 72);
    }
    sc_dlink_header h;
    const uint8_t *pl;
    int n = sc_dlink_encode_colour(buf, sizeof buf, &k_frame, 42u, 5u, vals, 145u);
    assert_int_equal(n, SC_DLINK_HEADER_SIZE + SC_DLINK_COLOUR_HEAD + 145);
    assert_int_equal(buf[4], SC_DLINK_VERSION_COLOUR);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), 0);
    assert_int_equal(h.type, SC_DLINK_COLOUR_LINE);
    assert_int_equal(h.version, SC_DLINK_VERSION_COLOUR);
    assert_int_equal(h.line_index, 42u);
    assert_memory_equal(pl + SC_DLINK_COLOUR_HEAD, vals, 145u);
    /* out of the line: refused at the encoder */
    assert_int_equal(sc_dlink_encode_colour(buf, sizeof buf, &k_frame, 42u, 100u, vals, 145u),
                     SC_ERR_DLINK_FIELD);
    assert_int_equal(sc_dlink_encode_colour(buf, sizeof buf, &k_frame, 128u, 0u, vals, 1u),
                     SC_ERR_DLINK_FIELD);

    const sc_dlink_doppler d = sample_doppler();
    n = sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &d);
    assert_int_equal(n, SC_DLINK_HEADER_SIZE + SC_DLINK_DOPPLER_HEAD + 128);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), 0);
    assert_int_equal(h.type, SC_DLINK_DOPPLER);
    sc_dlink_doppler d2;
    sc_dlink_parse_doppler(pl, &d2);
    assert_memory_equal(&d2, &d, sizeof d);
    sc_dlink_doppler bad = d;
    bad.nyquist_mm_s = NAN;
    assert_int_equal(sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &bad), SC_ERR_NOT_FINITE);
    bad = d;
    bad.box_line_hi = 129u;
    assert_int_equal(sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &bad), SC_ERR_DLINK_FIELD);
    bad = d;
    bad.gate_sample_hi = bad.gate_sample_lo;
    assert_int_equal(sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &bad), SC_ERR_DLINK_FIELD);
}

static void a_version_2_receiver_refuses_colour_packets_by_name_and_keeps_the_b_scan(void **state)
{
    (void)state;
    static sc_dlink_asm a;
    sc_dlink_asm_init(&a);
    a.max_version = (uint8_t)SC_DLINK_VERSION; /* an old receiver */
    uint8_t buf[SC_DLINK_MAX_PACKET];
    uint8_t samples[200];
    int8_t vals[10] = {1, -2, 3, -4, 5, -6, 7, -8, 9, -10};
    sc_dlink_header h;
    const uint8_t *pl;
    const sc_dlink_begin b = {.depth_mm = 40.0f, .width_mm = 60.0f, .radius_mm = 40.0f};
    int n = sc_dlink_encode_begin(buf, sizeof buf, &k_frame, &b);
    assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 0);
    for (uint16_t l = 0; l < k_frame.line_count; l++) {
        fill_line(samples, 200u, l);
        n = sc_dlink_encode_line(buf, sizeof buf, &k_frame, l, samples, 200u);
        assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 0);
        n = sc_dlink_encode_colour(buf, sizeof buf, &k_frame, l, 20u, vals, 10u);
        assert_int_equal(sc_dlink_decode_as(buf, (size_t)n, 2u, &h, &pl), SC_ERR_DLINK_VERSION);
        assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), SC_ERR_DLINK_VERSION);
    }
    const sc_dlink_doppler d = sample_doppler();
    n = sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &d);
    assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), SC_ERR_DLINK_VERSION);
    assert_string_equal(sc_err_str(SC_ERR_DLINK_VERSION), "display link version unsupported");
    const sc_dlink_end e = {128u, 0u, 500u, 20u};
    n = sc_dlink_encode_end(buf, sizeof buf, &k_frame, &e);
    assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 1);
    const sc_dlink_done *done = sc_dlink_asm_done(&a);
    assert_non_null(done);
    assert_int_equal(done->lines_lost, 0u); /* the B-scan is whole */
    assert_null(done->colour);
    assert_int_equal(done->doppler_seen, 0u);
    assert_int_equal(a.stats.rej_version, 129u);
    assert_int_equal(a.stats.rejected, 129u);
    assert_int_equal(a.stats.colour_lines, 0u);
}

static void a_version_3_receiver_assembles_colour_with_its_frame(void **state)
{
    (void)state;
    static sc_dlink_asm a;
    sc_dlink_asm_init(&a);
    uint8_t buf[SC_DLINK_MAX_PACKET];
    uint8_t samples[200];
    int8_t vals[10] = {1, -2, 3, -4, 5, -6, 7, -8, 9, -10};
    for (uint32_t fr = 0; fr < 2u; fr++) {
        sc_dlink_frame f = k_frame;
        f.frame_no += fr;
        const sc_dlink_begin b = {.depth_mm = 40.0f, .width_mm = 60.0f, .radius_mm = 40.0f};
        int n = sc_dlink_encode_begin(buf, sizeof buf, &f, &b);
        assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 0);
        for (uint16_t l = 0; l < f.line_count; l++) {
            fill_line(samples, 200u, l);
            n = sc_dlink_encode_line(buf, sizeof buf, &f, l, samples, 200u);
            assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 0);
            if (fr == 0u && l == 7u) { /* colour in the first frame only */
                n = sc_dlink_encode_colour(buf, sizeof buf, &f, l, 20u, vals, 10u);
                assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 0);
            }
        }
        if (fr == 0u) {
            const sc_dlink_doppler d = sample_doppler();
            n = sc_dlink_encode_doppler(buf, sizeof buf, &f, &d);
            assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 0);
        }
        const sc_dlink_end e = {128u, 0u, 500u, 20u};
        n = sc_dlink_encode_end(buf, sizeof buf, &f, &e);
        assert_int_equal(sc_dlink_asm_push(&a, buf, (size_t)n), 1);
        const sc_dlink_done *done = sc_dlink_asm_done(&a);
        if (fr == 0u) {
            assert_non_null(done->colour);
            assert_memory_equal(done->colour + 7u * SC_MAX_SCAN_SAMPLES + 20u, vals, 10u);
            assert_int_equal(done->colour[7u * SC_MAX_SCAN_SAMPLES + 19u], 0);
            assert_int_equal(done->doppler_seen, 1u);
            assert_int_equal(done->doppler.spectrum[10], 20u);
        } else {
            assert_null(done->colour); /* colour does not linger into a frame without it */
            assert_int_equal(done->doppler_seen, 0u);
        }
    }
    assert_int_equal(a.stats.rejected, 0u);
    assert_int_equal(a.stats.colour_lines, 1u);
    assert_int_equal(a.stats.doppler_records, 1u);
}

static void corrupt_colour_packets_are_refused_by_reason(void **state)
{
    (void)state;
    uint8_t buf[SC_DLINK_MAX_PACKET];
    int8_t vals[10] = {0};
    sc_dlink_header h;
    const uint8_t *pl;
    int n = sc_dlink_encode_colour(buf, sizeof buf, &k_frame, 3u, 20u, vals, 10u);
    /* a colour type under version 2 does not exist */
    buf[4] = (uint8_t)SC_DLINK_VERSION;
    refresh_crc(buf, (size_t)n);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), SC_ERR_DLINK_TYPE);
    /* count beyond the payload */
    n = sc_dlink_encode_colour(buf, sizeof buf, &k_frame, 3u, 20u, vals, 10u);
    buf[SC_DLINK_HEADER_SIZE + 2] = 11u;
    refresh_crc(buf, (size_t)n);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), SC_ERR_DLINK_LENGTH);
    /* first + count past the line */
    n = sc_dlink_encode_colour(buf, sizeof buf, &k_frame, 3u, 20u, vals, 10u);
    buf[SC_DLINK_HEADER_SIZE + 0] = 195u;
    refresh_crc(buf, (size_t)n);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), SC_ERR_DLINK_FIELD);
    /* a doppler record with a negative scale */
    sc_dlink_doppler d = sample_doppler();
    n = sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &d);
    const float neg = -1.0f;
    memcpy(buf + SC_DLINK_HEADER_SIZE + 8, &neg, 4u);
    refresh_crc(buf, (size_t)n);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), SC_ERR_DLINK_FIELD);
    /* more bins than the limit */
    n = sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &d);
    buf[SC_DLINK_HEADER_SIZE + 26] = 129u;
    refresh_crc(buf, (size_t)n);
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), SC_ERR_DLINK_LENGTH);
    /* any flipped byte: the CRC */
    n = sc_dlink_encode_doppler(buf, sizeof buf, &k_frame, &d);
    buf[SC_DLINK_HEADER_SIZE + 40] ^= 0x10u;
    assert_int_equal(sc_dlink_decode(buf, (size_t)n, &h, &pl), SC_ERR_DLINK_CRC);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(round_trip_preserves_every_field_of_all_three_packet_types),
        cmocka_unit_test(wire_bytes_match_the_documented_layout),
        cmocka_unit_test(compression_measure_is_permille_of_the_area_lost),
        cmocka_unit_test(every_single_bit_flip_is_rejected_with_its_named_error),
        cmocka_unit_test(truncated_and_extended_datagrams_are_length_errors),
        cmocka_unit_test(valid_crc_with_bad_type_or_fields_is_still_rejected),
        cmocka_unit_test(begin_and_end_payload_fields_are_range_checked),
        cmocka_unit_test(encoders_refuse_out_of_range_fields_and_small_buffers),
        cmocka_unit_test(complete_frames_assemble_without_loss),
        cmocka_unit_test(frame_params_round_trip_reach_the_closed_frame_and_are_range_checked),
        cmocka_unit_test(dropped_lines_are_counted_exactly_and_show_the_previous_row),
        cmocka_unit_test(late_duplicate_and_missing_markers_are_counted),
        cmocka_unit_test(frame_numbers_wrap_and_a_restarted_sender_resynchronises),
        cmocka_unit_test(rejected_packets_are_counted_by_reason_and_change_nothing),
        cmocka_unit_test(colour_packets_round_trip_as_version_3),
        cmocka_unit_test(a_version_2_receiver_refuses_colour_packets_by_name_and_keeps_the_b_scan),
        cmocka_unit_test(a_version_3_receiver_assembles_colour_with_its_frame),
        cmocka_unit_test(corrupt_colour_packets_are_refused_by_reason),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
