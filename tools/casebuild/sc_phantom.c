/* sc_phantom.c: procedural ultrasound-like phantom cases, see sc_phantom.h. */
#include "sc_phantom.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_materials.h"

/* ---- extent of every phantom (volume frame, mm) ---------------------------------------- */
#define PH_X0     (-24.0f)
#define PH_Y0     (-20.0f)
#define PH_Z0     (-2.0f) /* 2 mm of gel above the skin at z = 0 */
#define PH_SIZE_X 48.0f
#define PH_SIZE_Y 40.0f
#define PH_SIZE_Z 48.0f

/* ---- deterministic PRNG: splitmix64 ----------------------------------------------------- */
static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* uniform in [-1, 1) from the top 24 bits */
static float urand(uint64_t *s)
{
    return (float)(splitmix64(s) >> 40) * (2.0f / 16777216.0f) - 1.0f;
}

/* ---- scene ------------------------------------------------------------------------------ */
typedef struct scene {
    sc_phantom_kind kind;
    sc_phantom_vessel v[2];
    int has_nerve;
    float nerve_x, nerve_z, nerve_a, nerve_b;
    float skin_mm;
} scene;

static void scene_init(scene *s, sc_phantom_kind kind)
{
    memset(s, 0, sizeof *s);
    s->kind = kind;
    s->has_nerve = 1;
    if (kind == SC_PHANTOM_NECK_IJV) {
        /* IJV: oval, lateral and a little superficial to the CCA, deep to the SCM. Typical
         * adult IJV 10-15 mm wide at rest, 1-2 cm deep; CCA 6-8 mm, rounder and stiffer. */
        s->v[0] = (sc_phantom_vessel){SC_LABEL_VEIN, -7.0f, 15.5f, 7.0f, 4.5f, 0.4f, 0.03f, 0};
        s->v[1] = (sc_phantom_vessel){SC_LABEL_ARTERY, 4.5f, 17.5f, 3.8f, 3.8f, 0.9f, 0.02f, 0};
        /* vagus nerve, posterior between them */
        s->nerve_x = -1.5f;
        s->nerve_z = 20.0f;
        s->nerve_a = 1.3f;
        s->nerve_b = 1.1f;
        s->skin_mm = 1.2f;
    } else {
        /* groin: CFV medial (10-12 mm), CFA lateral (8-9 mm), femoral nerve lateral to it */
        int dvt = kind == SC_PHANTOM_FEMORAL_DVT;
        /* the thrombosed vein is distended (rounder, larger, bulging medially) */
        s->v[0] = (sc_phantom_vessel){SC_LABEL_VEIN,
                                      dvt ? -6.5f : -5.5f,
                                      18.0f,
                                      dvt ? 6.5f : 6.0f,
                                      dvt ? 6.0f : 5.0f,
                                      0.4f,
                                      -0.02f,
                                      dvt};
        s->v[1] = (sc_phantom_vessel){SC_LABEL_ARTERY, 5.5f, 17.0f, 4.2f, 4.2f, 1.0f, -0.015f, 0};
        s->nerve_x = 13.0f;
        s->nerve_z = 16.0f;
        s->nerve_a = 3.0f;
        s->nerve_b = 1.5f;
        s->skin_mm = 1.5f;
    }
}

static float fat_bottom_mm(const scene *s, float x, float y)
{
    if (s->kind == SC_PHANTOM_NECK_IJV) {
        return 4.0f + 0.3f * sinf(x / 7.0f) + 0.2f * sinf(y / 9.0f);
    }
    return 9.0f + 1.0f * sinf(x / 8.0f) + 0.5f * sinf(y / 6.0f);
}

static float bone_top_mm(const scene *s, float x)
{
    if (s->kind == SC_PHANTOM_NECK_IJV) {
        return 35.0f + 0.03f * (x - 6.0f) * (x - 6.0f); /* vertebral transverse process */
    }
    return 38.0f + 0.025f * (x - 8.0f) * (x - 8.0f); /* femoral head / pubic ramus */
}

