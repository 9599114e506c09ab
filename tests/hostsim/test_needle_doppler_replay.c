/* test_needle_doppler_replay.c: a needle + Doppler session replays to the same hashes (issue 18
 * item 4: "deterministic (hashes), replayable"). The block case (vein and artery along y), the
 * probe pressing with a 10-degree roll so that the beam sees the flow (colour Doppler over the
 * whole image), the tracked needle driven into the vein, held and withdrawn; every CAN frame the
 * engine received is recorded as candump -l lines (as sc-hostsim --record writes them), then a
 * fresh engine is fed only those lines (parsed by the candump reader, injected on the bus at
 * their time stamps, as sc-hostsim --replay does). Checked, frame by frame: the B-mode image
 * hash (with the needle drawn in it), the colour Doppler hash and the tissue state hash are
 * identical; at the end the needle's punctures and the assessment are the same. */
#include "sc_test.h"

#include <string.h>

#include "sc_candump.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_test_block_rig.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

#define FRAMES 240u /* 4 s at 60 Hz */
#define LOG_CAP (1u << 21)

static sc_hs_rig rig;
static sc_emu emu;
static sc_emu_needle needle;

static char g_log[LOG_CAP]; /* the candump -l log of the recorded session */
static size_t g_log_len;
static uint32_t g_log_frames;

typedef struct session {
    uint64_t image[FRAMES];
    uint64_t colour[FRAMES];
    uint64_t state[FRAMES];
    uint32_t drawn_max, colour_max;
    sc_needle_status needle;
    sc_assess_report assess;
} session;

static session g_rec, g_rep;

static void record_frame(void *user, const sc_can_frame *f)
{
    (void)user;
    sc_candump_rec rec = {.ts_us = f->ts_ns / 1000u, .frame = *f};
    strcpy(rec.iface, "hs0");
    char line[SC_CANDUMP_LINE_MAX + 2];
    const int n = sc_candump_format(&rec, line, sizeof line);
    assert_true(n > 0);
    assert_true(g_log_len + (size_t)n < LOG_CAP);
    memcpy(g_log + g_log_len, line, (size_t)n);
    g_log_len += (size_t)n;
    g_log_frames++;
}

static void rig_up(void)
{
    sc_test_block_rig_up(&rig, &sc_test_block, 3, 1);
}

static void emulators_up(void)
{
    /* the probe pressing 2 mm with a 10-degree roll about x */
    const sc_emu_def pd = sc_test_block_probe_def(&sc_test_block, 2.0f, 10.0f);
    assert_int_equal(sc_emu_init(&emu, &pd), SC_OK);
    /* the needle of test_needle_engine: from 8 mm beside the vein toward its axis */
    const sc_emu_needle_def nd = sc_test_block_needle_def(
        &sc_test_block, sc_test_block.vein_tracker_mm[0] - 8.0f, 8.0f, 0.5);
    assert_int_equal(sc_emu_needle_init(&needle, &nd), SC_OK);
}

static void after_frame(session *s, uint32_t i)
{
    assert_int_equal(rig.display.hash_count, i + 1u); /* every frame complete */
    s->image[i] = rig.display.hashes[i];
    s->colour[i] = rig.display.colour_hash;
    s->state[i] = sc_engine_state_hash(&rig.engine);
    const sc_needle_status *ns = sc_engine_get_needle_status(&rig.engine);
    s->drawn_max = ns->drawn_pixels > s->drawn_max ? ns->drawn_pixels : s->drawn_max;
    const uint32_t cp = sc_engine_get_doppler_status(&rig.engine)->colour_pixels;
    s->colour_max = cp > s->colour_max ? cp : s->colour_max;
}

static void finish(session *s)
{
    s->needle = *sc_engine_get_needle_status(&rig.engine);
    s->assess = *sc_engine_assessment(&rig.engine);
}

