/* sc_case_drive.c: the optional DRIV section (the patient's vessel drive), see sc_case_drive.h. */
#include "sc_case_drive.h"

#include <string.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_le.h"

int sc_case_drive_parse(const uint8_t *p, uint64_t n, sc_case_drive *out)
{
    if (p == NULL || out == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (n != SC_CASE_DRIVE_SIZE || sc_le_rd_u32(p) != SC_CASE_DRIVE_VERSION ||
        sc_le_rd_u32(p + 28) != 0u) {
        return SC_ERR_CASE_DRIVE;
    }
    const uint32_t wave = sc_le_rd_u32(p + 12);
    if (wave > (uint32_t)SC_LUMEN_WAVE_SINE) {
        return SC_ERR_CASE_DRIVE;
    }
    sc_case_drive v;
    memset(&v, 0, sizeof v);
    v.present = 1u;
    v.d.heart_rate_bpm = sc_le_rd_f32(p + 4);
    v.d.pulse_pa = sc_le_rd_f32(p + 8);
    v.d.wave = (uint8_t)wave;
    v.d.resp_rate_bpm = sc_le_rd_f32(p + 16);
    v.d.resp_pa = sc_le_rd_f32(p + 20);
    v.d.valsalva_pa = sc_le_rd_f32(p + 24);
    v.d.valsalva = 0u;
    if (sc_lumen_drive_validate(&v.d) != SC_OK) {
        return SC_ERR_CASE_DRIVE;
    }
    *out = v;
    return SC_OK;
}

int sc_case_drive_find(const uint8_t *bytes, size_t size, sc_case_drive *out)
{
    if (bytes == NULL || out == NULL || size < SC_CASE_HEADER_SIZE) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t count = sc_le_rd_u32(bytes + 24);
    uint64_t off = SC_CASE_HEADER_SIZE;
    const uint8_t *found = NULL;
    uint64_t found_n = 0;
    for (uint32_t i = 0; i < count && off + SC_CASE_SECTION_HEADER_SIZE <= size; i++) {
        const uint8_t *h = bytes + off;
        const uint64_t psize =
            (uint64_t)sc_le_rd_u32(h + 8) | ((uint64_t)sc_le_rd_u32(h + 12) << 32);
        if (psize > size - off - SC_CASE_SECTION_HEADER_SIZE) {
            return SC_ERR_CASE_TRUNCATED; /* the framing check would have refused it */
        }
        if (sc_le_rd_u32(h) == SC_CASE_TAG_DRIV_U32) {
            if (found != NULL) {
                return SC_ERR_CASE_SECTION; /* duplicated */
            }
            found = h + SC_CASE_SECTION_HEADER_SIZE;
            found_n = psize;
        }
        off += SC_CASE_SECTION_HEADER_SIZE + psize;
        off = (off + SC_CASE_ALIGN - 1u) / SC_CASE_ALIGN * SC_CASE_ALIGN;
    }
    if (found == NULL) {
        memset(out, 0, sizeof *out);
        return SC_OK;
    }
    return sc_case_drive_parse(found, found_n, out);
}

int sc_case_drive_encode(const sc_lumen_drive *d, uint8_t out[SC_CASE_DRIVE_SIZE])
{
    if (d == NULL || out == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    sc_lumen_drive v = *d;
    v.valsalva = 0u;
    const int rc = sc_lumen_drive_validate(&v);
    if (rc != SC_OK) {
        return rc;
    }
    memset(out, 0, SC_CASE_DRIVE_SIZE);
    sc_le_wr_u32(out, SC_CASE_DRIVE_VERSION);
    sc_le_wr_f32(out + 4, v.heart_rate_bpm);
    sc_le_wr_f32(out + 8, v.pulse_pa);
    sc_le_wr_u32(out + 12, v.wave);
    sc_le_wr_f32(out + 16, v.resp_rate_bpm);
    sc_le_wr_f32(out + 20, v.resp_pa);
    sc_le_wr_f32(out + 24, v.valsalva_pa);
    return SC_OK;
}
