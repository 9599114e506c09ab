/* test_sc_secoc.c: command authentication (core/link/sc_secoc.h) on its own and in the
 * tracker: a signed command is accepted once; a wrong key, a flipped bit anywhere, a replay, a
 * stale or out-of-window freshness, a missing MAC, an unknown or unsynchronised sender are
 * refused and counted by reason; the freshness window and the 16-bit truncation's wrap. */
#include "sc_test.h"

#include <string.h>

#include "sc_canproto.h"
#include "sc_cmdsign.h"
#include "sc_err.h"
#include "sc_secoc.h"
#include "sc_tracker.h"

#define MS 1000000ull

static sc_tracker trk;
static sc_cmdsign snd;
static uint64_t now;

static int setup(void **state)
{
    (void)state;
    now = 1000u * MS;
    sc_tracker_def d = sc_tracker_default_def();
    assert_int_equal(sc_cmdsign_init(&snd, sc_secoc_bench_key, 1u, 70000u, 0), SC_OK);
    return sc_tracker_init(&trk, &d);
}

static sc_trk_outcome feed(const sc_can_frame *f)
{
    now += MS;
    return sc_tracker_on_frame(&trk, f, now);
}

/* command frame then its cryptographic PDU: the second outcome */
static sc_trk_outcome feed_pair(const sc_can_frame f[2])
{
    const sc_trk_outcome a = feed(&f[0]);
    assert_int_equal(a, SC_TRK_CMD_PENDING);
    return feed(&f[1]);
}

static void sync_sender(void)
{
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_sync(&snd, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_SYNCED);
}

static const sc_cmd k_fem = {.kind = SC_CMD_SET_METHOD, .method = SC_METHOD_FEM};

static void a_signed_command_after_a_sync_is_queued_with_its_sender(void **state)
{
    (void)state;
    sync_sender();
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(f[1].id, SC_CANID_AUTH_CASE + 1u);
    assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    sc_cmd c;
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_OK);
    assert_int_equal(c.kind, SC_CMD_SET_METHOD);
    assert_int_equal(c.method, SC_METHOD_FEM);
    assert_int_equal(c.sender, 1);
    assert_int_equal(sc_tracker_rejected_auth(&trk), 0);
    assert_int_equal(sc_tracker_authenticated(&trk), 2);
    /* the core's signer gives the same cryptographic PDU as the Mbed TLS one */
    sc_cmac_key k;
    sc_cmac_key_init(&k, sc_secoc_bench_key);
    uint8_t auth[8];
    sc_secoc_sign(&k, SC_CANID_CMD_METHOD, f[0].data, 1u, snd.fv, auth);
    assert_memory_equal(auth, f[1].data, 8);
}

static void a_command_before_any_sync_is_refused_as_not_synced(void **state)
{
    (void)state;
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_NOT_SYNCED);
    sc_cmd c;
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_ERR_WOULD_BLOCK);
}

static void a_wrong_key_is_refused_as_bad_mac(void **state)
{
    (void)state;
    sync_sender();
    uint8_t key[16];
    memcpy(key, sc_secoc_bench_key, 16);
    key[0] ^= 0x80u;
    sc_cmdsign other;
    assert_int_equal(sc_cmdsign_init(&other, key, 1u, snd.fv, 0), SC_OK);
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_command(&other, &k_fem, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_BAD_MAC);
    /* a sync under the wrong key neither */
    assert_int_equal(sc_cmdsign_sync(&other, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_BAD_MAC);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_AUTH_BAD_MAC], 2);
    sc_cmd c;
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_ERR_WOULD_BLOCK);
}

static void any_flipped_bit_of_command_or_mac_is_refused(void **state)
{
    (void)state;
    sync_sender();
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    unsigned refused = 0;
    /* every bit of the command's signals (E2E CRC recomputed: an attacker can) and of the
     * cryptographic PDU's freshness and MAC */
    for (unsigned bit = 16; bit < 64u; bit++) {
        sc_can_frame g[2] = {f[0], f[1]};
        g[0].data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        (void)sc_e2e_protect_with((uint16_t)g[0].id, g[0].data[1] & 0x0Fu, g[0].data, 8u);
        const sc_trk_outcome a = feed(&g[0]);
        if (a == SC_TRK_CMD_REJECTED) {
            refused++; /* outside the DBC range: refused before the MAC */
            continue;
        }
        assert_int_equal(a, SC_TRK_CMD_PENDING);
        assert_int_equal(feed(&g[1]), SC_TRK_AUTH_BAD_MAC);
        refused++;
    }
    for (unsigned bit = 8; bit < 64u; bit++) {
        sc_can_frame g[2] = {f[0], f[1]};
        g[1].data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        assert_int_equal(feed(&g[0]), SC_TRK_CMD_PENDING);
        const sc_trk_outcome o = feed(&g[1]);
        /* freshness bits give another value: a MAC mismatch, or out of the window (stale) */
        assert_true(o == SC_TRK_AUTH_BAD_MAC || o == SC_TRK_AUTH_STALE);
        refused++;
    }
    assert_int_equal(refused, 48u + 56u);
    sc_cmd c;
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_ERR_WOULD_BLOCK);
    /* the genuine pair still goes through afterwards (nothing advanced the freshness) */
    assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
}