/* 0 outside the vessel, 1 in the wall, 2 in the lumen */
static int vessel_part(const sc_phantom_vessel *v, float x, float y, float z)
{
    float cx = v->x_mm + v->dx_per_mm * y;
    float dx = x - cx, dz = z - v->z_mm;
    float a = v->half_w_mm, b = v->half_d_mm;
    if ((dx * dx) / (a * a) + (dz * dz) / (b * b) > 1.0f) {
        return 0;
    }
    float ai = a - v->wall_mm, bi = b - v->wall_mm;
    return (dx * dx) / (ai * ai) + (dz * dz) / (bi * bi) > 1.0f ? 1 : 2;
}

/* Feature bits kept beside the label for the echo model. */
enum { F_WALL = 1, F_LUMEN = 2 };

static uint8_t label_at(const scene *s, float x, float y, float z, uint8_t *feat)
{
    *feat = 0;
    if (z < 0.0f) {
        return SC_LABEL_OUTSIDE;
    }
    if (z < s->skin_mm) {
        return SC_LABEL_SKIN;
    }
    if (z >= bone_top_mm(s, x)) {
        return SC_LABEL_BONE;
    }
    for (int i = 0; i < 2; i++) {
        int part = vessel_part(&s->v[i], x, y, z);
        if (part != 0) {
            if (part == 1) {
                *feat = F_WALL;
                return s->v[i].label;
            }
            *feat = F_LUMEN;
            return s->v[i].thrombosed ? (uint8_t)SC_LABEL_THROMBUS : s->v[i].label;
        }
    }
    if (s->has_nerve) {
        float dx = (x - s->nerve_x) / s->nerve_a, dz = (z - s->nerve_z) / s->nerve_b;
        if (dx * dx + dz * dz <= 1.0f) {
            return SC_LABEL_NERVE;
        }
    }
    const float fb = fat_bottom_mm(s, x, y);
    if (z < fb) {
        return SC_LABEL_FAT;
    }
    if (s->kind == SC_PHANTOM_NECK_IJV) {
        /* sternocleidomastoid: a lens under the subcutaneous fat */
        float u = (x + 3.0f) / 17.0f;
        float t = u * u < 1.0f ? 7.0f * sqrtf(1.0f - u * u) : 0.0f;
        if (z < fb + t) {
            return SC_LABEL_MUSCLE;
        }
        /* prevertebral / scalene muscle in the depth */
        if (z > 25.0f + 2.0f * sinf(x / 9.0f) + 0.4f * sinf(x / 2.9f + y / 7.0f)) {
            return SC_LABEL_MUSCLE;
        }
        return SC_LABEL_FAT; /* carotid sheath and loose connective tissue */
    }
    /* groin: iliopsoas lateral (oblique medial border), pectineus medial, deep muscle */
    /* the borders undulate (about 1 mm over 7-16 mm) so no straight edge shows in the image */
    if (x > 10.0f - 0.3f * (z - 12.0f) + 1.2f * sinf(z / 1.9f + y / 9.0f) &&
        z > fb + 1.0f + 0.8f * sinf(x / 2.3f)) {
        return SC_LABEL_MUSCLE;
    }
    if (x < -12.0f + 0.2f * (z - 20.0f) + 1.1f * sinf(z / 2.1f + 1.0f + y / 8.0f) &&
        z > 20.0f + 1.2f * sinf(x / 2.6f)) {
        return SC_LABEL_MUSCLE;
    }
    if (z > 27.0f + 1.5f * sinf(x / 10.0f) + 0.6f * sinf(x / 2.4f + y / 6.0f)) {
        return SC_LABEL_MUSCLE;
    }
    return SC_LABEL_FAT;
}

