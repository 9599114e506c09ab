/* sc_state.c: the console state stream's records, see sc_state.h and docs/state-stream.md. */
#include "sc_state.h"

#include <string.h>

#include "sc_err.h"
#include "sc_le.h"

#define CAT_NAME_BYTES 240u

typedef struct wr {
    uint8_t *p;
    uint32_t n;
} wr;

static void put_u8(wr *w, uint8_t v)
{
    w->p[w->n++] = v;
}

static void put_u16(wr *w, uint16_t v)
{
    put_u8(w, (uint8_t)v);
    put_u8(w, (uint8_t)(v >> 8));
}

static void put_u32(wr *w, uint32_t v)
{
    put_u16(w, (uint16_t)v);
    put_u16(w, (uint16_t)(v >> 16));
}

static void put_u64(wr *w, uint64_t v)
{
    put_u32(w, (uint32_t)v);
    put_u32(w, (uint32_t)(v >> 32));
}

static void put_f32(wr *w, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_u32(w, u);
}

static void put_text(wr *w, const char *s, uint32_t bytes)
{
    uint32_t i = 0;
    for (; s != NULL && s[i] != '\0' && i + 1u < bytes; i++) {
        put_u8(w, (uint8_t)s[i]);
    }
    for (; i < bytes; i++) {
        put_u8(w, 0u);
    }
}

void sc_state_tx_init(sc_state_tx *t, uint32_t period_ms, uint32_t vert_records)
{
    memset(t, 0, sizeof *t);
    t->period_ms = period_ms;
    t->vert_records = vert_records;
}

static wr begin(sc_state_tx *t, sc_state_type type)
{
    wr w = {t->buf, 0};
    put_u32(&w, SC_STATE_MAGIC);
    put_u8(&w, SC_STATE_VERSION);
    put_u8(&w, (uint8_t)type);
    put_u16(&w, 0u); /* payload length, patched by finish() */
    put_u32(&w, 0u); /* sequence, patched by finish() */
    put_u32(&w, 0u); /* frame */
    return w;
}

static uint32_t finish(sc_state_tx *t, const sc_state_dev *dev, wr *w, uint32_t frame_no)
{
    wr h = {t->buf + 6, 0};
    put_u16(&h, (uint16_t)(w->n - SC_STATE_HEADER_SIZE));
    put_u32(&h, t->seq);
    put_u32(&h, frame_no);
    t->seq++;
    if (sc_state_send(dev, t->buf, (uint16_t)w->n) == SC_OK) {
        t->records_sent++;
        return 1u;
    }
    t->records_dropped++;
    return 0u;
}

static uint32_t case_crc(const sc_state_in *in)
{
    return in->c != NULL ? in->c->case_id : 0u;
}

static uint32_t emit_frame(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    wr w = begin(t, SC_STATE_FRAME);
    put_u64(&w, in->now_ns);
    put_u8(&w, in->health_state);
    put_u8(&w, in->case_loaded);
    put_u8(&w, in->case_id);
    put_u8(&w, in->method);
    put_u8(&w, in->tracked);
    put_u8(&w, in->contact);
    put_u8(&w, in->switching);
    put_u8(&w, in->frozen);
    put_u32(&w, in->faults);
    put_u32(&w, in->geometry_id);
    put_u64(&w, in->frames);
    put_u64(&w, in->misses);
    put_u64(&w, in->worst_frame_ns);
    put_u64(&w, in->p99_frame_ns);
    put_f32(&w, in->vein_area_ratio);
    put_f32(&w, in->artery_area_ratio);
    for (int a = 0; a < 3; a++) {
        put_f32(&w, in->probe_volume.pos_mm[a]);
    }
    for (int a = 0; a < 4; a++) {
        put_f32(&w, in->probe_volume.q[a]);
    }
    put_f32(&w, in->gain_db);
    put_f32(&w, in->dynamic_range_db);
    put_f32(&w, in->depth_mm);
    for (int b = 0; b < 8; b++) {
        put_f32(&w, in->tgc_db[b]);
    }
    put_u64(&w, in->commands_applied);
    put_u64(&w, in->commands_refused);
    put_u64(&w, in->commands_auth_refused);
    put_u64(&w, in->case_loads);
    put_u64(&w, in->case_load_failures);
    put_u32(&w, (uint32_t)in->last_case_error);
    put_u32(&w, case_crc(in));
    put_u32(&w, in->c != NULL ? in->c->surf.vertex_count : 0u);
    put_u32(&w, in->c != NULL ? in->c->surf.triangle_count : 0u);
    put_u32(&w, (uint32_t)t->records_dropped);
    put_u32(&w, in->catalogue_count);
    put_u32(&w, 0u);
    put_u32(&w, 0u);
    return finish(t, dev, &w, in->frame_no);
}

