/*
 * sc_case_surf.h: the optional SURF section of a case file (docs/case-format.md, "SURF"): the
 * surfaces the console draws (the body's skin and the vessels' isosurfaces), each vertex
 * embedded in a tet of the rest mesh by barycentric weights, computed once per case by the
 * case builder (tools/casebuild). The engine carries the vertices with the deformed mesh
 * (x = sum w_i x_i of the tet's deformed nodes) for the state stream (core/sc_state.h).
 *
 * Payload (little-endian, version 1):
 *   u32 version (1), u32 surface_count (1..SC_CASE_SURF_MAX_SURFACES), u32 vertex_count,
 *   u32 triangle_count;
 *   surface_count x 16 B: u8 label, u8 kind (SC_CASE_SURF_*), u16 0, u32 first_vertex,
 *       u32 vertex_count, u32 triangle_count   (vertex ranges consecutive, triangles in order);
 *   vertex_count x 16 B: u32 tet, f32 w0, w1, w2 (w3 = 1 - w0 - w1 - w2; each in [-0.05, 1.05]);
 *   triangle_count x 12 B: u32 a, b, c (global vertex indices inside the surface's own range).
 * A file without SURF is valid (the console then shows no surfaces). A SURF that breaks any
 * rule refuses the whole case (SC_ERR_CASE_SURFACE), like every other section.
 *
 * Pure functions over caller memory; never allocate, never call the OS.
 */
#ifndef SC_CASE_SURF_H
#define SC_CASE_SURF_H

#include <stddef.h>
#include <stdint.h>

#include "sc_mesh.h"

#define SC_CASE_TAG_SURF_U32 0x46525553u /* "SURF" */
#define SC_CASE_SURF_VERSION 1u
#ifndef SC_CASE_SURF_MAX_SURFACES
#define SC_CASE_SURF_MAX_SURFACES 8u
#endif
#ifndef SC_CASE_SURF_MAX_VERTICES
#define SC_CASE_SURF_MAX_VERTICES 8192u
#endif
#ifndef SC_CASE_SURF_MAX_TRIANGLES
#define SC_CASE_SURF_MAX_TRIANGLES 16384u
#endif
#define SC_CASE_SURF_HEAD_SIZE 16u
#define SC_CASE_SURF_REC_SIZE 16u
#define SC_CASE_SURF_VERTEX_SIZE 16u
#define SC_CASE_SURF_TRI_SIZE 12u
#define SC_CASE_SURF_WEIGHT_TOL 0.05f

enum { SC_CASE_SURF_SKIN = 0, SC_CASE_SURF_VESSEL = 1 };

typedef struct sc_case_surface {
    uint8_t label; /* config/sc_labels.h label the surface bounds (0 for the skin) */
    uint8_t kind;  /* SC_CASE_SURF_SKIN or SC_CASE_SURF_VESSEL */
    uint32_t first_vertex;
    uint32_t vertex_count;
    uint32_t first_triangle;
    uint32_t triangle_count;
} sc_case_surface;

/* The validated view (pointers into the case bytes). count == 0: the case has no SURF. */
typedef struct sc_case_surf {
    uint32_t count;
    sc_case_surface s[SC_CASE_SURF_MAX_SURFACES];
    uint32_t vertex_count;
    uint32_t triangle_count;
    const uint8_t *vertices;  /* vertex_count x 16 B */
    const uint8_t *triangles; /* triangle_count x 12 B */
} sc_case_surf;

/* Validate a SURF payload p[0..n) against a mesh of tet_count tets and fill *out.
 * O(vertices + triangles). Errors: SC_ERR_INVALID_ARG, SC_ERR_CASE_SURFACE (any rule above);
 * *out untouched on error. */
int sc_case_surf_parse(const uint8_t *p, uint64_t n, uint32_t tet_count, sc_case_surf *out);

/* Find the SURF section in a case image whose framing is already validated (sc_case_load did
 * it) and parse it; no SURF: out->count = 0 and SC_OK. O(sections + vertices + triangles). */
int sc_case_surf_find(const uint8_t *bytes, size_t size, const sc_mesh_def *mesh,
                      sc_case_surf *out);

/* Vertex v of the view: the tet and the four weights. O(1); v < vertex_count. */
void sc_case_surf_vertex(const sc_case_surf *s, uint32_t v, uint32_t *tet, float w[4]);
/* Triangle t: three global vertex indices. O(1); t < triangle_count. */
void sc_case_surf_triangle(const sc_case_surf *s, uint32_t t, uint32_t idx[3]);

/* Bytes of a SURF payload with these counts. O(1). */
uint64_t sc_case_surf_payload_size(uint32_t surfaces, uint32_t vertices, uint32_t triangles);

/* Append a section (tag, payload) to a valid case image buf[0..*size) of capacity cap:
 * rewrites the file header (section count, size, CRC). For builders; O(payload).
 * Errors: SC_ERR_INVALID_ARG, SC_ERR_NO_SPACE. */
int sc_case_append_section(uint8_t *buf, size_t cap, size_t *size, uint32_t tag,
                           const uint8_t *payload, size_t n);

#endif /* SC_CASE_SURF_H */
