/* sc_lumen.c: vessel lumens as pressure-volume chambers; see sc_lumen.h. */
#include "sc_lumen.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_materials.h"

/* a region smaller than this (voxel noise at a vessel's edge) stays solid filler */
#define SC_LUMEN_MIN_TETS 4u
/* a lumen below this fraction of its rest volume has its walls in contact */
#define SC_LUMEN_CONTACT_RATIO 0.02f
#define SC_LUMEN_TWO_PI 6.28318530718f

void sc_lumen_laws_default(sc_lumen_law law[SC_MAX_LABELS])
{
    for (uint32_t i = 0; i < SC_MAX_LABELS; i++) {
        law[i].kind = (uint8_t)SC_LUMEN_NONE;
        law[i].hold_pa = 0.0f;
        law[i].bulk_pa = 0.0f;
    }
#define SC_LUMEN_ROW_(lab_, kind_, h_, b_)                                                     \
    law[(lab_)].kind = (uint8_t)(kind_);                                                       \
    law[(lab_)].hold_pa = (h_);                                                                \
    law[(lab_)].bulk_pa = (b_);
    SC_LUMEN_LIST(SC_LUMEN_ROW_)
#undef SC_LUMEN_ROW_
}

sc_lumen_drive sc_lumen_drive_default(void)
{
    sc_lumen_drive d;
    memset(&d, 0, sizeof d);
    d.heart_rate_bpm = SC_LUMEN_HEART_RATE_BPM;
    d.pulse_pa = SC_LUMEN_PULSE_PA;
    d.wave = (uint8_t)SC_LUMEN_WAVE_ARTERIAL;
    d.resp_rate_bpm = SC_LUMEN_RESP_RATE_BPM;
    d.resp_pa = SC_LUMEN_RESP_PA;
    d.valsalva_pa = SC_LUMEN_VALSALVA_PA;
    d.valsalva = 0u;
    return d;
}

int sc_lumen_drive_validate(const sc_lumen_drive *d)
{
    if (d == NULL || d->wave > (uint8_t)SC_LUMEN_WAVE_SINE || d->valsalva > 1u) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(d->heart_rate_bpm) || !isfinite(d->pulse_pa) || !isfinite(d->resp_rate_bpm) ||
        !isfinite(d->resp_pa) || !isfinite(d->valsalva_pa)) {
        return SC_ERR_NOT_FINITE;
    }
    const int hr_ok = !(d->heart_rate_bpm > 0.0f) ||
                      (d->heart_rate_bpm >= 20.0f && d->heart_rate_bpm <= 250.0f);
    const int rr_ok = !(d->resp_rate_bpm > 0.0f) ||
                      (d->resp_rate_bpm >= 4.0f && d->resp_rate_bpm <= 60.0f);
    if (!hr_ok || !rr_ok || d->heart_rate_bpm < 0.0f || d->resp_rate_bpm < 0.0f || !(d->pulse_pa >= 0.0f && d->pulse_pa <= 20.0e3f) ||
        !(d->resp_pa >= 0.0f && d->resp_pa <= 5.0e3f) ||
        !(d->valsalva_pa >= 0.0f && d->valsalva_pa <= 10.0e3f)) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* normalised arterial waveform at phase ph in [0, 1): 0 at diastole, 1 at the systolic peak */
static float wave_at(uint8_t wave, float ph)
{
    if (wave == (uint8_t)SC_LUMEN_WAVE_SINE) {
        return 0.5f - 0.5f * cosf(SC_LUMEN_TWO_PI * ph);
    }
    const float rise = 0.15f, tau = 0.3f;
    if (ph < rise) {
        return 0.5f - 0.5f * cosf(3.14159265359f * ph / rise);
    }
    const float tail = expf(-(1.0f - rise) / tau);
    const float run = (expf(-(ph - rise) / tau) - tail) / (1.0f - tail);
    const float u = (ph - 0.42f) / 0.04f; /* dicrotic notch and wave after it */
    return run + 0.08f * expf(-u * u) * (1.0f - ph);
}

static float wave_mean(uint8_t wave)
{
    float s = 0.0f;
    for (uint32_t i = 0; i < 256u; i++) {
        s += wave_at(wave, ((float)i + 0.5f) / 256.0f);
    }
    return s / 256.0f;
}