static void record_session(void)
{
    memset(&g_rec, 0, sizeof g_rec);
    g_log_len = 0;
    g_log_frames = 0;
    rig_up();
    emulators_up();
    rig.tap.fn = record_frame;
    sc_test_feed feed;
    sc_test_feed_start(&feed, &rig, &emu, &needle);
    for (uint32_t i = 0; i < FRAMES; i++) {
        sc_test_feed_due(&feed, &rig, sc_engine_next_release_ns(&rig.engine));
        sc_engine_step(&rig.engine, NULL);
        after_frame(&g_rec, i);
        sc_can_frame r;
        while (sc_can_recv(&rig.peer, &r) == SC_OK) {
        }
    }
    finish(&g_rec);
    rig.tap.fn = NULL;
}

static void replay_session(void)
{
    memset(&g_rep, 0, sizeof g_rep);
    rig_up();
    size_t pos = 0;
    int have = 0;
    uint32_t injected = 0;
    sc_candump_rec pending;
    for (uint32_t i = 0; i < FRAMES; i++) {
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        for (;;) {
            if (!have) {
                if (pos >= g_log_len) {
                    break;
                }
                const char *line = g_log + pos;
                const char *nl = memchr(line, '\n', g_log_len - pos);
                const size_t len = nl != NULL ? (size_t)(nl - line) : g_log_len - pos;
                pos += len + 1u;
                sc_candump_reject why;
                assert_int_equal(sc_candump_parse_line(line, len, &pending, &why), SC_OK);
                have = 1;
            }
            if (pending.ts_us * 1000u > release) {
                break;
            }
            assert_int_equal(sc_hs_can_inject(&rig.bus, rig.engine_node, &pending.frame), SC_OK);
            injected++;
            have = 0;
        }
        sc_engine_step(&rig.engine, NULL);
        after_frame(&g_rep, i);
        sc_can_frame r;
        while (sc_can_recv(&rig.peer, &r) == SC_OK) {
        }
    }
    finish(&g_rep);
    assert_int_equal(injected, g_log_frames); /* the whole log went in */
}

static void a_needle_and_doppler_session_replays_to_the_same_hashes(void **state)
{
    (void)state;
    record_session();
    print_message("recorded: %u CAN frames (%zu bytes of candump log), needle drawn up to %u px, "
                  "colour up to %u px, vein punctures %u, artery %u\n",
                  g_log_frames, g_log_len, g_rec.drawn_max, g_rec.colour_max,
                  g_rec.needle.vein_punctures, g_rec.needle.artery_punctures);
    /* the session holds what it claims: the needle in the image, colour, a vein puncture */
    assert_true(g_rec.drawn_max > 20u);
    assert_true(g_rec.colour_max > 20u);
    assert_int_equal(g_rec.needle.vein_punctures, 1u);
    assert_int_equal(g_rec.needle.artery_punctures, 0u);
    assert_int_equal(g_rec.assess.vein_punctures, 1u);
    /* the images change over the session (a replay of a still scene would prove little) */
    uint32_t changes = 0;
    for (uint32_t i = 1; i < FRAMES; i++) {
        changes += g_rec.image[i] != g_rec.image[i - 1];
    }
    assert_true(changes > FRAMES / 4u);
    replay_session();
    uint32_t image_diff = 0, colour_diff = 0, state_diff = 0, first = FRAMES;
    for (uint32_t i = 0; i < FRAMES; i++) {
        const int d = g_rec.image[i] != g_rep.image[i] || g_rec.colour[i] != g_rep.colour[i] ||
                      g_rec.state[i] != g_rep.state[i];
        image_diff += g_rec.image[i] != g_rep.image[i];
        colour_diff += g_rec.colour[i] != g_rep.colour[i];
        state_diff += g_rec.state[i] != g_rep.state[i];
        if (d && first == FRAMES) {
            first = i;
        }
    }
    print_message("replayed %u frames: %u image, %u colour, %u state hashes differ (first %u)\n",
                  FRAMES, image_diff, colour_diff, state_diff, first);
    assert_int_equal(first, FRAMES);
    assert_int_equal(g_rep.needle.vein_punctures, g_rec.needle.vein_punctures);
    assert_int_equal(g_rep.needle.artery_punctures, g_rec.needle.artery_punctures);
    assert_memory_equal(&g_rep.assess, &g_rec.assess, sizeof g_rec.assess);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_needle_and_doppler_session_replays_to_the_same_hashes),
    };
    return cmocka_run_group_tests(tests, sc_test_block_group_setup, sc_test_block_group_teardown);
}
