/*
 * sc_case.h: the patient case file (format v1, docs/case-format.md): constants, the validating
 * loader and a pure writer.
 *
 * A case is one immutable little-endian byte image: a 64-byte file header, then 64-byte aligned
 * sections, each a 64-byte section header (tag, payload size, payload CRC-32, header CRC-32) and
 * its payload: INFO (name, description), GRID (dimensions, spacing, origin, orientation), VOXL
 * (8-bit intensities), LABL (label map, same grid), MATL (material per label), MESH (mesh box in
 * volume mm and node counts), XFRM (probe calibration, mannequin registration). It holds voxels
 * and geometry only: there is no field for any patient identity.
 *
 * Loader: sc_case_load() validates every byte that the engine will use against config/ limits
 * (sizes overflow-safe, CRCs, finite and rigid transforms, labels inside the material table,
 * mesh box inside the volume, node counts within limits) and only then fills the caller's
 * sc_case view; on any error the view is left untouched, so the running case stays. The view
 * points into the bytes (voxels, labels, name, description are not copied): keep the bytes
 * mapped while the view is used.
 *
 * Orientation: GRID stores the direction cosines of the grid axes in the mannequin (patient)
 * frame. The loader accepts any rigid orientation and folds it into the registration:
 * tracker_to_volume = R(orientation)^T o tracker_to_patient, so the engine always works in the
 * axis-aligned volume frame of sc_volume.h. A non-rigid orientation is SC_ERR_CASE_TRANSFORM.
 *
 * Thread and memory rules: pure functions over caller memory, reentrant. Never allocates,
 * never calls the OS, never writes to the case bytes.
 */
#ifndef SC_CASE_H
#define SC_CASE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_case_drive.h"
#include "sc_case_surf.h"
#include "sc_config.h"
#include "sc_hal_storage.h"
#include "sc_mesh.h"
#include "sc_pose.h"
#include "sc_volume.h"

/* ---- format constants (v1) --------------------------------------------------------------- */
#define SC_CASE_MAGIC                "\x89SCASE\r\n" /* 8 bytes, PNG-style: catches text-mode mangling */
#define SC_CASE_MAGIC_LEN            8u
#define SC_CASE_VERSION              1u
#define SC_CASE_HEADER_SIZE          64u
#define SC_CASE_SECTION_HEADER_SIZE  64u
#define SC_CASE_ALIGN                64u
#define SC_CASE_NAME_LEN             64u  /* bytes incl. the terminating NUL */
#define SC_CASE_DESCRIPTION_LEN      960u /* bytes incl. the terminating NUL */
#define SC_CASE_MATERIAL_RECORD_SIZE 16u
/* Tolerance of the rigidity check of transforms and orientation (float32 round-off of a
 * rotation written from doubles is ~1e-7; 1e-4 refuses anything visibly non-rigid). */
#define SC_CASE_RIGID_TOL 1.0e-4f

/* Physical plausibility (a value outside is refused by name, however finite): a voxel is at
 * most 50 mm, the volume, the mesh box and every translation lie within 5 m of the origin,
 * Young's modulus is 1 Pa .. 100 GPa (vein lumen .. ten times cortical bone), density
 * 10 .. 25,000 kg/m^3. */
#define SC_CASE_MAX_SPACING_MM 50.0f
#define SC_CASE_MAX_EXTENT_MM  5000.0f
#define SC_CASE_MIN_E_PA       1.0f
#define SC_CASE_MAX_E_PA       1.0e11f
#define SC_CASE_MIN_DENSITY    10.0f
#define SC_CASE_MAX_DENSITY    25000.0f

/* Section tags: four ASCII characters read as a little-endian u32. */
#define SC_CASE_TAG(a, b, c, d)                                                                    \
    ((uint32_t)(a) | ((uint32_t)(b) << 8) | ((uint32_t)(c) << 16) | ((uint32_t)(d) << 24))