void sc_lumen_reset(sc_lumen *l)
{
    for (uint32_t k = 0; k < l->count; k++) {
        l->v[k].p_pa = 0.0f;
        l->v[k].drive_pa = 0.0f;
        l->v[k].v_mm3 = l->v[k].v0_mm3;
        for (uint32_t i = 0; i < SC_LUMEN_SLICES; i++) {
            l->v[k].s_p[i] = 0.0f;
        }
    }
    l->heart_phase = 0.0f;
    l->resp_phase = 0.0f;
    l->faces = 0u;
}

/* the tet's face opposite vertex f: its three nodes */
static void face_nodes(const uint32_t tet[4], uint32_t f, uint32_t out[3])
{
    uint32_t c = 0;
    for (uint32_t i = 0; i < 4u; i++) {
        if (i != f) {
            out[c++] = tet[i];
        }
    }
}

/* one sweep of the flood fill of region id over the tets of label lab (dir 0 up, 1 down);
 * returns the tets added */
static uint32_t fill_sweep(sc_lumen *l, const sc_mesh *m, uint8_t lab, uint8_t id, int down)
{
    uint32_t added = 0;
    const uint32_t nt = m->tet_count;
    for (uint32_t s = 0; s < nt; s++) {
        const uint32_t t = down ? nt - 1u - s : s;
        if (l->region[t] != 0u || m->tet_label[t] != lab) {
            continue;
        }
        for (uint32_t f = 0; f < 4u; f++) {
            const int32_t nb = m->tet_nbr[t][f];
            if (nb >= 0 && l->region[nb] == id) {
                l->region[t] = id;
                added++;
                break;
            }
        }
    }
    return added;
}

static const float *rest_axis(const sc_mesh *m, uint32_t axis)
{
    return axis == 0u ? m->rest_x : axis == 1u ? m->rest_y : m->rest_z;
}

/* the section of vessel v that tet t (of v) lies in: its rest centroid's slab along the axis */
static uint32_t slice_of(const sc_lumen_vessel *v, const sc_mesh *m, uint32_t t)
{
    if (v->slices <= 1u) {
        return 0u;
    }
    const float *r = rest_axis(m, v->axis);
    const uint32_t *tv = m->tet[t];
    const float c = 0.25f * (r[tv[0]] + r[tv[1]] + r[tv[2]] + r[tv[3]]);
    const float u = (c - v->lo_mm) / v->slab_mm;
    if (!(u > 0.0f)) {
        return 0u;
    }
    const uint32_t i = (uint32_t)u;
    return i < v->slices ? i : v->slices - 1u;
}

/* an artery's sections (sc_lumen.h "Sections"): the axis along which its rest extent is the
 * largest share of the box's, slabs of at least one cell, their rest volumes */
static void sections(sc_lumen *l, const sc_mesh *m, uint32_t k)
{
    sc_lumen_vessel *v = &l->v[k];
    v->slices = 1u;
    v->axis = 0u;
    v->lo_mm = 0.0f;
    v->slab_mm = 0.0f;
    for (uint32_t i = 0; i < SC_LUMEN_SLICES; i++) {
        v->s_v0[i] = 0.0f;
    }
    v->s_v0[0] = v->v0_mm3;
    if (v->kind != (uint8_t)SC_LUMEN_ARTERY || SC_LUMEN_SLICES < 2u) {
        return;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = 0; t < m->tet_count; t++) {
        if (l->region[t] != k + 1u) {
            continue;
        }
        for (uint32_t a = 0; a < 4u; a++) {
            const uint32_t q = m->tet[t][a];
            const float p[3] = {m->rest_x[q], m->rest_y[q], m->rest_z[q]};
            for (uint32_t d = 0; d < 3u; d++) {
                lo[d] = fminf(lo[d], p[d]);
                hi[d] = fmaxf(hi[d], p[d]);
            }
        }
    }
    const uint32_t cnt[3] = {m->nx, m->ny, m->nz};
    float best = -1.0f;
    for (uint32_t d = 0; d < 3u; d++) {
        const float box = m->cell_mm[d] * (float)(cnt[d] - 1u);
        const float share = box > 0.0f ? (hi[d] - lo[d]) / box : 0.0f;
        if (share > best) {
            best = share;
            v->axis = (uint8_t)d;
        }
    }
    const uint32_t d = v->axis;
    const float ext = hi[d] - lo[d];
    const float cells = m->cell_mm[d] > 0.0f ? ext / m->cell_mm[d] : 0.0f;
    uint32_t n = cells >= (float)SC_LUMEN_SLICES ? SC_LUMEN_SLICES : (uint32_t)(cells + 0.5f);
    if (n < 2u || !(ext > 0.0f)) {
        return;
    }
    v->slices = (uint8_t)n;
    v->lo_mm = lo[d];
    v->slab_mm = ext / (float)n;
    v->s_v0[0] = 0.0f;
    for (uint32_t t = 0; t < m->tet_count; t++) {
        if (l->region[t] == k + 1u) {
            v->s_v0[slice_of(v, m, t)] +=
                sc_mesh_tet_volume_mm3(m->rest_x, m->rest_y, m->rest_z, m->tet[t]);
        }
    }
}