static uint32_t emit_surf_info(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    const sc_case_surf *s = &in->c->surf;
    wr w = begin(t, SC_STATE_SURF_INFO);
    put_u32(&w, case_crc(in));
    put_u32(&w, s->count);
    put_u32(&w, s->vertex_count);
    put_u32(&w, s->triangle_count);
    for (uint32_t i = 0; i < SC_CASE_SURF_MAX_SURFACES && i < 8u; i++) {
        const sc_case_surface *r = &s->s[i];
        const int used = i < s->count;
        put_u8(&w, used ? r->label : 0u);
        put_u8(&w, used ? r->kind : 0u);
        put_u16(&w, 0u);
        put_u32(&w, used ? r->first_vertex : 0u);
        put_u32(&w, used ? r->vertex_count : 0u);
        put_u32(&w, used ? r->triangle_count : 0u);
    }
    for (uint32_t i = SC_CASE_SURF_MAX_SURFACES; i < 8u; i++) {
        put_u32(&w, 0u);
        put_u32(&w, 0u);
        put_u32(&w, 0u);
        put_u32(&w, 0u);
    }
    put_text(&w, in->c->name, 64u);
    /* the probe calibration (image -> probe), so a view can place the image plane */
    for (int i = 0; i < 9; i++) {
        put_f32(&w, in->c->image_to_probe.r[i]);
    }
    for (int i = 0; i < 3; i++) {
        put_f32(&w, in->c->image_to_probe.t_mm[i]);
    }
    return finish(t, dev, &w, in->frame_no);
}

static uint32_t emit_verts(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    const sc_case_surf *s = &in->c->surf;
    if (t->vert_cursor >= s->vertex_count) {
        t->vert_cursor = 0;
    }
    const uint32_t first = t->vert_cursor;
    uint32_t n = s->vertex_count - first;
    if (n > SC_STATE_VERTS_PER_RECORD) {
        n = SC_STATE_VERTS_PER_RECORD;
    }
    wr w = begin(t, SC_STATE_VERTS);
    put_u32(&w, case_crc(in));
    put_u32(&w, first);
    put_u16(&w, (uint16_t)n);
    put_u16(&w, 0u);
    for (uint32_t v = first; v < first + n; v++) {
        uint32_t tet;
        float wt[4];
        sc_case_surf_vertex(s, v, &tet, wt);
        float p[3] = {0.0f, 0.0f, 0.0f};
        for (int k = 0; k < 4; k++) {
            const uint32_t node = in->mesh->tet[tet][k];
            p[0] += wt[k] * in->x[node];
            p[1] += wt[k] * in->y[node];
            p[2] += wt[k] * in->z[node];
        }
        put_f32(&w, p[0]);
        put_f32(&w, p[1]);
        put_f32(&w, p[2]);
    }
    t->vert_cursor = first + n;
    return finish(t, dev, &w, in->frame_no);
}

static uint32_t emit_tris(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    const sc_case_surf *s = &in->c->surf;
    if (t->tri_cursor >= s->triangle_count) {
        t->tri_cursor = 0;
    }
    const uint32_t first = t->tri_cursor;
    uint32_t n = s->triangle_count - first;
    if (n > SC_STATE_TRIS_PER_RECORD) {
        n = SC_STATE_TRIS_PER_RECORD;
    }
    wr w = begin(t, SC_STATE_TRIS);
    put_u32(&w, case_crc(in));
    put_u32(&w, first);
    put_u16(&w, (uint16_t)n);
    put_u16(&w, 0u);
    for (uint32_t i = first; i < first + n; i++) {
        uint32_t idx[3];
        sc_case_surf_triangle(s, i, idx);
        put_u32(&w, idx[0]);
        put_u32(&w, idx[1]);
        put_u32(&w, idx[2]);
    }
    t->tri_cursor = first + n;
    return finish(t, dev, &w, in->frame_no);
}

static uint32_t emit_catalogue(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    if (t->cat_cursor >= in->catalogue_count) {
        t->cat_cursor = 0;
    }
    const uint32_t i = t->cat_cursor++;
    wr w = begin(t, SC_STATE_CATALOGUE);
    put_u32(&w, i);
    put_u32(&w, in->catalogue_count);
    put_u8(&w, (uint8_t)(in->case_loaded && in->case_id == i));
    put_u8(&w, 0u);
    put_u16(&w, 0u);
    put_text(&w, in->catalogue[i], CAT_NAME_BYTES);
    return finish(t, dev, &w, in->frame_no);
}

/* The assessment record, field by field in the little-endian layout of docs/assessment.md
 * (104 bytes, the same as sc_assess_report's). */
