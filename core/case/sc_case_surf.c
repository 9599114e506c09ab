/* sc_case_surf.c: the optional SURF section (embedded console surfaces), see sc_case_surf.h. */
#include "sc_case_surf.h"

#include <math.h>
#include <string.h>

#include "sc_case.h"
#include "sc_crc32.h"
#include "sc_err.h"
#include "sc_le.h"

uint64_t sc_case_surf_payload_size(uint32_t surfaces, uint32_t vertices, uint32_t triangles)
{
    return SC_CASE_SURF_HEAD_SIZE + (uint64_t)surfaces * SC_CASE_SURF_REC_SIZE +
           (uint64_t)vertices * SC_CASE_SURF_VERTEX_SIZE +
           (uint64_t)triangles * SC_CASE_SURF_TRI_SIZE;
}

static int weight_ok(float w)
{
    return isfinite(w) && w >= -SC_CASE_SURF_WEIGHT_TOL && w <= 1.0f + SC_CASE_SURF_WEIGHT_TOL;
}

int sc_case_surf_parse(const uint8_t *p, uint64_t n, uint32_t tet_count, sc_case_surf *out)
{
    if (p == NULL || out == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (n < SC_CASE_SURF_HEAD_SIZE || sc_le_rd_u32(p) != SC_CASE_SURF_VERSION) {
        return SC_ERR_CASE_SURFACE;
    }
    const uint32_t ns = sc_le_rd_u32(p + 4), nv = sc_le_rd_u32(p + 8), nt = sc_le_rd_u32(p + 12);
    if (ns < 1u || ns > SC_CASE_SURF_MAX_SURFACES || nv > SC_CASE_SURF_MAX_VERTICES ||
        nt > SC_CASE_SURF_MAX_TRIANGLES || n != sc_case_surf_payload_size(ns, nv, nt)) {
        return SC_ERR_CASE_SURFACE;
    }
    sc_case_surf v;
    memset(&v, 0, sizeof v);
    v.count = ns;
    v.vertex_count = nv;
    v.triangle_count = nt;
    v.vertices = p + SC_CASE_SURF_HEAD_SIZE + ns * SC_CASE_SURF_REC_SIZE;
    v.triangles = v.vertices + (size_t)nv * SC_CASE_SURF_VERTEX_SIZE;
    uint32_t vsum = 0, tsum = 0;
    for (uint32_t i = 0; i < ns; i++) {
        const uint8_t *r = p + SC_CASE_SURF_HEAD_SIZE + i * SC_CASE_SURF_REC_SIZE;
        sc_case_surface *s = &v.s[i];
        s->label = r[0];
        s->kind = r[1];
        s->first_vertex = sc_le_rd_u32(r + 4);
        s->vertex_count = sc_le_rd_u32(r + 8);
        s->triangle_count = sc_le_rd_u32(r + 12);
        s->first_triangle = tsum;
        if ((s->kind != SC_CASE_SURF_SKIN && s->kind != SC_CASE_SURF_VESSEL) || r[2] != 0u ||
            r[3] != 0u || s->label >= SC_MAX_LABELS || s->first_vertex != vsum ||
            s->vertex_count > nv - vsum || s->triangle_count > nt - tsum) {
            return SC_ERR_CASE_SURFACE;
        }
        vsum += s->vertex_count;
        tsum += s->triangle_count;
    }
    if (vsum != nv || tsum != nt) {
        return SC_ERR_CASE_SURFACE;
    }
    for (uint32_t i = 0; i < nv; i++) {
        const uint8_t *q = v.vertices + (size_t)i * SC_CASE_SURF_VERTEX_SIZE;
        const float w0 = sc_le_rd_f32(q + 4), w1 = sc_le_rd_f32(q + 8), w2 = sc_le_rd_f32(q + 12);
        if (sc_le_rd_u32(q) >= tet_count || !weight_ok(w0) || !weight_ok(w1) || !weight_ok(w2) ||
            !weight_ok(1.0f - w0 - w1 - w2)) {
            return SC_ERR_CASE_SURFACE;
        }
    }
    for (uint32_t si = 0; si < ns; si++) {
        const sc_case_surface *s = &v.s[si];
        for (uint32_t t = s->first_triangle; t < s->first_triangle + s->triangle_count; t++) {
            const uint8_t *q = v.triangles + (size_t)t * SC_CASE_SURF_TRI_SIZE;
            for (int k = 0; k < 3; k++) {
                const uint32_t a = sc_le_rd_u32(q + 4 * k);
                if (a < s->first_vertex || a - s->first_vertex >= s->vertex_count) {
                    return SC_ERR_CASE_SURFACE;
                }
            }
        }
    }
    *out = v;
    return SC_OK;
}

int sc_case_surf_find(const uint8_t *bytes, size_t size, const sc_mesh_def *mesh,
                      sc_case_surf *out)
{
    if (bytes == NULL || mesh == NULL || out == NULL || size < SC_CASE_HEADER_SIZE) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t count = sc_le_rd_u32(bytes + 24);
    const uint32_t tets = 5u * (mesh->nx - 1u) * (mesh->ny - 1u) * (mesh->nz - 1u);
    uint64_t off = SC_CASE_HEADER_SIZE;
    const uint8_t *found = NULL;
    uint64_t found_n = 0;
    for (uint32_t i = 0; i < count && off + SC_CASE_SECTION_HEADER_SIZE <= size; i++) {
        const uint8_t *h = bytes + off;
        const uint64_t psize = sc_le_rd_u64(h + 8);
        if (psize > size - off - SC_CASE_SECTION_HEADER_SIZE) {
            return SC_ERR_CASE_TRUNCATED; /* the framing check would have refused it */
        }
        if (sc_le_rd_u32(h) == SC_CASE_TAG_SURF_U32) {
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
    return sc_case_surf_parse(found, found_n, tets, out);
}

void sc_case_surf_vertex(const sc_case_surf *s, uint32_t v, uint32_t *tet, float w[4])
{
    const uint8_t *q = s->vertices + (size_t)v * SC_CASE_SURF_VERTEX_SIZE;
    *tet = sc_le_rd_u32(q);
    w[0] = sc_le_rd_f32(q + 4);
    w[1] = sc_le_rd_f32(q + 8);
    w[2] = sc_le_rd_f32(q + 12);
    w[3] = 1.0f - w[0] - w[1] - w[2];
}

void sc_case_surf_triangle(const sc_case_surf *s, uint32_t t, uint32_t idx[3])
{
    const uint8_t *q = s->triangles + (size_t)t * SC_CASE_SURF_TRI_SIZE;
    idx[0] = sc_le_rd_u32(q);
    idx[1] = sc_le_rd_u32(q + 4);
    idx[2] = sc_le_rd_u32(q + 8);
}

int sc_case_append_section(uint8_t *buf, size_t cap, size_t *size, uint32_t tag,
                           const uint8_t *payload, size_t n)
{
    if (buf == NULL || size == NULL || (payload == NULL && n > 0u) ||
        *size < SC_CASE_HEADER_SIZE || (*size % SC_CASE_ALIGN) != 0u) {
        return SC_ERR_INVALID_ARG;
    }
    const size_t padded = (n + SC_CASE_ALIGN - 1u) / SC_CASE_ALIGN * SC_CASE_ALIGN;
    const size_t need = *size + SC_CASE_SECTION_HEADER_SIZE + padded;
    if (padded < n || need < *size || need > cap) {
        return SC_ERR_NO_SPACE;
    }
    uint8_t *h = buf + *size;
    memset(h, 0, SC_CASE_SECTION_HEADER_SIZE + padded);
    sc_le_wr_u32(h, tag);
    sc_le_wr_u64(h + 8, n);
    if (n > 0u) {
        memcpy(h + SC_CASE_SECTION_HEADER_SIZE, payload, n);
    }
    sc_le_wr_u32(h + 16, sc_crc32(h + SC_CASE_SECTION_HEADER_SIZE, n));
    sc_le_wr_u32(h + 60, sc_crc32(h, 60));
    sc_le_wr_u64(buf + 16, need);
    sc_le_wr_u32(buf + 24, sc_le_rd_u32(buf + 24) + 1u);
    sc_le_wr_u32(buf + 60, sc_crc32(buf, 60));
    *size = need;
    return SC_OK;
}