void sc_lumen_split(uint32_t nx, uint32_t ny, uint32_t nz, uint32_t *ranges,
                    uint32_t *span_cells)
{
    SC_ASSERT(ranges != NULL && span_cells != NULL);
    const uint32_t cells = nx >= 2u && ny >= 2u && nz >= 2u ? (nx - 1u) * (ny - 1u) * (nz - 1u)
                                                            : 0u;
    *ranges = 1u;
    *span_cells = cells;
    if (SC_LUMEN_RANGES < 2u || nx * ny * nz <= SC_LUMEN_SERIAL_NODES || cells == 0u) {
        return;
    }
    /* cells of index c and c + d share a node only if d <= (nx - 1)(ny - 1) + (nx - 1) + 1:
     * a range of more cells keeps the ranges two apart from sharing one */
    const uint32_t near = (nx - 1u) * (ny - 1u) + nx + 1u;
    uint32_t span = (cells + SC_LUMEN_RANGES - 1u) / SC_LUMEN_RANGES;
    span = span > near ? span : near;
    /* an even number of ranges per phase (two workers: as many each), as sc_grid's cell ranges;
     * a count that is a multiple of four already keeps its span (re-cut, it could come out
     * below near: 2,790 of the meshes within the limits had ranges two apart sharing nodes, a
     * race between the workers' force passes) */
    const uint32_t n = (cells + span - 1u) / span;
    if (n >= 8u && n % 4u != 0u) {
        const uint32_t want = n / 4u * 4u;
        span = (cells + want - 1u) / want;
    }
    *ranges = (cells + span - 1u) / span;
    *span_cells = span;
}

/* the passes' ranges (sc_lumen.h "Workers"): by the mesh alone */
static void split(sc_lumen *l, const sc_mesh *m)
{
    uint32_t ranges = 1u, span = 0u;
    sc_lumen_split(m->nx, m->ny, m->nz, &ranges, &span);
    l->ranges = ranges;
    l->span_tets = ranges > 1u ? 5u * span : m->tet_count;
}

/* the faces of lumen tet t that its pressure loads, bit f for face f: tissue across (not the
 * hull, where the vessel goes on, nor a lumen, its own or another vessel's: a shared wall loaded
 * by both lumens let an artery's pressure drive the filler of a crushed vein beside it far off in
 * the robustness test) */
static uint32_t loaded_faces(const sc_lumen *l, const sc_mesh *m, uint32_t t)
{
    uint32_t faces = 0;
    for (uint32_t f = 0; f < 4u; f++) {
        const int32_t nb = m->tet_nbr[t][f];
        faces |= (nb >= 0 && l->region[nb] == 0u) ? 1u << f : 0u;
    }
    return faces;
}

#if SC_LUMEN_RANGES > 1
#define LIST_TET(e) ((e)&0xFFFFFu)
#define LIST_SLICE(e) (((e) >> 20) & 0x1Fu)
#define LIST_FACES(e) (((e) >> 25) & 0xFu)
_Static_assert(SC_MAX_TETS <= 0x100000u && SC_LUMEN_SLICES <= 32u,
               "a lumen tet's index and section fit their bits of sc_lumen.list");

static void range_tets(const sc_lumen *l, const sc_mesh *m, uint32_t r, uint32_t *t0, uint32_t *t1);