/* ---- separable box blur (two passes ~ a Gaussian), along one axis, in place ------------- */
static void blur_axis(float *f, const uint32_t dim[3], int axis, uint32_t radius, float *line)
{
    if (radius == 0u) {
        return;
    }
    const size_t stride = axis == 0 ? 1u : axis == 1 ? (size_t)dim[0] : (size_t)dim[0] * dim[1];
    const uint32_t n = dim[axis];
    const uint32_t o1 = axis == 0 ? dim[1] : dim[0];
    const uint32_t o2 = axis == 2 ? dim[1] : dim[2];
    const float inv = 1.0f / (float)(2u * radius + 1u);
    for (uint32_t b = 0; b < o2; b++) {
        for (uint32_t a = 0; a < o1; a++) {
            size_t base;
            if (axis == 0) {
                base = ((size_t)b * dim[1] + a) * dim[0];
            } else if (axis == 1) {
                base = (size_t)b * dim[0] * dim[1] + a;
            } else {
                base = (size_t)b * dim[0] + a;
            }
            for (int pass = 0; pass < 2; pass++) {
                for (uint32_t i = 0; i < n; i++) {
                    line[i] = f[base + i * stride];
                }
                /* running sum with clamped (edge-replicated) borders */
                float sum = 0.0f;
                for (int64_t d = -(int64_t)radius; d <= (int64_t)radius; d++) {
                    int64_t j = d < 0 ? 0 : (d >= (int64_t)n ? (int64_t)n - 1 : d);
                    sum += line[j];
                }
                for (uint32_t i = 0; i < n; i++) {
                    f[base + i * stride] = sum * inv;
                    int64_t out = (int64_t)i - (int64_t)radius;
                    int64_t in = (int64_t)i + (int64_t)radius + 1;
                    out = out < 0 ? 0 : out;
                    in = in >= (int64_t)n ? (int64_t)n - 1 : in;
                    sum += line[in] - line[out];
                }
            }
        }
    }
}

static void normalize_unit_rms(float *f, size_t n)
{
    double ss = 0.0;
    for (size_t i = 0; i < n; i++) {
        ss += (double)f[i] * (double)f[i];
    }
    float inv = ss > 0.0 ? (float)(1.0 / sqrt(ss / (double)n)) : 1.0f;
    for (size_t i = 0; i < n; i++) {
        f[i] *= inv;
    }
}

/* Two-way attenuation in dB per mm at ~7.5 MHz (0.6-0.7 dB/cm/MHz soft tissue, blood ~0.15,
 * bone > 10; Duck 1990, Szabo "Diagnostic ultrasound imaging" table 4.x). */
static float atten_db_mm(uint8_t label, uint8_t feat)
{
    if (feat & F_LUMEN) {
        return label == SC_LABEL_THROMBUS ? 0.9f : 0.05f;
    }
    switch (label) {
    case SC_LABEL_OUTSIDE:
        return 0.0f;
    case SC_LABEL_FAT:
        return 0.9f;
    case SC_LABEL_BONE:
        return 12.0f;
    default:
        return 1.0f;
    }
}
#define PH_TGC_DB_MM 0.95f /* gain ramp that compensates average soft tissue */

