/*
 * sc_soak_frames.c: the whole engine on the host simulator under random valid and invalid CAN
 * traffic, for a million CAN frames or more (issue 14, item 6; tools/soak-frames.sh).
 *
 *   sc_soak_frames [--can-frames N] [--seed S] [--every FRAMES] [--out FILE]
 *
 * Every engine frame the peer node sends, besides the tracker emulator's poses (press, sweep
 * and rock in turn, classic and FD), a random mix of: frames of random id, length and bytes
 * (standard and extended ids, RTR and FD flags); frames on the protocol's ids with random
 * bytes; frames on the protocol's ids with a valid E2E header over random signals (implausible
 * or out-of-range poses, commands with arbitrary fields); replays of an earlier pose frame. The
 * bus drops, corrupts, duplicates and reorders frames at random. Everything follows from the
 * seed: two runs with the same arguments print the same checkpoints (tools/soak-frames.sh runs
 * it twice and compares).
 *
 * Checked after every engine frame (the run stops at the first failure, exit 1):
 *  - every CAN frame the engine took reached the tracker and was counted under exactly one
 *    outcome; the engine took every frame the bus delivered to it;
 *  - no deadline miss, no imaging error, no stability guard reset, never the FAULT state;
 *  - every frame reached the display complete.
 * Every --every frames (default 1000) a checkpoint line: engine frame, CAN frames sent, the
 * engine's state hash, the last image's hash, the health state and the tracker's outcome
 * counts. Exit 0 when the count is reached with every check passing, 2 on a usage error.
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_test_case.h"
#include "sc_tracker.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_test_case tc;
static sc_emu emu;

static uint64_t rng_state;

static uint32_t rnd(void)
{
    rng_state ^= rng_state >> 12u;
    rng_state ^= rng_state << 25u;
    rng_state ^= rng_state >> 27u;
    return (uint32_t)((rng_state * UINT64_C(2685821657736338717)) >> 32u);
}

static int send_peer(void *ctx, const sc_can_frame *f)
{
    return sc_can_send((const sc_can_dev *)ctx, f);
}

static sc_can_frame last_pose; /* replayed later: a stale frame */
static int have_last_pose;

static int record_pose(void *ctx, const sc_can_frame *f)
{
    if (f->id >= SC_CANID_POSE_POS && f->id <= SC_CANID_POSE_FD) {
        last_pose = *f;
        have_last_pose = 1;
    }
    return send_peer(ctx, f);
}

static const uint32_t k_proto_ids[] = {SC_CANID_CMD_CASE,   SC_CANID_CMD_METHOD,
                                       SC_CANID_CMD_IMAGING, SC_CANID_CMD_RESET,
                                       SC_CANID_POSE_POS,   SC_CANID_POSE_QUAT,
                                       SC_CANID_POSE_AUX,   SC_CANID_POSE_FD,
                                       SC_CANID_STATUS,     SC_CANID_TIMING,
                                       SC_CANID_DIAG};

/* One frame of the invalid (or valid but hostile) mix. */
static void make_noise(sc_can_frame *f)
{
    memset(f, 0, sizeof *f);
    const uint32_t kind = rnd() % 100u;
    const uint32_t nids = (uint32_t)(sizeof k_proto_ids / sizeof k_proto_ids[0]);
    f->len = (uint8_t)(rnd() % 9u);
    if (kind < 25u) { /* anything */
        f->flags = (uint8_t)(rnd() & (SC_CAN_FLAG_EXT | SC_CAN_FLAG_RTR | SC_CAN_FLAG_FD));
        f->id = f->flags & SC_CAN_FLAG_EXT ? rnd() & 0x1FFFFFFFu : rnd() & 0x7FFu;
        if (f->flags & SC_CAN_FLAG_FD) {
            static const uint8_t fd_len[] = {0, 8, 12, 16, 20, 24, 32, 48, 64};
            f->len = fd_len[rnd() % 9u];
        }
    } else if (kind < 55u) { /* a protocol id, random bytes (a bad CRC, almost always) */
        f->id = k_proto_ids[rnd() % nids];
        if (f->id == SC_CANID_POSE_FD) {
            f->flags = SC_CAN_FLAG_FD;
            f->len = rnd() % 2u ? 32u : (uint8_t)(rnd() % 65u);
        }
    } else if (kind < 95u) { /* a protocol id, a valid E2E header over random signals */
        f->id = k_proto_ids[rnd() % nids];
        f->len = 8u;
        if (f->id == SC_CANID_POSE_FD) {
            f->flags = SC_CAN_FLAG_FD;
            f->len = 32u;
        }
    } else { /* a replay of an earlier pose frame: stale counter */
        if (have_last_pose) {
            *f = last_pose;
            return;
        }
        f->id = SC_CANID_POSE_POS;
    }
    for (uint32_t i = 0; i < f->len; i++) {
        f->data[i] = (uint8_t)rnd();
    }
    if (kind >= 55u && kind < 95u && f->len >= 2u) {
        (void)sc_e2e_protect_with((uint16_t)f->id, (uint8_t)(rnd() & 0x0Fu), f->data, f->len);
    }
}