static uint32_t emit_assessment(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    const sc_assess_report *r = in->assess;
    wr w = begin(t, SC_STATE_ASSESSMENT);
    put_u32(&w, r->version);
    put_u32(&w, r->frames);
    put_u32(&w, r->contact_frames);
    put_u32(&w, r->resets);
    put_u32(&w, r->calls);
    for (uint32_t v = 0; v < SC_ASSESS_VESSELS; v++) {
        const sc_assess_vessel_rec *x = &r->vessel[v];
        put_f32(&w, x->min_ratio);
        put_f32(&w, x->force_at_min_n);
        put_u32(&w, x->frames_in_view);
        put_u32(&w, x->min_frame);
        put_u8(&w, x->coapted);
        put_u8(&w, 0u);
        put_u16(&w, 0u);
    }
    put_f32(&w, r->peak_force_n);
    put_f32(&w, r->venous_force_max_n);
    put_u8(&w, r->artery_over);
    put_u8(&w, r->call);
    put_u8(&w, r->finding);
    put_u8(&w, r->criteria_met);
    for (uint32_t c = 0; c < SC_ASSESS_CRITERIA_R0; c++) {
        put_u8(&w, r->points[c]);
    }
    put_u8(&w, r->score);
    put_u8(&w, r->score_max);
    /* revision 1: the needle's punctures and criterion 5 in bytes 99..102 */
    put_u8(&w, r->artery_punctures);
    put_u8(&w, r->vein_punctures);
    put_u8(&w, r->puncture_points);
    put_u8(&w, r->revision);
    put_u8(&w, 0u);
    return finish(t, dev, &w, in->frame_no);
}

/* The MATERIAL record (docs/state-stream.md): what the running tissue was built with. */
static uint32_t emit_material(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    const sc_material_table *m = in->mat;
    const uint32_t count = m->count < SC_STATE_MATERIAL_ROWS ? m->count : SC_STATE_MATERIAL_ROWS;
    wr w = begin(t, SC_STATE_MATERIAL);
    put_u8(&w, (uint8_t)count);
    put_u8(&w, in->mat_sim_override);
    put_u8(&w, in->cg_iterations);
    put_u8(&w, in->corotated);
    put_f32(&w, in->damping_s);
    put_u32(&w, in->mat_override_mask);
    put_u32(&w, 0u);
    put_u64(&w, in->material_rebuilds);
    put_u64(&w, in->material_refused);
    for (uint32_t l = 0; l < SC_STATE_MATERIAL_ROWS; l++) {
        put_f32(&w, l < count ? m->row[l].e_pa : 0.0f);
        put_f32(&w, l < count ? m->row[l].poisson : 0.0f);
    }
    return finish(t, dev, &w, in->frame_no);
}

uint32_t sc_state_emit(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in)
{
    if (t->period_ms == 0u || dev == NULL || dev->ops == NULL || in->now_ns < t->next_ns) {
        return 0u;
    }
    const uint64_t period_ns = (uint64_t)t->period_ms * 1000000u;
    /* the next period counts from this one's due time; a late one resynchronises */
    t->next_ns = (t->next_ns != 0u && in->now_ns - t->next_ns < period_ns) ? t->next_ns + period_ns
                                                                          : in->now_ns + period_ns;
    uint32_t sent = emit_frame(t, dev, in);
    const int surf = in->c != NULL && in->mesh != NULL && in->x != NULL && in->c->surf.count > 0u;
    if (surf) {
        sent += emit_surf_info(t, dev, in);
        for (uint32_t r = 0; r < t->vert_records; r++) {
            sent += emit_verts(t, dev, in);
            if (in->c->surf.vertex_count <= SC_STATE_VERTS_PER_RECORD * (r + 1u)) {
                break; /* all of a small surface set went out this period */
            }
        }
        if (in->c->surf.triangle_count > 0u) {
            sent += emit_tris(t, dev, in);
        }
    }
    if (in->catalogue_count > 0u && in->catalogue != NULL) {
        sent += emit_catalogue(t, dev, in);
    }
    if (in->assess != NULL) {
        sent += emit_assessment(t, dev, in);
    }
    if (in->mat != NULL) {
        sent += emit_material(t, dev, in);
    }
    t->periods++;
    return sent;
}

int sc_state_check(const uint8_t *rec, uint32_t len, uint32_t *seq, uint32_t *frame_no)
{
    if (rec == NULL || len < SC_STATE_HEADER_SIZE) {
        return SC_ERR_INVALID_ARG;
    }
    const uint32_t plen = (uint32_t)rec[6] | ((uint32_t)rec[7] << 8);
    if (sc_le_rd_u32(rec) != SC_STATE_MAGIC || rec[4] != SC_STATE_VERSION || rec[5] == 0u ||
        plen != len - SC_STATE_HEADER_SIZE) {
        return SC_ERR_RANGE;
    }
    if (seq) {
        *seq = sc_le_rd_u32(rec + 8);
    }
    if (frame_no) {
        *frame_no = sc_le_rd_u32(rec + 12);
    }
    return (int)rec[5];
}