/* Backscatter amplitude (relative) of a voxel before speckle. */
static float reflectivity(const scene *s, uint8_t label, uint8_t feat, float x, float y, float z,
                          float fibre, float fat_w)
{
    if (feat & F_WALL) {
        return label == SC_LABEL_ARTERY ? 3.2f : 1.1f;
    }
    if (feat & F_LUMEN) {
        if (label == SC_LABEL_THROMBUS) {
            /* echogenic, heterogeneous organising thrombus */
            float h = 0.55f + 0.25f * sinf(x * 1.3f + y * 0.4f) * sinf(z * 1.1f) + 0.2f * fibre;
            /* brighter than the tissue around (deep connective tissue 0.36, muscle 0.2) */
            return 1.5f * (h > 0.15f ? h : 0.15f);
        }
        return 0.012f; /* anechoic blood */
    }
    switch (label) {
    case SC_LABEL_OUTSIDE:
        return 0.0f;
    case SC_LABEL_SKIN:
        return 2.2f;
    case SC_LABEL_FAT: {
        const float fb = fat_bottom_mm(s, x, y);
        if (fabsf(z - fb) < 0.3f) {
            return 1.9f; /* superficial fascia / fascia lata: hyperechoic line */
        }
        if (z > fb) {
            /* deep loose connective tissue (carotid / femoral sheath): mid-grey, patchy */
            return 0.36f + 0.08f * fibre;
        }
        /* subcutaneous fat: hypoechoic lobules with thin, broken bright septa roughly
         * parallel to the skin */
        float w =
            z + 0.8f * sinf(x / 3.3f + 0.7f) + 0.6f * sinf(y / 4.1f) + 0.4f * sinf((x + y) / 2.3f);
        float band = floorf(w / 3.0f);
        float ph = w / 3.0f - band - 0.5f;
        float present = sinf(x / 2.9f + 2.1f * band) + 0.5f * sinf(y / 3.7f - band);
        float septum = present > 0.2f ? expf(-(ph * 3.0f) * (ph * 3.0f) / 0.06f) : 0.0f;
        return 0.26f + 0.9f * septum * (fat_w > 0.0f ? 1.0f : 0.4f);
    }
    case SC_LABEL_MUSCLE: {
        /* hypoechoic muscle with bright fibro-adipose septa along the fibres (y): dots in a
         * transverse view ("starry night"), lines in a longitudinal view */
        float t = fibre > 1.1f ? 0.9f * (fibre - 1.1f) : 0.0f;
        return 0.2f + t;
    }
    case SC_LABEL_NERVE: {
        /* honeycomb: dark fascicles in a bright epineurium */
        float c = cosf(x * 2.6f) * cosf(z * 2.6f);
        return c > 0.35f ? 0.35f : 1.3f;
    }
    case SC_LABEL_BONE:
        return 0.5f;
    case SC_LABEL_VEIN:
    case SC_LABEL_ARTERY:
    case SC_LABEL_THROMBUS:
    default:
        return 0.3f;
    }
}

static int interface_label(uint8_t l)
{
    return l == SC_LABEL_FAT || l == SC_LABEL_MUSCLE || l == SC_LABEL_NERVE;
}

sc_phantom_def sc_phantom_default_def(void)
{
    return (sc_phantom_def){
        .kind = SC_PHANTOM_NECK_IJV, .seed = 1u, .spacing_mm = 0.25f, .engine_acoustics = 0};
}

static const char *const kind_names[SC_PHANTOM_KIND_COUNT] = {"neck-ijv", "femoral", "femoral-dvt"};

int sc_phantom_kind_from_name(const char *name)
{
    for (int k = 0; k < (int)SC_PHANTOM_KIND_COUNT; k++) {
        if (strcmp(name, kind_names[k]) == 0) {
            return k;
        }
    }
    return -1;
}

const char *sc_phantom_kind_name(sc_phantom_kind kind)
{
    return (unsigned)kind < SC_PHANTOM_KIND_COUNT ? kind_names[kind] : "?";
}

void sc_phantom_free(sc_phantom *p)
{
    if (p != NULL) {
        free(p->voxels);
        free(p->labels);
        p->voxels = NULL;
        p->labels = NULL;
    }
}

