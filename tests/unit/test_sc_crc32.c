/* test_sc_crc32.c: CRC-32 (IEEE reflected) against published check values and a bitwise
 * reference implementation. */
#include "sc_test.h"

#include <string.h>

#include "sc_crc32.h"

/* Bit-at-a-time reference, independent of the table. */
static uint32_t crc32_bitwise(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int b = 0; b < 8; b++) {
            c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
        }
    }
    return ~c;
}

static void check_value_of_123456789_is_cbf43926(void **state)
{
    (void)state;
    assert_int_equal(sc_crc32("123456789", 9), 0xCBF43926u);
}

static void empty_input_gives_zero(void **state)
{
    (void)state;
    assert_int_equal(sc_crc32(NULL, 0), 0u);
}

static void known_vectors_match_zlib(void **state)
{
    (void)state;
    /* values from zlib crc32() */
    const char *fox = "The quick brown fox jumps over the lazy dog";
    assert_int_equal(sc_crc32(fox, strlen(fox)), 0x414FA339u);
    const uint8_t zero32[32] = {0};
    assert_int_equal(sc_crc32(zero32, sizeof zero32), 0x190A55ADu);
}

static void table_matches_bitwise_reference_on_every_byte_and_lengths(void **state)
{
    (void)state;
    uint8_t buf[1031];
    uint32_t x = 12345u;
    for (size_t i = 0; i < sizeof buf; i++) {
        x = x * 1103515245u + 12345u;
        buf[i] = (uint8_t)(x >> 16);
    }
    for (unsigned v = 0; v < 256u; v++) {
        uint8_t b = (uint8_t)v;
        assert_int_equal(sc_crc32(&b, 1), crc32_bitwise(&b, 1));
    }
    for (size_t n = 0; n <= sizeof buf; n += 37u) {
        assert_int_equal(sc_crc32(buf, n), crc32_bitwise(buf, n));
    }
    /* every length and start offset around the 8-byte step: tails and misaligned starts */
    for (size_t off = 0; off < 8u; off++) {
        for (size_t n = 0; n <= 40u; n++) {
            assert_int_equal(sc_crc32(buf + off, n), crc32_bitwise(buf + off, n));
        }
    }
}

static void incremental_equals_one_shot(void **state)
{
    (void)state;
    const char *s = "sonocomp case file section payload";
    size_t n = strlen(s);
    for (size_t cut = 0; cut <= n; cut++) {
        uint32_t c = SC_CRC32_INIT;
        c = sc_crc32_update(c, s, cut);
        c = sc_crc32_update(c, s + cut, n - cut);
        assert_int_equal(sc_crc32_final(c), sc_crc32(s, n));
    }
}

static void single_bit_flip_changes_crc(void **state)
{
    (void)state;
    uint8_t buf[64];
    for (size_t i = 0; i < sizeof buf; i++) {
        buf[i] = (uint8_t)i;
    }
    uint32_t ref = sc_crc32(buf, sizeof buf);
    for (size_t bit = 0; bit < sizeof buf * 8u; bit++) {
        buf[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        assert_int_not_equal(sc_crc32(buf, sizeof buf), ref);
        buf[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(check_value_of_123456789_is_cbf43926),
        cmocka_unit_test(empty_input_gives_zero),
        cmocka_unit_test(known_vectors_match_zlib),
        cmocka_unit_test(table_matches_bitwise_reference_on_every_byte_and_lengths),
        cmocka_unit_test(incremental_equals_one_shot),
        cmocka_unit_test(single_bit_flip_changes_crc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