#define SC_CASE_TAG_INFO      SC_CASE_TAG('I', 'N', 'F', 'O')
#define SC_CASE_TAG_GRID      SC_CASE_TAG('G', 'R', 'I', 'D')
#define SC_CASE_TAG_VOXL      SC_CASE_TAG('V', 'O', 'X', 'L')
#define SC_CASE_TAG_LABL      SC_CASE_TAG('L', 'A', 'B', 'L')
#define SC_CASE_TAG_MATL      SC_CASE_TAG('M', 'A', 'T', 'L')
#define SC_CASE_TAG_MESH      SC_CASE_TAG('M', 'E', 'S', 'H')
#define SC_CASE_TAG_XFRM      SC_CASE_TAG('X', 'F', 'R', 'M')
#define SC_CASE_SECTION_COUNT 7u

/* Payload sizes of the fixed-size sections. */
#define SC_CASE_INFO_SIZE      (SC_CASE_NAME_LEN + SC_CASE_DESCRIPTION_LEN) /* 1024 */
#define SC_CASE_GRID_SIZE      80u /* dim[3], usable depth, spacing[3], origin[3], orient[9], flags */
#define SC_CASE_MESH_SIZE      40u /* f32 origin[3], size[3], u32 nx, ny, nz, u32 0 */
#define SC_CASE_XFRM_SIZE      96u /* image->probe, tracker->patient: 12 f32 each (r[9], t[3]) */
#define SC_CASE_MATL_HEAD_SIZE 8u  /* u32 count, u32 0; then count 16-byte records */

_Static_assert(SC_MAX_LABELS >= 9u && SC_MAX_LABELS <= 256u, "labels are 8-bit");
_Static_assert(SC_MAX_VOLUME_DIM >= 2u, "volume needs at least 2 voxels per axis");
_Static_assert(SC_MAX_VOLUME_VOXELS <=
                   (uint64_t)SC_MAX_VOLUME_DIM * SC_MAX_VOLUME_DIM * SC_MAX_VOLUME_DIM,
               "voxel limit above what the dimension limit allows");
_Static_assert(SC_CASE_INFO_SIZE == 1024u, "INFO payload size");

/* GRID imaging flags (u32 at GRID offset 76; other bits reserved, zero). */
#define SC_CASE_IMAGING_ENGINE_ACOUSTICS 1u /* the voxels hold echogenicity only: the engine adds
                                               attenuation, interfaces and TGC along the beam
                                               (sc_acoustics.h); clear: the volume holds them
                                               (real-patient volumes) */
#define SC_CASE_IMAGING_ENGINE_SPECKLE   2u /* the voxels hold mean echogenicity without speckle:
                                               the engine forms it from its scatterer field and
                                               the beam's PSF (sc_psf.h) */
#define SC_CASE_IMAGING_KNOWN (SC_CASE_IMAGING_ENGINE_ACOUSTICS | SC_CASE_IMAGING_ENGINE_SPECKLE)

/* GRID usable imaging depth (f32 at GRID offset 12, formerly reserved zero, so older files read
 * as "not stated"): how deep below the skin the image stays on the case's data, mm; 0: not
 * stated, else within [SC_CASE_MIN_DEPTH_MM, SC_CASE_MAX_DEPTH_MM] (SC_ERR_CASE_DEPTH). The
 * engine's imaging depth after a case swap never exceeds it. */
#define SC_CASE_MIN_DEPTH_MM 5.0f
#define SC_CASE_MAX_DEPTH_MM 500.0f

/* One material record per label value (index = label, config/sc_labels.h). */
typedef struct sc_case_material {
    float e_pa;          /* Young's modulus, Pa; finite, > 0 */
    float poisson;       /* Poisson ratio, [0, 0.5) */
    float density_kg_m3; /* finite, > 0 */
} sc_case_material;

