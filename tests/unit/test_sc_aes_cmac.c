/* test_sc_aes_cmac.c: the core's AES-128 and AES-CMAC against FIPS-197's example, RFC 4493's
 * subkeys and four examples, and against Mbed TLS on random keys and messages of every length
 * from 0 to 80 bytes (block boundaries included). */
#include "sc_test.h"

#include <string.h>

#include "sc_aes_cmac.h"
#include "sc_cmdsign.h"
#include "sc_err.h"

static void unhex(const char *h, uint8_t *out, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        unsigned v = 0;
        for (int k = 0; k < 2; k++) {
            const char c = h[2 * i + (size_t)k];
            v = v * 16u + (unsigned)(c <= '9' ? c - '0' : c - 'a' + 10);
        }
        out[i] = (uint8_t)v;
    }
}

static void aes128_matches_fips197_appendix_c1(void **state)
{
    (void)state;
    uint8_t key[16], pt[16], want[16], got[16];
    unhex("000102030405060708090a0b0c0d0e0f", key, 16);
    unhex("00112233445566778899aabbccddeeff", pt, 16);
    unhex("69c4e0d86a7b0430d8cdb78070b4c55a", want, 16);
    sc_aes128 a;
    sc_aes128_init(&a, key);
    sc_aes128_encrypt(&a, pt, got);
    assert_memory_equal(got, want, 16);
    /* FIPS-197 appendix A.1: the last round key of 2b7e1516... */
    unhex("2b7e151628aed2a6abf7158809cf4f3c", key, 16);
    sc_aes128_init(&a, key);
    unhex("d014f9a8c9ee2589e13f0cc8b6630ca6", want, 16);
    assert_memory_equal(&a.rk[160], want, 16);
}

static const char *const k_rfc_msg =
    "6bc1bee22e409f96e93d7e117393172aae2d8a571e03ac9c9eb76fac45af8e51"
    "30c81c46a35ce411e5fbc1191a0a52eff69f2445df4f9b17ad2b417be66c3710";

static void cmac_matches_rfc4493_subkeys_and_examples(void **state)
{
    (void)state;
    uint8_t key[16], msg[64], want[16], got[16];
    unhex("2b7e151628aed2a6abf7158809cf4f3c", key, 16);
    unhex(k_rfc_msg, msg, 64);
    sc_cmac_key k;
    sc_cmac_key_init(&k, key);
    unhex("fbeed618357133667c85e08f7236a8de", want, 16);
    assert_memory_equal(k.k1, want, 16);
    unhex("f7ddac306ae266ccf90bc11ee46d513b", want, 16);
    assert_memory_equal(k.k2, want, 16);
    const struct {
        size_t len;
        const char *mac;
    } ex[] = {
        {0, "bb1d6929e95937287fa37d129b756746"},
        {16, "070a16b46b4d4144f79bdd9dd04a287c"},
        {40, "dfa66747de9ae63030ca32611497c827"},
        {64, "51f0bebf7e3b9d92fc49741779363cfe"},
    };
    for (size_t i = 0; i < sizeof ex / sizeof ex[0]; i++) {
        unhex(ex[i].mac, want, 16);
        sc_cmac(&k, ex[i].len ? msg : NULL, ex[i].len, got);
        assert_memory_equal(got, want, 16);
        /* and the Linux senders' CMAC (Mbed TLS where built with it) */
        assert_int_equal(sc_cmdsign_cmac(key, msg, ex[i].len, got), SC_OK);
        assert_memory_equal(got, want, 16);
    }
    sc_cmac_key_wipe(&k);
    const uint8_t zero[sizeof k] = {0};
    assert_memory_equal(&k, zero, sizeof k);
}

static void cmac_agrees_with_mbedtls_on_random_keys_and_lengths(void **state)
{
    (void)state;
    if (!sc_cmdsign_uses_mbedtls()) {
        print_message("built without Mbed TLS: nothing to compare with\n");
        skip();
    }
    uint32_t r = 2024u;
    unsigned checked = 0;
    for (int it = 0; it < 400; it++) {
        uint8_t key[16], msg[80], a[16], b[16];
        for (size_t i = 0; i < sizeof key; i++) {
            r = r * 1664525u + 1013904223u;
            key[i] = (uint8_t)(r >> 24);
        }
        for (size_t i = 0; i < sizeof msg; i++) {
            r = r * 1664525u + 1013904223u;
            msg[i] = (uint8_t)(r >> 24);
        }
        const size_t len = (size_t)it % 81u;
        sc_cmac_key k;
        sc_cmac_key_init(&k, key);
        sc_cmac(&k, msg, len, a);
        assert_int_equal(sc_cmdsign_cmac(key, msg, len, b), SC_OK);
        assert_memory_equal(a, b, 16);
        checked++;
    }
    assert_int_equal(checked, 400);
}

static void mac_compare_finds_a_difference_in_any_byte(void **state)
{
    (void)state;
    uint8_t a[5] = {1, 2, 3, 4, 5}, b[5];
    memcpy(b, a, 5);
    assert_true(sc_mac_equal(a, b, 5));
    for (size_t i = 0; i < 5; i++) {
        memcpy(b, a, 5);
        b[i] ^= 0x80u;
        assert_false(sc_mac_equal(a, b, 5));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(aes128_matches_fips197_appendix_c1),
        cmocka_unit_test(cmac_matches_rfc4493_subkeys_and_examples),
        cmocka_unit_test(cmac_agrees_with_mbedtls_on_random_keys_and_lengths),
        cmocka_unit_test(mac_compare_finds_a_difference_in_any_byte),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
