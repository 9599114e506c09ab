/* fuzz_sc_state_stream.c: the outside inputs of the console's transports: a state-stream record
 * as the gateway checks it (core/sc_state.h sc_state_check), a CAN-over-UDP datagram as the live
 * host simulator decodes it (platform/linux/sc_udpcan.h), and a case's SURF payload as the loader
 * validates it (core/case/sc_case_surf.h). Never crash; what is accepted is consistent. */
#include <string.h>

#include "sc_case_surf.h"
#include "sc_err.h"
#include "sc_fuzz.h"
#include "sc_state.h"
#include "sc_udpcan.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1u) {
        return 0;
    }
    const uint8_t which = data[0] % 3u;
    const uint8_t *p = data + 1;
    const size_t n = size - 1u;
    if (which == 0u) {
        uint32_t seq = 0, fno = 0;
        const int t = sc_state_check(p, (uint32_t)(n > 0xffffu ? 0xffffu : n), &seq, &fno);
        if (t > 0) {
            SC_FUZZ_CHECK(n >= SC_STATE_HEADER_SIZE);
            SC_FUZZ_CHECK(((uint32_t)p[6] | ((uint32_t)p[7] << 8)) + SC_STATE_HEADER_SIZE == n);
        }
    } else if (which == 1u) {
        sc_can_frame f;
        if (sc_udpcan_decode(p, n, &f) == SC_OK) {
            uint8_t back[SC_UDPCAN_SIZE];
            SC_FUZZ_CHECK(sc_udpcan_encode(&f, back) == SC_OK);
            SC_FUZZ_CHECK(memcmp(back, p, SC_UDPCAN_SIZE) == 0);
        }
    } else {
        sc_case_surf s;
        if (sc_case_surf_parse(p, n, 320u, &s) == SC_OK) {
            SC_FUZZ_CHECK(s.count >= 1u && s.count <= SC_CASE_SURF_MAX_SURFACES);
            for (uint32_t t = 0; t < s.triangle_count; t++) {
                uint32_t idx[3];
                sc_case_surf_triangle(&s, t, idx);
                SC_FUZZ_CHECK(idx[0] < s.vertex_count && idx[1] < s.vertex_count &&
                              idx[2] < s.vertex_count);
            }
            for (uint32_t v = 0; v < s.vertex_count; v++) {
                uint32_t tet;
                float w[4];
                sc_case_surf_vertex(&s, v, &tet, w);
                SC_FUZZ_CHECK(tet < 320u);
            }
        }
    }
    return 0;
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (cap < 256u) {
        return 0;
    }
    memset(buf, 0, 256u);
    if (i == 0u) { /* a FRAME-typed record header with a 16-byte payload */
        buf[0] = 0;
        put32(buf + 1, SC_STATE_MAGIC);
        buf[5] = SC_STATE_VERSION;
        buf[6] = SC_STATE_FRAME;
        buf[7] = 16;
        return 1u + SC_STATE_HEADER_SIZE + 16u;
    }
    if (i == 1u) { /* a classic CAN frame over UDP */
        sc_can_frame f = {.id = 0x123, .len = 8, .data = {1, 2, 3, 4, 5, 6, 7, 8}};
        buf[0] = 1;
        (void)sc_udpcan_encode(&f, buf + 1);
        return 1u + SC_UDPCAN_SIZE;
    }
    if (i == 2u) { /* a SURF payload: one skin surface, 3 vertices, 1 triangle */
        uint8_t *p = buf + 1;
        buf[0] = 2;
        put32(p, SC_CASE_SURF_VERSION);
        put32(p + 4, 1);
        put32(p + 8, 3);
        put32(p + 12, 1);
        put32(p + 24, 3);
        put32(p + 28, 1);
        const float w = 0.25f;
        for (int v = 0; v < 3; v++) {
            uint8_t *q = p + 32 + 16 * v;
            put32(q, (uint32_t)v);
            for (int k = 0; k < 3; k++) {
                memcpy(q + 4 + 4 * k, &w, 4);
            }
        }
        put32(p + 80, 0);
        put32(p + 84, 1);
        put32(p + 88, 2);
        return 1u + 92u;
    }
    return 0;
}
