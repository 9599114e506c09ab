/*
 * sc_phantom.h: procedural phantom cases that look like B-mode ultrasound, with exact label
 * maps (host tool library; allocates with malloc, not for the engine).
 *
 * Geometry is analytic (labels decided per voxel centre from ellipses, bands and surfaces);
 * the intensities are derived from the labels: tissue echogenicity, correlated speckle
 * (Rayleigh amplitude of a blurred complex noise field), muscle fibre texture, fat septa,
 * hyperechoic fascia and vessel walls, anechoic lumens, depth attenuation with time-gain
 * compensation (so fluid gives posterior acoustic enhancement and bone a shadow), then log
 * compression to 8 bits. Frame: sc_volume.h (x lateral, y along the body, z depth), skin at
 * z = 0, 2 mm of gel (label 0) above it, vessels along y.
 *
 * Deterministic: the same kind, seed and spacing give the same bytes (integer PRNG, float
 * arithmetic in a fixed order).
 */
#ifndef SC_PHANTOM_H
#define SC_PHANTOM_H

#include <stdint.h>

#include "sc_case.h"

typedef enum sc_phantom_kind {
    SC_PHANTOM_NECK_IJV = 0, /* internal jugular vein beside the common carotid, under the SCM */
    SC_PHANTOM_FEMORAL,      /* common femoral vein and artery in the groin, normal */
    SC_PHANTOM_FEMORAL_DVT,  /* the same with an occlusive echogenic thrombus in the vein */
    SC_PHANTOM_KIND_COUNT
} sc_phantom_kind;

typedef struct sc_phantom_def {
    sc_phantom_kind kind;
    uint64_t seed;
    float spacing_mm;     /* isotropic voxel size, 0.1 .. 2 mm */
    int engine_acoustics; /* 1: echogenicity only, no attenuation or TGC in the voxels; the
                             case asks the engine for them (SC_CASE_IMAGING_ENGINE_ACOUSTICS),
                             so shadows and enhancement follow the beam. 0 (default): baked */
    int engine_speckle;   /* 1: mean echogenicity without speckle in the voxels; the case asks
                             the engine to form it (SC_CASE_IMAGING_ENGINE_SPECKLE, sc_psf.h).
                             0 (default): speckle baked in the voxels */
} sc_phantom_def;

/* A vessel as generated (cross-section at y = 0; the centre drifts by dx_per_mm along y). */
typedef struct sc_phantom_vessel {
    uint8_t label;    /* SC_LABEL_VEIN or SC_LABEL_ARTERY */
    float x_mm, z_mm; /* centre at y = 0 */
    float half_w_mm;  /* outer semi-axis along x (wall included) */
    float half_d_mm;  /* outer semi-axis along z */
    float wall_mm;    /* wall thickness */
    float dx_per_mm;  /* lateral drift per mm of y */
    int thrombosed;   /* lumen filled with SC_LABEL_THROMBUS */
} sc_phantom_vessel;

typedef struct sc_phantom {
    sc_case_def def;              /* ready for sc_case_write(); voxels/labels point below */
    uint8_t *voxels;              /* malloc'd */
    uint8_t *labels;              /* malloc'd */
    sc_phantom_vessel vessels[2]; /* [0] vein, [1] artery */
    char name[SC_CASE_NAME_LEN];
    char description[SC_CASE_DESCRIPTION_LEN];
} sc_phantom;

/* Default definition: neck-ijv, seed 1, 0.25 mm voxels, acoustics baked into the voxels. */
sc_phantom_def sc_phantom_default_def(void);

/* Kind from its case name ("neck-ijv", "femoral", "femoral-dvt"); -1 when unknown. */
int sc_phantom_kind_from_name(const char *name);
const char *sc_phantom_kind_name(sc_phantom_kind kind);
/* The phantom's patient drive (its DRIV section, sc_case_drive.h): a plausible, different
 * heart rate per case (neck-ijv 60 / min, femoral 78 / min, femoral-dvt 96 / min: the DVT
 * patient is tachycardic), pulse pressure, arterial waveform, breathing and venous swing.
 * SC_ERR_INVALID_ARG for an unknown kind or NULL. */
int sc_phantom_drive(sc_phantom_kind kind, sc_lumen_drive *out);

/* Generate a phantom. O(voxels). Allocates the voxel and label arrays (free with
 * sc_phantom_free). Errors: SC_ERR_INVALID_ARG (kind, spacing), SC_ERR_NO_SPACE (malloc). */
int sc_phantom_generate(const sc_phantom_def *def, sc_phantom *out);
void sc_phantom_free(sc_phantom *p);

#endif /* SC_PHANTOM_H */