/* sc_lumen.list (sc_lumen.h): per range, its lumen tets in tet order */
static void build_list(sc_lumen *l, const sc_mesh *m)
{
    uint32_t n = 0;
    for (uint32_t r = 0; r < l->ranges; r++) {
        l->list_start[r] = n;
        uint32_t t0, t1;
        range_tets(l, m, r, &t0, &t1);
        for (uint32_t t = t0; t < t1; t++) {
            const uint8_t k = l->region[t];
            if (k == 0u) {
                continue;
            }
            l->list[n++] =
                t | (slice_of(&l->v[k - 1u], m, t) << 20) | (loaded_faces(l, m, t) << 25);
        }
    }
    l->list_start[l->ranges] = n;
}
#endif

int sc_lumen_init(sc_lumen *l, const sc_mesh *m, const sc_material_table *mat)
{
    if (l == NULL || m == NULL || mat == NULL || m->tet_count > SC_MAX_TETS) {
        return SC_ERR_INVALID_ARG;
    }
    memset(l->v, 0, sizeof l->v);
    l->count = 0u;
    l->dropped = 0u;
    sc_lumen_laws_default(l->law);
    l->drive = sc_lumen_drive_default();
    l->frame_s = 1.0f / (float)SC_FRAME_RATE_DEFAULT_HZ;
    l->wave_mean = wave_mean(l->drive.wave);
    l->enabled = 1u;
    l->pool = NULL;
    l->ranges = 1u;
    l->span_tets = m->tet_count;
    const uint32_t nt = m->tet_count;
    for (uint32_t t = 0; t < nt; t++) {
        if (m->tet_label[t] >= mat->count) {
            return SC_ERR_INVALID_ARG;
        }
    }
    memset(l->region, 0, nt);
    /* regions: a seed, then sweeps up and down until nothing is added (a tube along any axis
     * fills in a few sweeps); 0xFF marks a region that is not a vessel (too small, or past
     * SC_LUMEN_MAX) while the fill runs */
    for (uint32_t t = 0; t < nt; t++) {
        const uint8_t lab = m->tet_label[t];
        if (l->region[t] != 0u || l->law[lab].kind == (uint8_t)SC_LUMEN_NONE) {
            continue;
        }
        const uint8_t id = l->count < SC_LUMEN_MAX ? (uint8_t)(l->count + 1u) : 0xFEu;
        l->region[t] = id;
        uint32_t size = 1u;
        for (;;) {
            const uint32_t a = fill_sweep(l, m, lab, id, 0) + fill_sweep(l, m, lab, id, 1);
            size += a;
            if (a == 0u) {
                break;
            }
        }
        if (id == 0xFEu || size < SC_LUMEN_MIN_TETS) {
            l->dropped += id == 0xFEu ? 1u : 0u;
            for (uint32_t u = t; u < nt; u++) {
                l->region[u] = l->region[u] == id ? 0xFFu : l->region[u];
            }
            continue;
        }
        sc_lumen_vessel *v = &l->v[l->count++];
        v->label = lab;
        v->kind = l->law[lab].kind;
        v->tets = size;
        v->hold_pa = l->law[lab].hold_pa;
        v->bulk_pa = l->law[lab].bulk_pa;
    }
    for (uint32_t t = 0; t < nt; t++) {
        l->region[t] = l->region[t] >= 0xFEu ? 0u : l->region[t];
    }
    /* rest volumes and the softest material across each lumen's boundary */
    float emin[SC_LUMEN_MAX], numin[SC_LUMEN_MAX];
    for (uint32_t k = 0; k < SC_LUMEN_MAX; k++) {
        emin[k] = INFINITY;
        numin[k] = 0.0f;
    }
    for (uint32_t t = 0; t < nt; t++) {
        const uint8_t r = l->region[t];
        if (r == 0u) {
            continue;
        }
        l->v[r - 1u].v0_mm3 += sc_mesh_tet_volume_mm3(m->rest_x, m->rest_y, m->rest_z, m->tet[t]);
        for (uint32_t f = 0; f < 4u; f++) {
            const int32_t nb = m->tet_nbr[t][f];
            if (nb >= 0 && l->region[nb] != r) {
                const sc_material *q = &mat->row[m->tet_label[nb]];
                if (q->e_pa < emin[r - 1u]) {
                    emin[r - 1u] = q->e_pa;
                    numin[r - 1u] = q->poisson;
                }
            }
        }
    }
    for (uint32_t k = 0; k < l->count; k++) {
        sc_lumen_vessel *v = &l->v[k];
        /* the lumen's volume stiffness against its own pressure: the hole in the softest
         * material around (plane strain, mu_min = E / (2 (1 + nu))) in parallel with the
         * lumen's own tets (their plane-strain bulk modulus lambda + mu = E / (2 (1 + nu)
         * (1 - 2 nu)), the least they resist a uniform area change); c is its inverse */
        const sc_material *fill = &mat->row[v->label];
        const float k_fill =
            fill->e_pa / (2.0f * (1.0f + fill->poisson) * (1.0f - 2.0f * fill->poisson));
        const float k_hole = isfinite(emin[k]) ? emin[k] / (2.0f * (1.0f + numin[k])) : 0.0f;
        /* a lumen with nothing solid in or around it is bounded by its own law only */
        const float c = k_fill + k_hole > 0.0f ? 1.0f / (k_fill + k_hole) : 0.0f;
        v->theta = 1.0f / (1.0f + v->bulk_pa * c);
        sections(l, m, k);
    }
    split(l, m);
#if SC_LUMEN_RANGES > 1
    build_list(l, m);
#endif
    sc_lumen_reset(l);
    return SC_OK;
}

