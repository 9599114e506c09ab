/*
 * sc_image.h: an imported 3D image of any element type, as doubles, with its geometry. Plain
 * C, also included from C++ (the DICOM reader). Host tool code.
 */
#ifndef SC_IMAGE_H
#define SC_IMAGE_H

#include <stdint.h>

typedef enum sc_elem_type {
    SC_ELEM_U8,
    SC_ELEM_I8,
    SC_ELEM_U16,
    SC_ELEM_I16,
    SC_ELEM_U32,
    SC_ELEM_I32,
    SC_ELEM_F32,
    SC_ELEM_F64
} sc_elem_type;

typedef struct sc_image {
    uint32_t dim[3];
    double spacing[3];
    double origin[3];
    double dir[9];     /* row-major; column a = direction of grid axis a */
    int anatomical;    /* 1: the file states a patient frame (DICOM, NRRD space RAS/LAS/LPS,
                        * MetaImage AnatomicalOrientation); the world is then LPS (the readers
                        * convert RAS and LAS) */
    double lps[9];     /* row-major; columns: world direction of patient Left, Posterior,
                        * Superior (identity: every reader gives LPS) */
    sc_elem_type type; /* element type of the file */
    double *data;      /* dim[0]*dim[1]*dim[2] values, x fastest (malloc'd) */
} sc_image;

#endif /* SC_IMAGE_H */