static void start_script(uint32_t n)
{
    sc_emu_def ed = sc_emu_default_def();
    static const sc_emu_script scripts[] = {SC_EMU_PRESS, SC_EMU_SWEEP, SC_EMU_ROCK};
    ed.script = scripts[n % 3u];
    ed.fd = (int)(n / 3u % 2u);
    memcpy(ed.point_mm, tc.centre_tracker_mm, sizeof ed.point_mm);
    ed.hover_mm = 3.0f;
    ed.depth_mm = 4.0f;
    ed.duration_s = 20.0;
    if (sc_emu_init(&emu, &ed) != SC_OK) {
        fprintf(stderr, "soak: emulator refused its definition\n");
        exit(1);
    }
}

static uint64_t parse_u64(const char *s, const char *what)
{
    char *end = NULL;
    const unsigned long long v = strtoull(s, &end, 10);
    if (!*s || *s == '-' || *end) {
        fprintf(stderr, "soak: %s wants an unsigned integer, got '%s'\n", what, s);
        exit(2);
    }
    return (uint64_t)v;
}

#define CHECK(c)                                                                               \
    do {                                                                                       \
        if (!(c)) {                                                                            \
            fprintf(stderr, "soak: engine frame %" PRIu64 ": check failed: %s\n", frame, #c);  \
            return 1;                                                                          \
        }                                                                                      \
    } while (0)

int main(int argc, char **argv)
{
    uint64_t can_frames = 1000000u, seed = 1u, every = 1000u;
    const char *out_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (i + 1 < argc && strcmp(argv[i], "--can-frames") == 0) {
            can_frames = parse_u64(argv[++i], "--can-frames");
        } else if (i + 1 < argc && strcmp(argv[i], "--seed") == 0) {
            seed = parse_u64(argv[++i], "--seed");
        } else if (i + 1 < argc && strcmp(argv[i], "--every") == 0) {
            every = parse_u64(argv[++i], "--every");
        } else if (i + 1 < argc && strcmp(argv[i], "--out") == 0) {
            out_path = argv[++i];
        } else {
            fprintf(stderr, "usage: sc_soak_frames [--can-frames N] [--seed S] [--every FRAMES] "
                            "[--out FILE]\n");
            return 2;
        }
    }
    if (every == 0u) {
        fprintf(stderr, "soak: --every wants at least 1\n");
        return 2;
    }
    FILE *out = out_path ? fopen(out_path, "w") : stdout;
    if (!out) {
        perror(out_path);
        return 2;
    }
    rng_state = seed * UINT64_C(0x9E3779B97F4A7C15) + 1u;
    if (sc_test_case_make(&tc, 6, 4, 5, SC_LABEL_VEIN, "block") != SC_OK) {
        fprintf(stderr, "soak: cannot make the test case\n");
        return 1;
    }
    sc_engine_def def = sc_test_engine_def();
    def.bscan.scan.lines_n = 32u;
    def.bscan.scan.samples_n = 64u;
    if (sc_hs_rig_init(&rig, &def, seed, 0) != SC_OK ||
        sc_hs_storage_add(&rig.storage, "block", tc.bytes, tc.size) != SC_OK ||
        sc_engine_load_case(&rig.engine, "block") != SC_OK) {
        fprintf(stderr, "soak: cannot start the engine on the test case\n");
        return 1;
    }
    const sc_hs_can_faults faults = {.drop_ppm = 20000u, .corrupt_ppm = 20000u,
                                     .duplicate_ppm = 10000u, .reorder_ppm = 10000u};
    sc_hs_can_set_faults(&rig.bus, &faults);
    uint32_t script_n = 0;
    start_script(script_n);
    uint64_t script_t0 = rig.clock.now_ns;

    fprintf(out, "# engine_frame can_frames state_hash image_hash state accepted refused\n");
    uint64_t frame = 0;
    const sc_hs_can_injected *peer_tx = &rig.bus.by_sender[rig.peer_node];
    while (peer_tx->sent < can_frames) {
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        if (sc_emu_feed(&emu, release - script_t0, record_pose, &rig.peer) == SC_ERR_NOT_FOUND) {
            start_script(++script_n);
            script_t0 = release;
        }
        const uint32_t noise = rnd() % 13u;
        for (uint32_t k = 0; k < noise; k++) {
            sc_can_frame f;
            make_noise(&f);
            (void)sc_can_send(&rig.peer, &f);
        }
        sc_engine_step(&rig.engine, NULL);
        frame++;

        const sc_engine_counters *c = sc_engine_get_counters(&rig.engine);
        const sc_trk_counters *k = sc_tracker_counters(&rig.engine.tracker);
        uint64_t outcomes = 0;
        for (int o = 0; o < (int)SC_TRK_OUTCOME_COUNT; o++) {
            outcomes += k->outcome[o];
        }
        sc_engine_status st;
        sc_engine_get_status(&rig.engine, &st);
        /* every received frame went to the tracker or, on the needle's ids, to its receiver */
        uint64_t needle_frames = 0;
#if SC_ENABLE_NEEDLE
        const sc_needle_rx *nrx = sc_engine_get_needle_rx(&rig.engine);
        for (int o = 0; o < (int)SC_NEEDLE_OUTCOME_COUNT; o++) {
            needle_frames += nrx->outcome[o];
        }
#endif
        CHECK(k->frames + needle_frames == c->can_rx_frames);
        CHECK(outcomes == k->frames);
        CHECK(rig.tap.frames == c->can_rx_frames);
        CHECK(st.misses == 0u);
        CHECK(c->imaging_errors == 0u);
        CHECK(c->phys_resets == 0u);
        CHECK(st.state != SC_HEALTH_FAULT);
        CHECK(rig.display.frames_complete == frame);
        if (frame % every == 0u || peer_tx->sent >= can_frames) {
            const uint64_t image = rig.display.hash_count
                                       ? rig.display.hashes[rig.display.hash_count - 1u]
                                       : 0u;
            fprintf(out, "%" PRIu64 " %" PRIu64 " %016" PRIx64 " %016" PRIx64 " %s %u %u\n",
                    frame, peer_tx->sent, sc_engine_state_hash(&rig.engine), image,
                    sc_health_state_name(st.state), (unsigned)k->outcome[SC_TRK_POSE_ACCEPTED],
                    (unsigned)(k->frames - k->outcome[SC_TRK_POSE_ACCEPTED]));
        }
    }
    const sc_trk_counters *k = sc_tracker_counters(&rig.engine.tracker);
    fprintf(stderr,
            "soak: %" PRIu64 " engine frames, %" PRIu64 " CAN frames sent to the engine (%" PRIu64
            " dropped, %" PRIu64 " corrupted, %" PRIu64 " duplicated, %" PRIu64
            " reordered), %u taken by the engine, %u poses accepted; every check passed\n",
            frame, peer_tx->sent, peer_tx->dropped, peer_tx->corrupted, peer_tx->duplicated,
            peer_tx->reordered, (unsigned)k->frames,
            (unsigned)k->outcome[SC_TRK_POSE_ACCEPTED]);
    if (out != stdout && fclose(out) != 0) {
        return 1;
    }
    free(tc.bytes);
    return 0;
}