int sc_lumen_set_drive(sc_lumen *l, const sc_lumen_drive *d)
{
    if (l == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_lumen_drive_validate(d);
    if (rc != SC_OK) {
        return rc;
    }
    l->drive = *d;
    l->wave_mean = wave_mean(d->wave);
    return SC_OK;
}

void sc_lumen_set_valsalva(sc_lumen *l, int on)
{
    l->drive.valsalva = on != 0 ? 1u : 0u;
}

int sc_lumen_set_frame_s(sc_lumen *l, float frame_s)
{
    if (l == NULL || !isfinite(frame_s) || frame_s < 1e-4f || frame_s > 1.0f) {
        return SC_ERR_RANGE;
    }
    l->frame_s = frame_s;
    return SC_OK;
}

float sc_lumen_drive_pa(const sc_lumen *l, uint8_t kind)
{
    const sc_lumen_drive *d = &l->drive;
    if (kind == (uint8_t)SC_LUMEN_ARTERY) {
        if (d->heart_rate_bpm <= 0.0f) {
            return 0.0f;
        }
        return d->pulse_pa * (wave_at(d->wave, l->heart_phase) - l->wave_mean);
    }
    if (kind == (uint8_t)SC_LUMEN_VEIN) {
        float p = d->valsalva != 0u ? d->valsalva_pa : 0.0f;
        if (d->resp_rate_bpm > 0.0f) {
            /* inspiration (first half of the breath) lowers the venous pressure */
            p -= d->resp_pa * sinf(SC_LUMEN_TWO_PI * l->resp_phase);
        }
        return p;
    }
    return 0.0f;
}

static float advance(float phase, float rate_bpm, float dt_s)
{
    phase += rate_bpm * (1.0f / 60.0f) * dt_s;
    phase -= floorf(phase);
    return phase >= 0.0f && phase < 1.0f ? phase : 0.0f;
}

float sc_lumen_volume_mm3(const sc_lumen *l, const sc_mesh *m, const float *x, const float *y,
                          const float *z, uint32_t k)
{
    float vol = 0.0f;
    for (uint32_t t = 0; t < m->tet_count; t++) {
        if (l->region[t] == k) {
            vol += sc_mesh_tet_volume_mm3(x, y, z, m->tet[t]);
        }
    }
    return vol;
}

/* the law g(s) of sc_lumen.h */
static float law(const sc_lumen_vessel *v, float s)
{
    if (s >= 0.0f) {
        /* walls in contact: below SC_LUMEN_CONTACT_RATIO of the rest volume the lumen pushes
         * back again, with the law's own slope B (so theta bounds it too) */
        const float c = s - (1.0f - SC_LUMEN_CONTACT_RATIO);
        return v->hold_pa * tanhf(v->bulk_pa * s / v->hold_pa) + (c > 0.0f ? v->bulk_pa * c : 0.0f);
    }
    return v->bulk_pa * s;
}

#if SC_LUMEN_RANGES == 1
/* The first tet from t on with a region (nt if none): the frame's loops visit the lumens' tets
 * alone, in tet order (the sums' order unchanged), skipping the rest eight region bytes at a time
 * (the lumens are a few percent of the tets: the byte-per-tet scan was most of these passes).
 * Builds with more than one range read sc_lumen.list instead. */
static uint32_t next_region_tet(const uint8_t *region, uint32_t t, uint32_t nt)
{
    while (t + 8u <= nt) {
        uint64_t w;
        memcpy(&w, region + t, sizeof w);
        if (w != 0u) {
            break;
        }
        t += 8u;
    }
    while (t < nt && region[t] == 0u) {
        t++;
    }
    return t;
}
#endif

/* one frame's passes on the pool: the lumen, the mesh, the state, the pressures, the phase */
typedef struct lumen_job {
    const sc_lumen *l;
    float (*part_vol)[SC_LUMEN_MAX][SC_LUMEN_SLICES]; /* l->part_vol (NULL: the clear) */
    uint32_t *part_faces;                              /* l->part_faces (NULL: the clear) */
    const sc_mesh *m;
    sc_nodes *n;
    const float (*press)[SC_LUMEN_SLICES];
    uint32_t phase; /* 0: the even ranges, 1: the odd ones (forces, clear) */
    float *list_vol; /* sc_lumen.list_vol (the lists' builds) */
} lumen_job;

static void range_tets(const sc_lumen *l, const sc_mesh *m, uint32_t r, uint32_t *t0, uint32_t *t1)
{
    const uint32_t nt = m->tet_count;
    const uint32_t a = r * l->span_tets;
    *t0 = a < nt ? a : nt;
    *t1 = nt - *t0 > l->span_tets ? *t0 + l->span_tets : nt;
}

/* range r's volumes per vessel and section, in tet order */
static void job_volume(void *arg, uint32_t r)
{
    const lumen_job *j = (const lumen_job *)arg;
    const sc_lumen *l = j->l;
    const sc_mesh *m = j->m;
    const sc_nodes *n = j->n;
    float(*vol)[SC_LUMEN_SLICES] = j->part_vol[r];
    memset(vol, 0, sizeof j->part_vol[r]);
#if SC_LUMEN_RANGES > 1
    for (uint32_t i = l->list_start[r]; i < l->list_start[r + 1u]; i++) {
        const uint32_t e = l->list[i], t = LIST_TET(e);
        const float v = sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[t]);
        j->list_vol[i] = v;
        vol[l->region[t] - 1u][LIST_SLICE(e)] += v;
    }
#else
    uint32_t t0, t1;
    range_tets(l, m, r, &t0, &t1);
    for (uint32_t t = next_region_tet(l->region, t0, t1); t < t1;
         t = next_region_tet(l->region, t + 1u, t1)) {
        const uint8_t k = l->region[t];
        vol[k - 1u][slice_of(&l->v[k - 1u], m, t)] +=
            sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[t]);
    }