static void a_replayed_command_is_stale_and_an_exact_repeat_is_a_duplicate(void **state)
{
    (void)state;
    sync_sender();
    sc_can_frame rec[2];
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, rec), SC_OK);
    assert_int_equal(feed_pair(rec), SC_TRK_COMMAND);
    /* the bus repeats the pair at once: one duplicate, nothing refused */
    assert_int_equal(feed(&rec[0]), SC_TRK_CMD_PENDING);
    assert_int_equal(feed(&rec[1]), SC_TRK_DUPLICATE);
    /* each frame repeated on its own: one duplicate each */
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, rec), SC_OK);
    assert_int_equal(feed(&rec[0]), SC_TRK_CMD_PENDING);
    assert_int_equal(feed(&rec[0]), SC_TRK_DUPLICATE);
    assert_int_equal(feed(&rec[1]), SC_TRK_COMMAND);
    assert_int_equal(feed(&rec[1]), SC_TRK_DUPLICATE);
    /* later, after newer commands, the recorded pair comes back: stale */
    sc_can_frame f[2];
    for (unsigned i = 0; i < 3u; i++) {
        assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
        assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    }
    assert_int_equal(feed_pair(rec), SC_TRK_AUTH_STALE);
    /* an older sync replayed: stale too */
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_AUTH_STALE], 1);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_DUPLICATE], 3);
    assert_int_equal(sc_tracker_rejected_auth(&trk), 1);
}

static void a_replayed_sync_is_stale(void **state)
{
    (void)state;
    sc_can_frame s1[2], f[2];
    assert_int_equal(sc_cmdsign_sync(&snd, s1), SC_OK);
    assert_int_equal(feed_pair(s1), SC_TRK_AUTH_SYNCED);
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    /* the last accepted sync again, later than a bus duplicate could be: a replay, stale */
    now += SC_TRK_AUTH_PAIR_MS * MS;
    assert_int_equal(feed_pair(s1), SC_TRK_AUTH_STALE);
    /* after a newer sync it is stale too */
    sync_sender();
    assert_int_equal(feed_pair(s1), SC_TRK_AUTH_STALE);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_AUTH_STALE], 2);
}

static void the_window_accepts_losses_up_to_its_size_and_the_truncation_wraps(void **state)
{
    (void)state;
    /* last accepted value just below a 2^16 boundary: the next one's low bits wrap to 0 */
    snd.fv = 0x2FFFEu;
    sync_sender(); /* 0x2FFFF */
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK); /* 0x30000: low bits 0 */
    assert_int_equal(f[1].data[1] | f[1].data[2], 0);
    assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    /* window - 1 commands lost: step = window, accepted */
    snd.fv += SC_SECOC_DEFAULT_WINDOW - 1u;
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    /* window commands lost: step = window + 1, stale; the sender must resync */
    snd.fv += SC_SECOC_DEFAULT_WINDOW;
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_STALE);
    sync_sender();
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    /* a sender that went back (restarted without its clock): stale until it syncs higher */
    sc_cmdsign old;
    assert_int_equal(sc_cmdsign_init(&old, sc_secoc_bench_key, 1u, 100u, 0), SC_OK);
    assert_int_equal(sc_cmdsign_sync(&old, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_STALE);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_AUTH_STALE], 2);
}

static void a_command_without_its_mac_is_refused_as_missing(void **state)
{
    (void)state;
    sync_sender();
    sc_can_frame f[2], g[2];
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed(&f[0]), SC_TRK_CMD_PENDING);
    /* the next command of the same id comes: the first one never got its MAC */
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, g), SC_OK);
    assert_int_equal(feed_pair(g), SC_TRK_COMMAND);
    assert_int_equal(sc_tracker_counters(&trk)->auth_missing, 1);
    /* a command alone: refused when SC_TRK_AUTH_PAIR_MS has passed */
    assert_int_equal(sc_cmdsign_command(&snd, &k_fem, f), SC_OK);
    assert_int_equal(feed(&f[0]), SC_TRK_CMD_PENDING);
    sc_pose p;
    int contact;
    (void)sc_tracker_poll(&trk, now + SC_TRK_AUTH_PAIR_MS * MS / 2u, &p, &contact);
    assert_int_equal(sc_tracker_counters(&trk)->auth_missing, 1);
    (void)sc_tracker_poll(&trk, now + SC_TRK_AUTH_PAIR_MS * MS + 1u, &p, &contact);
    assert_int_equal(sc_tracker_counters(&trk)->auth_missing, 2);
    now += SC_TRK_AUTH_PAIR_MS * MS + 1u;
    /* its cryptographic PDU after that: an orphan */
    assert_int_equal(feed(&f[1]), SC_TRK_AUTH_ORPHAN);
    assert_int_equal(sc_tracker_rejected_auth(&trk), 3);
    sc_cmd c;
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_OK); /* only g */
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_ERR_WOULD_BLOCK);
}