/* The loaded case: a view into the case bytes plus small decoded copies (1 KiB or so). */
typedef struct sc_case {
    const char *name;        /* NUL-terminated, points into the bytes */
    const char *description; /* NUL-terminated, points into the bytes */
    sc_volume volume;        /* voxels and labels point into the bytes; labels never NULL */
    float orientation[9];    /* grid axes in the mannequin frame, row-major, as stored */
    uint32_t imaging_flags;  /* SC_CASE_IMAGING_* */
    float usable_depth_mm;   /* 0: not stated (see SC_CASE_MIN_DEPTH_MM) */
    uint32_t material_count; /* 1..SC_MAX_LABELS; every label value is < material_count */
    sc_case_material materials[SC_MAX_LABELS];
    sc_mesh_def mesh;            /* mesh box (volume frame, mm) and node counts */
    sc_xform image_to_probe;     /* probe calibration */
    sc_xform tracker_to_patient; /* mannequin registration as stored */
    sc_xform tracker_to_volume;  /* registration with the orientation folded in */
    uint64_t voxel_count;
    uint32_t case_id; /* CRC-32 over the file and section headers (without their
                       * own CRC fields; they hold the payload CRCs): identifies
                       * the case content */
    sc_case_surf surf; /* optional SURF section (console surfaces); surf.count 0: none */
    sc_case_drive drive; /* optional DRIV section (the vessel drive); drive.present 0: none */
} sc_case;

/* What the writer encodes. volume.voxels and volume.labels must both be non-NULL. */
typedef struct sc_case_def {
    const char *name;        /* < SC_CASE_NAME_LEN bytes, printable ASCII/UTF-8 */
    const char *description; /* < SC_CASE_DESCRIPTION_LEN bytes */
    sc_volume volume;
    float orientation[9];
    uint32_t imaging_flags; /* SC_CASE_IMAGING_* */
    float usable_depth_mm;  /* 0: not stated */
    uint32_t material_count;
    sc_case_material materials[SC_MAX_LABELS];
    sc_mesh_def mesh;
    sc_xform image_to_probe;
    sc_xform tracker_to_patient;
} sc_case_def;

/* Defaults: empty name, identity orientation and transforms, no volume, no materials, the
 * default mesh definition. O(1). */
sc_case_def sc_case_default_def(void);

/* Bytes the writer needs for def; 0 when def is unusable (NULL, dims product overflow).
 * O(1). Never allocates. */
size_t sc_case_encoded_size(const sc_case_def *def);

/* Encode def into buf[0..cap). Writes *out_size on success. The writer checks only what it
 * needs to produce a well-formed file (pointers, sizes, text lengths); it does NOT validate
 * semantics (spacing, labels, transforms): load the result with sc_case_load() for that, as
 * the case builder does. O(voxels) (two copies and CRCs), bounded by the dims of def.
 * Never allocates. Errors: SC_ERR_INVALID_ARG (NULL pointers, count above SC_MAX_LABELS),
 * SC_ERR_OVERFLOW (size does not fit size_t), SC_ERR_NO_SPACE (cap too small),
 * SC_ERR_CASE_TEXT (name or description too long). */
int sc_case_write(const sc_case_def *def, uint8_t *buf, size_t cap, size_t *out_size);

/* Validate the case image bytes[0..size) and, only if all of it is valid, fill *out.
 * O(size): CRC over every byte and one pass over the labels; bounded by SC_MAX_VOLUME_VOXELS.
 * Never allocates, never writes to bytes. Errors (first failing check wins, in file order):
 * SC_ERR_INVALID_ARG, SC_ERR_CASE_TRUNCATED, SC_ERR_CASE_MAGIC, SC_ERR_CASE_CRC,
 * SC_ERR_CASE_VERSION, SC_ERR_CASE_SECTION (missing, duplicated, unknown-size header),
 * SC_ERR_CASE_RESERVED, SC_ERR_CASE_SIZE, SC_ERR_CASE_TEXT, SC_ERR_CASE_DIMS,
 * SC_ERR_CASE_SPACING, SC_ERR_CASE_TRANSFORM, SC_ERR_CASE_MATERIAL, SC_ERR_CASE_LABEL,
 * SC_ERR_CASE_MESH_NODES, SC_ERR_CASE_MESH_BOX, SC_ERR_CASE_SURFACE, SC_ERR_CASE_DRIVE. */
int sc_case_load(const uint8_t *bytes, size_t size, sc_case *out);