#endif
}

/* the pressure pk on face f of lumen tet tv (its wall tet across not crushed): a third of the
 * face's outward area vector times pk onto each of its nodes */
static inline void face_force(sc_nodes *n, const uint32_t *tv, uint32_t f, float pk)
{
    uint32_t q[3];
    face_nodes(tv, f, q);
    const float ax = n->x[q[1]] - n->x[q[0]], ay = n->y[q[1]] - n->y[q[0]],
                az = n->z[q[1]] - n->z[q[0]];
    const float bx = n->x[q[2]] - n->x[q[0]], by = n->y[q[2]] - n->y[q[0]],
                bz = n->z[q[2]] - n->z[q[0]];
    float cx = 0.5f * (ay * bz - az * by), cy = 0.5f * (az * bx - ax * bz),
          cz = 0.5f * (ax * by - ay * bx);
    /* outward: away from the tet's fourth vertex */
    const uint32_t o = tv[f];
    const float ox = n->x[q[0]] - n->x[o], oy = n->y[q[0]] - n->y[o], oz = n->z[q[0]] - n->z[o];
    if (cx * ox + cy * oy + cz * oz < 0.0f) {
        cx = -cx;
        cy = -cy;
        cz = -cz;
    }
    for (uint32_t a = 0; a < 3u; a++) {
        n->fx[q[a]] += pk * cx;
        n->fy[q[a]] += pk * cy;
        n->fz[q[a]] += pk * cz;
    }
}

