/*
 * sc_casesurf.h: the case builder's SURF section (core/case/sc_case_surf.h): the body's skin
 * (the mesh's top face, k = 0) and the isosurface of each vessel label present in the mesh box
 * (sc_isosurface.h on the labels resampled to about 1 mm, smoothed), every vertex embedded
 * in the rest tet that holds it by barycentric weights, once per case. Host tool: allocates.
 */
#ifndef SC_CASESURF_H
#define SC_CASESURF_H

#include <stddef.h>
#include <stdint.h>

#include "sc_case.h"

/* Build the SURF payload of def into *payload (malloc'd, caller frees), *n bytes.
 * Errors: SC_ERR_INVALID_ARG, SC_ERR_NO_SPACE (malloc), mesh build errors. */
int sc_casesurf_build(const sc_case_def *def, uint8_t **payload, size_t *n);

#endif /* SC_CASESURF_H */