static void unknown_senders_and_the_floor_are_refused(void **state)
{
    (void)state;
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_sync(&snd, f), SC_OK);
    f[1].data[0] = (uint8_t)((f[1].data[0] & 0xF0u) | 9u); /* sender 9: not kept */
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_UNKNOWN_SENDER);
    /* a floor above the sender's values refuses its sync */
    sc_tracker_def d = sc_tracker_default_def();
    d.secoc.fv_floor = 1000000u;
    assert_int_equal(sc_tracker_init(&trk, &d), SC_OK);
    assert_int_equal(sc_cmdsign_sync(&snd, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_STALE);
    snd.fv = 1000000u;
    assert_int_equal(sc_cmdsign_sync(&snd, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_SYNCED);
    /* window outside its range */
    d.secoc.window = 0u;
    assert_int_equal(sc_tracker_init(&trk, &d), SC_ERR_RANGE);
    d.secoc.window = SC_SECOC_MAX_WINDOW + 1u;
    assert_int_equal(sc_tracker_def_validate(&d), SC_ERR_RANGE);
}

static void two_senders_keep_separate_freshness(void **state)
{
    (void)state;
    sc_cmdsign b;
    assert_int_equal(sc_cmdsign_init(&b, sc_secoc_bench_key, 3u, 5u, 0), SC_OK);
    sc_can_frame f[2];
    sync_sender();
    assert_int_equal(sc_cmdsign_sync(&b, f), SC_OK);
    assert_int_equal(feed_pair(f), SC_TRK_AUTH_SYNCED);
    const sc_cmd reset = {.kind = SC_CMD_RESET, .reset_target = SC_RESET_FAULTS};
    for (unsigned i = 0; i < 4u; i++) {
        assert_int_equal(sc_cmdsign_command(i % 2u ? &b : &snd, &reset, f), SC_OK);
        assert_int_equal(feed_pair(f), SC_TRK_COMMAND);
    }
    assert_int_equal(sc_tracker_rejected_auth(&trk), 0);
}

static void crypto_pdu_fields_round_trip(void **state)
{
    (void)state;
    const sc_secoc_auth a = {.sender = 0xA, .link = 0x5, .fv_low = 0xBEEF, .mac = {1, 2, 3, 4, 5}};
    uint8_t b[8];
    sc_secoc_auth_encode(&a, b);
    const uint8_t want[8] = {0x5A, 0xEF, 0xBE, 1, 2, 3, 4, 5};
    assert_memory_equal(b, want, 8);
    sc_secoc_auth d;
    sc_secoc_auth_decode(b, &d);
    assert_int_equal(d.sender, 0xA);
    assert_int_equal(d.link, 0x5);
    assert_int_equal(d.fv_low, 0xBEEF);
    assert_memory_equal(d.mac, a.mac, 5);
    uint8_t in[SC_SECOC_INPUT_BYTES];
    const uint8_t pdu[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
    sc_secoc_input(0x0082u, pdu, 3u, 0x0102030405060708ull, in);
    const uint8_t want_in[SC_SECOC_INPUT_BYTES] = {0x00, 0x82, 0x11, 0x22, 0x33, 0x44, 0x55,
                                                   0x66, 0x77, 0x88, 0x03, 0x01, 0x02, 0x03,
                                                   0x04, 0x05, 0x06, 0x07, 0x08};
    assert_memory_equal(in, want_in, sizeof in);
    uint8_t key[16];
    assert_int_equal(sc_cmdsign_parse_key("736f6e6f636f6d702d62656e63682d31", key), SC_OK);
    assert_memory_equal(key, sc_secoc_bench_key, 16);
    assert_int_equal(sc_cmdsign_parse_key("736f6e6f636f6d702d62656e63682d3", key),
                     SC_ERR_CFG_VALUE);
    assert_int_equal(sc_cmdsign_parse_key("x36f6e6f636f6d702d62656e63682d31", key),
                     SC_ERR_CFG_VALUE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_signed_command_after_a_sync_is_queued_with_its_sender, setup),
        cmocka_unit_test_setup(a_command_before_any_sync_is_refused_as_not_synced, setup),
        cmocka_unit_test_setup(a_wrong_key_is_refused_as_bad_mac, setup),
        cmocka_unit_test_setup(any_flipped_bit_of_command_or_mac_is_refused, setup),
        cmocka_unit_test_setup(a_replayed_command_is_stale_and_an_exact_repeat_is_a_duplicate,
                               setup),
        cmocka_unit_test_setup(a_replayed_sync_is_stale, setup),
        cmocka_unit_test_setup(the_window_accepts_losses_up_to_its_size_and_the_truncation_wraps,
                               setup),
        cmocka_unit_test_setup(a_command_without_its_mac_is_refused_as_missing, setup),
        cmocka_unit_test_setup(unknown_senders_and_the_floor_are_refused, setup),
        cmocka_unit_test_setup(two_senders_keep_separate_freshness, setup),
        cmocka_unit_test(crypto_pdu_fields_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