/* face f of tet tv's nodes' external forces back to zero */
static inline void face_clear(sc_nodes *n, const uint32_t *tv, uint32_t f)
{
    uint32_t q[3];
    face_nodes(tv, f, q);
    for (uint32_t a = 0; a < 3u; a++) {
        n->fx[q[a]] = 0.0f;
        n->fy[q[a]] = 0.0f;
        n->fz[q[a]] = 0.0f;
    }
}

/* range 2 i + phase's boundary forces (its faces counted in part_faces) */
static void job_forces(void *arg, uint32_t i)
{
    const lumen_job *j = (const lumen_job *)arg;
    const sc_lumen *l = j->l;
    const sc_mesh *m = j->m;
    sc_nodes *n = j->n;
    const uint32_t r = 2u * i + j->phase;
    uint32_t faces = 0;
#if SC_LUMEN_RANGES > 1
    for (uint32_t e = l->list_start[r]; e < l->list_start[r + 1u]; e++) {
        const uint32_t w = l->list[e], t = LIST_TET(w);
        const uint32_t *tv = m->tet[t];
        if (!(j->list_vol[e] > 0.0f)) {
            continue; /* an inverted (crushed) lumen tet: its faces have no outward side */
        }
        const float pk = j->press[l->region[t] - 1u][LIST_SLICE(w)];
        for (uint32_t f = 0; f < 4u; f++) {
            /* the loaded faces (loaded_faces), whose wall tet across is not crushed */
            if ((LIST_FACES(w) & (1u << f)) == 0u ||
                !(sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[m->tet_nbr[t][f]]) > 0.0f)) {
                continue;
            }
            face_force(n, tv, f, pk);
            faces++;
        }
    }
#else
    uint32_t t0, t1;
    range_tets(l, m, r, &t0, &t1);
    for (uint32_t t = next_region_tet(l->region, t0, t1); t < t1;
         t = next_region_tet(l->region, t + 1u, t1)) {
        const uint8_t rg = l->region[t];
        const float pk = j->press[rg - 1u][slice_of(&l->v[rg - 1u], m, t)];
        const uint32_t *tv = m->tet[t];
        if (!(sc_mesh_tet_volume_mm3(n->x, n->y, n->z, tv) > 0.0f)) {
            continue; /* an inverted (crushed) lumen tet: its faces have no outward side */
        }
        const uint32_t loaded = loaded_faces(l, m, t);
        for (uint32_t f = 0; f < 4u; f++) {
            if ((loaded & (1u << f)) == 0u ||
                !(sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[m->tet_nbr[t][f]]) > 0.0f)) {
                continue; /* not loaded, or the wall tet across is crushed: no face to push on */
            }
            face_force(n, tv, f, pk);
            faces++;
        }
    }
#endif
    j->part_faces[r] = faces;
}

/* range 2 i + phase's boundary nodes' external forces back to zero */
static void job_clear(void *arg, uint32_t i)
{
    const lumen_job *j = (const lumen_job *)arg;
    const sc_lumen *l = j->l;
    const sc_mesh *m = j->m;
    sc_nodes *n = j->n;
    const uint32_t r = 2u * i + j->phase;
#if SC_LUMEN_RANGES > 1
    for (uint32_t e = l->list_start[r]; e < l->list_start[r + 1u]; e++) {
        const uint32_t w = l->list[e];
        for (uint32_t f = 0; f < 4u; f++) {
            if ((LIST_FACES(w) & (1u << f)) != 0u) {
                face_clear(n, m->tet[LIST_TET(w)], f);
            }
        }
    }
#else
    uint32_t t0, t1;
    range_tets(l, m, r, &t0, &t1);
    for (uint32_t t = next_region_tet(l->region, t0, t1); t < t1;
         t = next_region_tet(l->region, t + 1u, t1)) {
        const uint32_t loaded = loaded_faces(l, m, t);
        for (uint32_t f = 0; f < 4u; f++) {
            if ((loaded & (1u << f)) != 0u) {
                face_clear(n, m->tet[t], f);
            }
        }
    }
#endif
}

/* the even ranges' job, then the odd ranges' (ranges two apart share no node) */
static void run_phases(const sc_lumen *l, sc_pool_job_fn fn, lumen_job *j)
{
    for (uint32_t p = 0; p < 2u; p++) {
        j->phase = p;
        sc_pool_run(l->pool, fn, j, l->ranges > p ? (l->ranges - p + 1u) / 2u : 0u);
    }
}