/* ---- the same validation in bounded slices (a case switch while another case runs) --------
 * sc_case_check_begin() checks the framing (file header, every section header and its CRC,
 * sizes, padding, presence; O(sections), the payloads are not read); each
 * sc_case_check_step() then CRCs at most budget_bytes of payload (in file order) and, after the
 * last CRC, runs the label pass over at most the rest of the budget; sc_case_check_finish()
 * runs the remaining semantic checks (O(materials), no pass over the volume) and fills *out.
 * The three together accept exactly the files sc_case_load() accepts and fill the same view
 * (tests/unit/test_sc_case.c); the error of a file with several faults may differ (framing
 * faults are found before payload CRC faults). Never allocates; the check holds pointers into
 * bytes, which must stay mapped until finish. */
#ifndef SC_CASE_MAX_SECTIONS
#define SC_CASE_MAX_SECTIONS 64u /* sections a file may declare (7 known + unknown ones) */
#endif

typedef struct sc_case_check {
    const uint8_t *bytes;
    size_t size;
    int state;            /* 0 running, 1 every byte checked, < 0 the sc_err that refused it */
    uint32_t case_id;
    uint32_t sec_count;   /* sections declared */
    uint32_t sec_index;   /* section whose payload CRC is running */
    uint64_t sec_done;    /* bytes of it CRC'd */
    uint32_t crc;         /* running CRC of that payload */
    uint64_t sec_off[SC_CASE_MAX_SECTIONS]; /* payload offset, size and stored CRC, file order */
    uint64_t sec_size[SC_CASE_MAX_SECTIONS];
    uint32_t sec_crc[SC_CASE_MAX_SECTIONS];
    const uint8_t *known_p[SC_CASE_SECTION_COUNT]; /* the known sections, by tag index */
    uint64_t known_size[SC_CASE_SECTION_COUNT];
    const uint8_t *labels; /* LABL payload and the label pass's progress */
    uint64_t label_count;
    uint64_t label_done;
    uint8_t label_max;
    uint64_t bytes_done;  /* payload and label bytes checked so far */
} sc_case_check;

/* O(sections). Errors: SC_ERR_INVALID_ARG and the framing errors of sc_case_load. */
int sc_case_check_begin(sc_case_check *k, const uint8_t *bytes, size_t size);
/* O(budget_bytes) (a budget of 0 counts as 1). Returns 0 (more to do), 1 (every byte
 * checked), or the sticky error (SC_ERR_CASE_CRC, SC_ERR_INVALID_ARG, a begin error). */
int sc_case_check_step(sc_case_check *k, size_t budget_bytes);
/* O(materials). Fills *out only when valid. Errors: SC_ERR_STATE (steps not finished), the
 * sticky error, and every semantic error of sc_case_load. */
int sc_case_check_finish(const sc_case_check *k, sc_case *out);

/* The running case and the storage mapping that backs it. Zero-initialise (or
 * sc_case_slot_init) before first use. */
typedef struct sc_case_slot {
    const sc_storage_dev *dev; /* storage of the mapping below; NULL when empty */
    const uint8_t *data;
    size_t size;
    sc_case c; /* valid when loaded != 0 */
    int loaded;
    int last_error;   /* result of the last sc_case_slot_switch() */
    uint32_t refused; /* switches refused so far */
} sc_case_slot;

void sc_case_slot_init(sc_case_slot *s);

/* Switch the running case to `name` from dev: open (map) it, validate it with sc_case_load(),
 * and only if it is valid release the previous mapping and make it the running case. On any
 * error the new mapping is closed, the running case and its mapping stay untouched, `refused`
 * is counted. Not for frame time: O(file size) (sc_case_load), plus the storage open.
 * Never allocates. Errors: SC_ERR_INVALID_ARG, the storage's open errors (SC_ERR_NOT_FOUND,
 * SC_ERR_IO, ...), every sc_case_load() error. */
int sc_case_slot_switch(sc_case_slot *s, const sc_storage_dev *dev, const char *name);

/* Release the running case's mapping; the slot becomes empty. O(1) plus the storage close. */
void sc_case_slot_close(sc_case_slot *s);

/* Label histogram of a loaded case: counts[l] = voxels with label l, l < SC_MAX_LABELS.
 * O(voxels). Never allocates, cannot fail for a case from sc_case_load(). */
void sc_case_label_histogram(const sc_case *c, uint64_t counts[SC_MAX_LABELS]);

#endif /* SC_CASE_H */
