/*
 * sc_le.h: little-endian field access for the file and record formats (case file sections, the
 * state stream): alignment- and host-endianness-independent byte reads and writes.
 *
 * Thread and memory rules: pure functions over caller bytes; never allocate, never call the OS,
 * cannot fail. The caller checks the bounds.
 */
#ifndef SC_LE_H
#define SC_LE_H

#include <stdint.h>
#include <string.h>

static inline uint32_t sc_le_rd_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static inline uint64_t sc_le_rd_u64(const uint8_t *p)
{
    return (uint64_t)sc_le_rd_u32(p) | ((uint64_t)sc_le_rd_u32(p + 4) << 32);
}

static inline float sc_le_rd_f32(const uint8_t *p)
{
    const uint32_t u = sc_le_rd_u32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static inline void sc_le_wr_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static inline void sc_le_wr_u64(uint8_t *p, uint64_t v)
{
    sc_le_wr_u32(p, (uint32_t)v);
    sc_le_wr_u32(p + 4, (uint32_t)(v >> 32));
}

static inline void sc_le_wr_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    sc_le_wr_u32(p, u);
}

#endif /* SC_LE_H */