int sc_phantom_generate(const sc_phantom_def *pd, sc_phantom *out)
{
    if (pd == NULL || out == NULL || (unsigned)pd->kind >= SC_PHANTOM_KIND_COUNT ||
        !isfinite(pd->spacing_mm) || pd->spacing_mm < 0.1f || pd->spacing_mm > 2.0f) {
        return SC_ERR_INVALID_ARG;
    }
    memset(out, 0, sizeof *out);
    scene s;
    scene_init(&s, pd->kind);
    const float sp = pd->spacing_mm;
    uint32_t dim[3] = {(uint32_t)lrintf(PH_SIZE_X / sp), (uint32_t)lrintf(PH_SIZE_Y / sp),
                       (uint32_t)lrintf(PH_SIZE_Z / sp)};
    const size_t n = (size_t)dim[0] * dim[1] * dim[2];
    uint8_t *labels = malloc(n);
    uint8_t *feats = malloc(n);
    uint8_t *vox = malloc(n);
    float *re = malloc(n * sizeof(float));
    float *im = malloc(n * sizeof(float));
    float *fib = malloc(n * sizeof(float));
    uint32_t maxdim = dim[0] > dim[1] ? dim[0] : dim[1];
    maxdim = maxdim > dim[2] ? maxdim : dim[2];
    float *line = malloc(maxdim * sizeof(float));
    if (!labels || !feats || !vox || !re || !im || !fib || !line) {
        free(labels);
        free(feats);
        free(vox);
        free(re);
        free(im);
        free(fib);
        free(line);
        return SC_ERR_NO_SPACE;
    }

    /* 1. labels, exact and analytic, at voxel centres */
    for (uint32_t k = 0; k < dim[2]; k++) {
        float z = PH_Z0 + sp * (float)k;
        for (uint32_t j = 0; j < dim[1]; j++) {
            float y = PH_Y0 + sp * (float)j;
            for (uint32_t i = 0; i < dim[0]; i++) {
                float x = PH_X0 + sp * (float)i;
                size_t idx = i + (size_t)dim[0] * (j + (size_t)dim[1] * k);
                labels[idx] = label_at(&s, x, y, z, &feats[idx]);
            }
        }
    }

    /* 2. noise fields: complex speckle and the muscle fibre field (long along y). The
     * scatterers are white at the voxel (0.25 mm) in x and z, the engine's trilinear sampling
     * being the point spread there (a 7.5 MHz linear probe's cell, about 0.3 mm axial and
     * 0.4 mm lateral: test_bscan_phantoms measures 0.41 / 0.44 mm in the image, 0.70 / 0.72
     * with the former 0.75 mm box blur); 1.25 mm in elevation (y), the slice thickness, so the
     * speckle decorrelates over about a millimetre when the probe moves out of plane. The field
     * lives in the rest configuration: the engine carries it with the deformation. */
    uint64_t rng = pd->seed * 0x2545F4914F6CDD1Dull + (uint64_t)pd->kind;
    for (size_t i = 0; i < n; i++) {
        re[i] = urand(&rng);
        im[i] = urand(&rng);
        fib[i] = urand(&rng);
    }
    const uint32_t rx = (uint32_t)(0.2f / sp), ry = (uint32_t)lrintf(0.5f / sp),
                   rz = (uint32_t)(0.15f / sp);
    blur_axis(re, dim, 0, rx, line);
    blur_axis(re, dim, 1, ry, line);
    blur_axis(re, dim, 2, rz, line);
    blur_axis(im, dim, 0, rx, line);
    blur_axis(im, dim, 1, ry, line);
    blur_axis(im, dim, 2, rz, line);
    blur_axis(fib, dim, 0, (uint32_t)lrintf(0.25f / sp), line);
    blur_axis(fib, dim, 1, (uint32_t)lrintf(3.0f / sp), line);
    blur_axis(fib, dim, 2, (uint32_t)lrintf(0.25f / sp), line);
    normalize_unit_rms(re, n);
    normalize_unit_rms(im, n);
    normalize_unit_rms(fib, n);
    /* Rayleigh amplitude, normalised to unit mean square; with the engine's speckle the voxels
     * hold the mean (the engine's scatterers and PSF give the texture) */
    for (size_t i = 0; i < n; i++) {
        re[i] = pd->engine_speckle ? 1.0f : sqrtf(0.5f * (re[i] * re[i] + im[i] * im[i]));
    }

    /* 3. echo amplitude per voxel: reflectivity x speckle, plus specular interfaces.
     * Smooth anatomy: a voxel on a boundary (a face neighbour of another label or part) takes
     * the mean reflectivity of 3 x 3 x 3 points inside it (anti-aliased edges, no voxel
     * staircase); the fascia (an interface across the beam within fascia_r) is a band of its
     * own, blurred over about 0.3 mm before it is added, so it runs as a smooth curve. */
    const int fascia_r = (int)lrintf(0.4f / sp) > 0 ? (int)lrintf(0.4f / sp) : 1;
    float *fas = calloc(n, sizeof(float));
    if (fas == NULL) {
        free(labels);
        free(feats);
        free(vox);
        free(re);
        free(im);
        free(fib);
        free(line);
        return SC_ERR_NO_SPACE;
    }
    const size_t sy = dim[0], sz = (size_t)dim[0] * dim[1];
    for (uint32_t k = 0; k < dim[2]; k++) {
        float z = PH_Z0 + sp * (float)k;
        for (uint32_t j = 0; j < dim[1]; j++) {
            float y = PH_Y0 + sp * (float)j;
            for (uint32_t i = 0; i < dim[0]; i++) {
                float x = PH_X0 + sp * (float)i;
                size_t idx = i + (size_t)dim[0] * (j + (size_t)dim[1] * k);
                uint8_t l = labels[idx];
                const float fat_w = im[idx] > -0.3f ? 1.0f : 0.0f;
                int edge = 0;
                if (i > 0u && i + 1u < dim[0] && j > 0u && j + 1u < dim[1] && k > 0u &&
                    k + 1u < dim[2]) {
                    const size_t nb[6] = {idx - 1u, idx + 1u, idx - sy, idx + sy, idx - sz,
                                          idx + sz};
                    for (int q = 0; q < 6 && !edge; q++) {
                        edge = labels[nb[q]] != l || feats[nb[q]] != feats[idx];
                    }
                }
                float r;
                if (edge) {
                    float acc = 0.0f;
                    for (int c = 0; c < 27; c++) {
                        const float px = x + sp * ((float)(c % 3) - 1.0f) / 3.0f,
                                    py = y + sp * ((float)((c / 3) % 3) - 1.0f) / 3.0f,
                                    pz = z + sp * ((float)(c / 9) - 1.0f) / 3.0f;
                        uint8_t f2;
                        const uint8_t l2 = label_at(&s, px, py, pz, &f2);
                        acc += reflectivity(&s, l2, f2, px, py, pz, fib[idx], fat_w);
                    }
                    r = acc / 27.0f;
                } else {
                    r = reflectivity(&s, l, feats[idx], x, y, z, fib[idx], fat_w);
                }
                /* hyperechoic fascia: a tissue interface across the beam within fascia_r */
                if (interface_label(l) && feats[idx] == 0u) {
                    for (int d = 1; d <= fascia_r; d++) {
                        if ((int64_t)k - d >= 0) {
                            uint8_t u = labels[idx - (size_t)d * sz];
                            if (u != l && interface_label(u)) {
                                fas[idx] = 1.6f;
                                break;
                            }
                        }
                        if ((uint64_t)k + (uint64_t)d < dim[2]) {
                            uint8_t u = labels[idx + (size_t)d * sz];
                            if (u != l && interface_label(u)) {
                                fas[idx] = 1.6f;
                                break;
                            }
                        }
                    }
                }
                /* bright cortex at the bone surface */
                if (l == SC_LABEL_BONE && k > 0u && z - bone_top_mm(&s, x) < 0.8f) {
                    r = 7.0f;
                }
                im[idx] = r; /* im is not needed past this point */
            }
        }
    }
    const uint32_t fr = (uint32_t)lrintf(0.15f / sp) > 0u ? (uint32_t)lrintf(0.15f / sp) : 1u;
    blur_axis(fas, dim, 0, fr, line);
    blur_axis(fas, dim, 1, fr, line);
    blur_axis(fas, dim, 2, fr, line);
    for (size_t i = 0; i < n; i++) {
        /* no fascia inside bone's cortex */
        fib[i] = (labels[i] == SC_LABEL_BONE ? im[i] : im[i] + fas[i]) * re[i];
    }
    free(fas);

    /* 4. attenuation along the beam (+z) with TGC; log compression to 8 bits */
    const float dr_db = 50.0f;  /* displayed dynamic range */
    const float ref_amp = 9.5f; /* amplitude shown as white: soft tissue lands near 100 */
    for (uint32_t j = 0; j < dim[1]; j++) {
        for (uint32_t i = 0; i < dim[0]; i++) {
            float loss_db = 0.0f;
            for (uint32_t k = 0; k < dim[2]; k++) {
                float z = PH_Z0 + sp * (float)k;
                size_t idx = i + (size_t)dim[0] * (j + (size_t)dim[1] * k);
                /* with the engine's acoustics the voxels hold echogenicity alone */
                float gain_db =
                    pd->engine_acoustics ? 0.0f : (z > 0.0f ? PH_TGC_DB_MM * z : 0.0f) - loss_db;
                float a = fib[idx] * powf(10.0f, gain_db / 20.0f) + 0.004f; /* noise floor */
                float db = 20.0f * log10f(a / ref_amp);
                float g = 255.0f * (db + dr_db) / dr_db;
                g = g < 0.0f ? 0.0f : (g > 255.0f ? 255.0f : g);
                vox[idx] = (uint8_t)lrintf(g);
                loss_db += atten_db_mm(labels[idx], feats[idx]) * sp;
            }
        }
    }
    free(feats);
    free(re);
    free(im);
    free(fib);
    free(line);

    /* 5. the case definition */
    out->voxels = vox;
    out->labels = labels;
    out->vessels[0] = s.v[0];
    out->vessels[1] = s.v[1];
    sc_case_def *d = &out->def;
    *d = sc_case_default_def();
    d->imaging_flags = (pd->engine_acoustics ? SC_CASE_IMAGING_ENGINE_ACOUSTICS : 0u) |
                       (pd->engine_speckle ? SC_CASE_IMAGING_ENGINE_SPECKLE : 0u);
    snprintf(out->name, sizeof out->name, "%s", kind_names[pd->kind]);
    const sc_phantom_vessel *vv = &s.v[0], *va = &s.v[1];
    const char *what =
        pd->kind == SC_PHANTOM_NECK_IJV
            ? "Phantom neck, transverse: internal jugular vein (oval, compressible) "
              "beside the common carotid artery (round, stiff) under the "
              "sternocleidomastoid; vagus nerve between them; vertebra deep."
        : pd->kind == SC_PHANTOM_FEMORAL
            ? "Phantom groin, transverse: common femoral vein (medial, compressible) "
              "and artery (lateral), femoral nerve, iliopsoas; normal."
            : "Phantom groin, transverse: common femoral vein distended and filled "
              "with echogenic thrombus (non-compressible: DVT), artery lateral.";
    snprintf(out->description, sizeof out->description,
             "%s\nProcedural (no patient data), seed %llu, %.3g mm voxels.\n"
             "Vein centre %.1f mm deep at x %.1f mm, %.1f x %.1f mm outer%s.\n"
             "Artery centre %.1f mm deep at x %.1f mm, %.1f x %.1f mm outer.\n"
             "Frames: x lateral, y along the body, z depth, skin at z = 0; vessels along y.",
             what, (unsigned long long)pd->seed, (double)sp, (double)vv->z_mm, (double)vv->x_mm,
             (double)(2.0f * vv->half_w_mm), (double)(2.0f * vv->half_d_mm),
             vv->thrombosed ? ", lumen thrombosed" : "", (double)va->z_mm, (double)va->x_mm,
             (double)(2.0f * va->half_w_mm), (double)(2.0f * va->half_d_mm));
    d->name = out->name;
    d->description = out->description;
    for (int a = 0; a < 3; a++) {
        d->volume.dim[a] = dim[a];
        d->volume.spacing_mm[a] = sp;
    }
    d->volume.origin_mm[0] = PH_X0;
    d->volume.origin_mm[1] = PH_Y0;
    d->volume.origin_mm[2] = PH_Z0;
    d->volume.voxels = vox;
    d->volume.labels = labels;
    /* usable imaging depth: the data's depth below the skin (z = 0) less 6 mm (a press of the
     * host simulator's scripts, 8 mm, then still ends 2 mm inside), whole mm; the engine's
     * default imaging depth on this case never exceeds it */
    d->usable_depth_mm = floorf(PH_Z0 + (float)(dim[2] - 1u) * sp - 6.0f);
    static const sc_case_material mats[] = {
#define PH_MAT_(label, e, nu, rho) {(e), (nu), (rho)},
        SC_MATERIAL_LIST(PH_MAT_)
#undef PH_MAT_
    };
    _Static_assert(sizeof mats / sizeof mats[0] == SC_LABEL_COUNT, "one material per label");
    d->material_count = SC_LABEL_COUNT;
    memcpy(d->materials, mats, sizeof mats);
    /* mesh box around the vessels, from the skin down to above the bone. Across (x) it spans
     * 46 mm, wider than the 38 mm image with the probe over the vessels: with the former
     * 30 mm box the image's edges sampled undeformed tissue beyond the mesh and a flat press
     * bent the shallow layers into a U there. The centre stays where it was (x -2 mm on the
     * neck, 0 in the groin: the probe's place in the press scripts and tests); the cells stay
     * 1.3 mm (24 nodes over 30 mm before): 34 nodes over 44 mm (neck, -24..20, the volume's
     * edge), 36 over 46 mm (groin), 1.42x / 1.5x the nodes. */
    const int neck = pd->kind == SC_PHANTOM_NECK_IJV;
    d->mesh.nx = neck ? 34u : 36u;
    d->mesh.ny = 12u;
    d->mesh.nz = 12u;
    d->mesh.origin_mm[0] = neck ? -24.0f : -23.0f;
    d->mesh.size_mm[0] = neck ? 44.0f : 46.0f;
    d->mesh.size_mm[2] = neck ? 30.0f : 32.0f;
    /* 30 mm across the probe's 10 mm face (y, its elevation axis): with 20 mm the box's
     * roller sides stood 5 mm beside the face and confined the tissue under a deep press
     * (24 mm of 32: the column under the face had nowhere to go but two 5 mm strips; its
     * tets inverted by the thousand, a muscle node passed the fixed bottom, and the tangled
     * MSDS flung nodes past the guard's bound at the lift) */
    d->mesh.origin_mm[1] = -15.0f;
    d->mesh.size_mm[1] = 30.0f;
    d->mesh.origin_mm[2] = 0.0f;
    /* image frame = probe frame. The mannequin's tracker frame has Z up out of the body
     * (as the tracker emulator and a real tracker on the mannequin report it) and y toward
     * the feet: tracker -> patient is a half turn about x, (x, y, z) -> (x, -y, -z), with the
     * tracker origin on the skin at the volume origin. */
    d->image_to_probe = sc_xform_identity();
    d->tracker_to_patient = sc_xform_identity();
    d->tracker_to_patient.r[4] = -1.0f;
    d->tracker_to_patient.r[8] = -1.0f;
    return SC_OK;
}

