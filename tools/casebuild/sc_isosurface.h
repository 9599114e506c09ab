/*
 * sc_isosurface.h: label isosurfaces of a case for a 3D view, as the paper builds them
 * (section VII): marching cubes on the label's indicator field, then Gaussian smoothing of
 * the surface (Taubin lambda/mu steps with Gaussian neighbour weights, so it does not shrink).
 * Host tool library: allocates with malloc.
 *
 * Marching cubes here polygonises each cube by walking its faces (the segments on each face
 * connect the edge crossings at their midpoints; the inside corners of an ambiguous face are
 * kept apart), so neighbouring cubes always agree on their shared face; each closed loop of
 * 4+ crossings is fanned around an added centre vertex, so the only edges two cubes share
 * are face segments and the surface is closed and 2-manifold. Triangles are wound
 * counter-clockwise seen from outside (normals point out of the label).
 */
#ifndef SC_ISOSURFACE_H
#define SC_ISOSURFACE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_volume.h"

typedef struct sc_iso_opts {
    int label;           /* label value whose boundary is extracted */
    float sigma_mm;      /* Gaussian width of the smoothing weights; 0: no smoothing */
    uint32_t iterations; /* lambda/mu smoothing steps */
} sc_iso_opts;

typedef struct sc_iso_mesh {
    float *xyz;    /* 3 per vertex, volume frame, mm */
    uint32_t *tri; /* 3 per triangle */
    size_t vertex_count;
    size_t triangle_count;
} sc_iso_mesh;

sc_iso_opts sc_iso_default_opts(void);
/* O(voxels of the label's bounding box). Errors: SC_ERR_INVALID_ARG, SC_ERR_NOT_FOUND (no
 * voxel has the label), SC_ERR_NO_SPACE (malloc). */
int sc_iso_extract(const sc_volume *vol, const sc_iso_opts *o, sc_iso_mesh *out);
void sc_iso_mesh_free(sc_iso_mesh *m);
int sc_iso_write_ply(const sc_iso_mesh *m, const char *path);
int sc_iso_write_obj(const sc_iso_mesh *m, const char *path);

#endif /* SC_ISOSURFACE_H */