void sc_lumen_apply(sc_lumen *l, const sc_mesh *m, sc_nodes *n)
{
    l->faces = 0u;
    if (!l->enabled || l->count == 0u) {
        return;
    }
    SC_ASSERT(l->ranges >= 1u && l->ranges <= SC_LUMEN_RANGES &&
              (uint64_t)l->ranges * l->span_tets >= m->tet_count);
    l->heart_phase = advance(l->heart_phase, l->drive.heart_rate_bpm, l->frame_s);
    l->resp_phase = advance(l->resp_phase, l->drive.resp_rate_bpm, l->frame_s);
#if SC_LUMEN_RANGES > 1
    float(*part)[SC_LUMEN_MAX][SC_LUMEN_SLICES] = l->part_vol;
#else
    float part1[1][SC_LUMEN_MAX][SC_LUMEN_SLICES]; /* one range: on the stack */
    float(*part)[SC_LUMEN_MAX][SC_LUMEN_SLICES] = part1;
#endif
#if SC_LUMEN_RANGES > 1
    lumen_job j = {l, part, l->part_faces, m, n, NULL, 0u, l->list_vol};
#else
    lumen_job j = {l, part, l->part_faces, m, n, NULL, 0u, NULL};
#endif
    sc_pool_run(l->pool, job_volume, &j, l->ranges);
    /* the ranges' partial volumes added to the first's in range order (one range: the serial
     * loop's sum) */
    float(*vol)[SC_LUMEN_SLICES] = part[0];
    for (uint32_t r = 1u; r < l->ranges; r++) {
        for (uint32_t k = 0; k < l->count; k++) {
            for (uint32_t i = 0; i < SC_LUMEN_SLICES; i++) {
                vol[k][i] += part[r][k][i];
            }
        }
    }
    float press_nmm2[SC_LUMEN_MAX][SC_LUMEN_SLICES];
    for (uint32_t k = 0; k < l->count; k++) {
        sc_lumen_vessel *v = &l->v[k];
        v->drive_pa = sc_lumen_drive_pa(l, v->kind);
        v->v_mm3 = 0.0f;
        v->p_pa = -INFINITY;
        for (uint32_t i = 0; i < v->slices; i++) {
            v->v_mm3 += vol[k][i];
            if (!(v->s_v0[i] > 0.0f)) {
                press_nmm2[k][i] = 0.0f; /* an empty section (no tet's centroid in it) */
                continue;
            }
            const float s = (v->s_v0[i] - vol[k][i]) / v->s_v0[i];
            /* bounded: a lumen squeezed past empty (inverted tets) pushes back no harder than
             * an empty one, a distension past double its volume pulls no harder than that */
            const float sc = isfinite(s) ? fminf(fmaxf(s, -1.0f), 1.0f) : 0.0f;
            const float g = law(v, sc);
            /* up: relaxed (theta, stable against the tissue's answer); down: at once, so that
             * a lumen let go (the probe lifted or jumped away) is never over-pressured (the
             * relaxed fall took 1 / theta frames and blew the lumen up) */
            float *p = &v->s_p[i];
            *p = g < *p ? g : *p + v->theta * (g - *p);
            v->p_pa = fmaxf(v->p_pa, *p);
            /* a lumen squeezed below half its volume carries less of the drive, none when
             * empty (no flow through a crushed vessel; fed forward onto a crushed artery the
             * pulse flung its filler's nodes past the guard's bound at the deepest press) */
            const float open = sc <= 0.5f ? 1.0f : 2.0f * (1.0f - sc);
            /* Pa -> N/mm^2; a third of the face's area vector per node */
            press_nmm2[k][i] = (*p + open * v->drive_pa) * (1.0e-6f / 3.0f);
        }
        v->p_pa = isfinite(v->p_pa) ? v->p_pa : 0.0f;
    }
    j.press = (const float(*)[SC_LUMEN_SLICES])press_nmm2;
    run_phases(l, job_forces, &j);
    uint32_t faces = 0;
    for (uint32_t r = 0; r < l->ranges; r++) {
        faces += l->part_faces[r];
    }
    l->faces = faces;
}

void sc_lumen_clear(const sc_lumen *l, const sc_mesh *m, sc_nodes *n)
{
    if (l->faces == 0u) {
        return;
    }
    lumen_job j = {l, NULL, NULL, m, n, NULL, 0u, NULL};
    run_phases(l, job_clear, &j);
}