int sc_phantom_drive(sc_phantom_kind kind, sc_lumen_drive *out)
{
    if (out == NULL || (unsigned)kind >= (unsigned)SC_PHANTOM_KIND_COUNT) {
        return SC_ERR_INVALID_ARG;
    }
    sc_lumen_drive d = sc_lumen_drive_default(); /* 72 / min, 40 mmHg, arterial, 15 / min */
    switch (kind) {
    case SC_PHANTOM_NECK_IJV: /* a resting adult: 60 / min, 40 mmHg, 12 breaths / min */
        d.heart_rate_bpm = 60.0f;
        d.resp_rate_bpm = 12.0f;
        break;
    case SC_PHANTOM_FEMORAL: /* 78 / min, 45 mmHg (6.0 kPa), 16 breaths / min, smaller venous
                              * swing far from the thorax */
        d.heart_rate_bpm = 78.0f;
        d.pulse_pa = 6.0e3f;
        d.resp_rate_bpm = 16.0f;
        d.resp_pa = 0.3e3f;
        break;
    case SC_PHANTOM_FEMORAL_DVT: /* tachycardic (96 / min), 35 mmHg, 20 breaths / min */
        d.heart_rate_bpm = 96.0f;
        d.pulse_pa = 4.7e3f;
        d.resp_rate_bpm = 20.0f;
        d.resp_pa = 0.3e3f;
        break;
    case SC_PHANTOM_KIND_COUNT:
        return SC_ERR_INVALID_ARG;
    }
    *out = d;
    return SC_OK;
}
