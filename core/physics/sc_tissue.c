/* sc_tissue.c: per-frame soft-tissue facade (MSDS / FEM, collider, skin, guard). */
#include "sc_tissue.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_msds_implicit.h"

sc_tissue_def sc_tissue_default_def(void)
{
    sc_tissue_def d;
    memset(&d, 0, sizeof d);
    d.mesh = sc_mesh_default_def();
    d.msds = sc_msds_default_def();
    d.fem = sc_fem_default_def();
    d.collider = sc_collider_default_def();
    d.skin = sc_skin_default_def();
    d.skin.origin_mm[0] = d.mesh.origin_mm[0];
    d.skin.origin_mm[1] = d.mesh.origin_mm[1];
    d.skin.size_mm[0] = d.mesh.size_mm[0];
    d.skin.size_mm[1] = d.mesh.size_mm[1];
    d.skin.z_mm = d.mesh.origin_mm[2];
    d.skin_enabled = 1u;
    d.method = SC_TISSUE_MSDS;
    d.msds_contact = SC_TISSUE_CONTACT_PROJECT;
    return d;
}

static sc_collider_grid mesh_grid(const sc_mesh *m)
{
    sc_collider_grid g;
    g.nx = m->nx;
    g.ny = m->ny;
    g.nz = m->nz;
    for (uint32_t i = 0; i < 3u; i++) {
        g.origin_mm[i] = m->origin_mm[i];
        g.cell_mm[i] = m->cell_mm[i];
    }
    return g;
}

void sc_tissue_reset(sc_tissue *t)
{
    sc_nodes_reset_to_rest(&t->nodes, &t->mesh);
    sc_skin_reset(&t->skin);
    t->contacts.count = 0u;
    for (uint32_t i = 0; i < t->mesh.node_count; i++) {
        t->kinematic[i] = 0u;
    }
    t->stats.max_disp_mm = 0.0f;
#if SC_PHYS_LUMEN
    sc_lumen_reset(&t->lumen);
#endif
}

int sc_tissue_build_begin(sc_tissue *t, const sc_tissue_def *def, const sc_volume *vol,
                          const sc_material_table *mat, uint8_t default_label)
{
    if (t == NULL || def == NULL || mat == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (def->method != SC_TISSUE_MSDS && def->method != SC_TISSUE_FEM) {
        return SC_ERR_INVALID_ARG;
    }
    t->build_phase = SC_TISSUE_BUILD_DONE; /* not usable until the last phase */
    const int rc = sc_material_table_validate(mat);
    if (rc != SC_OK) {
        return rc;
    }
    t->def = *def;
    t->method = def->method;
    t->mat = *mat;
    t->build_vol = vol;
    t->build_label = default_label;
    t->pool = NULL;
    memset(&t->stats, 0, sizeof t->stats);
    t->tip_active = 0u;
    t->tip_contacts = 0u;
    t->build_phase = SC_TISSUE_BUILD_MESH;
    return SC_OK;
}

static int build_contact(sc_tissue *t)
{
    int rc = sc_collider_init(&t->collider, &t->def.collider);
    if (rc != SC_OK) {
        return rc;
    }
    t->collider.pool = t->pool;
    sc_skin_def sd = t->def.skin;
    if (!t->def.skin_enabled) {
        /* a minimal, never stepped surface keeps the struct valid */
        sd = sc_skin_default_def();
        sd.nx = 2u;
        sd.ny = 2u;
    }
    rc = sc_skin_init(&t->skin, &sd);
    if (rc != SC_OK) {
        return rc;
    }
    const float *s = t->def.mesh.size_mm;
    t->box_diag_mm = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    sc_tissue_reset(t);
    return SC_OK;
}

int sc_tissue_build_step(sc_tissue *t)
{
    if (t == NULL || t->build_phase >= SC_TISSUE_BUILD_DONE) {
        return SC_ERR_STATE;
    }
    int rc = SC_OK;
    switch ((sc_tissue_build_phase)t->build_phase) {
    case SC_TISSUE_BUILD_MESH:
        rc = sc_mesh_build(&t->mesh, &t->def.mesh);
        break;
    case SC_TISSUE_BUILD_LABELS:
        rc = sc_material_assign(&t->mesh, t->build_vol, &t->mat, t->build_label);
#if SC_PHYS_LUMEN
        if (rc == SC_OK) {
            rc = sc_lumen_init(&t->lumen, &t->mesh, &t->mat);
            t->lumen.pool = t->pool;
        }
#endif
        break;
    case SC_TISSUE_BUILD_SPRINGS:
        rc = sc_springs_from_tets(&t->springs, (const uint32_t(*)[4])t->mesh.tet,
                                  t->mesh.tet_label, t->mesh.tet_count, &t->mat);
        break;
    case SC_TISSUE_BUILD_MSDS:
        rc = sc_msds_init_begin(&t->msds, &t->mesh, &t->springs, &t->mat, &t->def.msds);
        break;
    case SC_TISSUE_BUILD_MSDS_SCALE:
        rc = sc_msds_init_step(&t->msds, &t->mesh, SC_TISSUE_BUILD_POWER_ITS);
        if (rc == 0) {
            return 0; /* more iterations: the same phase again */
        }
        rc = rc == 1 ? SC_OK : rc;
        break;
    case SC_TISSUE_BUILD_FEM:
        rc = sc_fem_init(&t->fem, &t->mesh, &t->mat, &t->def.fem);
        t->fem.grid.pool = t->pool;
        break;
    case SC_TISSUE_BUILD_CONTACT:
        rc = build_contact(t);
        break;
    case SC_TISSUE_BUILD_DONE:
        break;
    }
    if (rc != SC_OK) {
        t->build_phase = SC_TISSUE_BUILD_DONE;
        return rc;
    }
    t->build_phase++;
    return t->build_phase == SC_TISSUE_BUILD_DONE ? 1 : 0;
}

int sc_tissue_init(sc_tissue *t, const sc_tissue_def *def, const sc_volume *vol,
                   const sc_material_table *mat, uint8_t default_label)
{
    int rc = sc_tissue_build_begin(t, def, vol, mat, default_label);
    while (rc == SC_OK) {
        rc = sc_tissue_build_step(t);
    }
    return rc == 1 ? SC_OK : rc;
}

int sc_tissue_set_method(sc_tissue *t, sc_tissue_method m)
{
    if (t == NULL || (m != SC_TISSUE_MSDS && m != SC_TISSUE_FEM)) {
        return SC_ERR_INVALID_ARG;
    }
    if (m != t->method) {
        for (uint32_t i = 0; i < t->mesh.node_count; i++) {
            t->kinematic[i] = 0u;
        }
        t->method = m;
    }
    return SC_OK;
}

int sc_tissue_set_msds_def(sc_tissue *t, const sc_msds_def *def)
{
    if (t == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_msds_set_def(&t->msds, def);
    if (rc == SC_OK) {
        t->def.msds = *def;
    }
    return rc;
}

/* Projection contact: the repulsion that removes a node's penetration within one step (an
 * external force f = m (depth / dt^2 - v_n / dt) n, applied as its effect on x and v). */
static void project_contacts(sc_tissue *t)
{
    sc_nodes *n = &t->nodes;
    for (uint32_t q = 0; q < t->contacts.count; q++) {
        const sc_contact *ct = &t->contacts.c[q];
        const uint32_t i = ct->node;
        const float d = sc_contact_depth_mm(ct, n->x[i], n->y[i], n->z[i]);
        if (d > 0.0f) {
            n->x[i] += d * ct->n[0];
            n->y[i] += d * ct->n[1];
            n->z[i] += d * ct->n[2];
            const float vn = n->vx[i] * ct->n[0] + n->vy[i] * ct->n[1] + n->vz[i] * ct->n[2];
            if (vn < 0.0f) {
                n->vx[i] -= vn * ct->n[0];
                n->vy[i] -= vn * ct->n[1];
                n->vz[i] -= vn * ct->n[2];
            }
        }
    }
}

static void step_msds(sc_tissue *t)
{
    sc_nodes *n = &t->nodes;
    const float ratio = t->msds.def.contact_stiffness_ratio;
    for (uint32_t it = 0; it < t->msds.def.iterations; it++) {
        if (t->def.msds_contact == SC_TISSUE_CONTACT_PENALTY) {
            sc_contact_clear_forces(&t->contacts, n->fx, n->fy, n->fz);
            sc_contact_add_forces(&t->contacts, n->x, n->y, n->z, t->msds.kref_n_per_mm, ratio,
                                  n->fx, n->fy, n->fz);
        }
        sc_msds_substep(&t->msds, n);
        if (t->def.msds_contact == SC_TISSUE_CONTACT_PROJECT) {
            project_contacts(t);
        }
    }
    sc_contact_clear_forces(&t->contacts, n->fx, n->fy, n->fz);
}

/* The FEM, or the MSDS's implicit integrator (implicit != 0): one backward Euler step of
 * the frame's simulated time with the probe's contacts as kinematic nodes. */
static void step_kinematic(sc_tissue *t, int implicit_msds)
{
    sc_nodes *n = &t->nodes;
    const float dt_frame = t->msds.def.dt_s * (float)t->msds.def.iterations;
    /* the only external forces on this path are the lumen pressures (contacts are kinematic) */
    t->fem.grid.forces_vanish_at_rest = 1u;
    /* nodes in the probe or on its surface (within the hold tolerance: a node left exactly on
     * the surface by the last frame, or by the MSDS before a switch, must stay held, or the
     * tissue under it would push it into the probe for one frame) */
    uint32_t held = 0;
    for (uint32_t q = 0; q < t->contacts.count; q++) {
        const sc_contact *ct = &t->contacts.c[q];
        const uint32_t i = ct->node;
        const float d = sc_contact_depth_mm(ct, n->x[i], n->y[i], n->z[i]);
        if (d > -SC_TISSUE_CONTACT_HOLD_MM) {
            t->kinematic[i] = 1u;
            const float dd = d > 0.0f ? d : 0.0f;
            n->vx[i] = dd * ct->n[0] / dt_frame;
            n->vy[i] = dd * ct->n[1] / dt_frame;
            n->vz[i] = dd * ct->n[2] / dt_frame;
            held++;
        }
    }
    if (implicit_msds) {
        sc_msds_implicit_step(&t->msds, &t->fem, &t->mesh, n, dt_frame, t->fem.def.cg_iterations,
                              t->kinematic);
    } else {
        sc_fem_step_kinematic(&t->fem, &t->mesh, n, dt_frame, t->fem.def.cg_iterations,
                              t->kinematic);
    }
    for (uint32_t q = 0; q < t->contacts.count; q++) {
        const uint32_t i = t->contacts.c[q].node;
        if (t->kinematic[i] != 0u) {
            /* the node sits on the probe: it carries no velocity of its own; clear the flag
             * (O(contacts), every node with a flag is a contact of this frame) */
            n->vx[i] = 0.0f;
            n->vy[i] = 0.0f;
            n->vz[i] = 0.0f;
            t->kinematic[i] = 0u;
        }
    }
    t->stats.kinematic = held;
}

/* The guard's scan on the worker pool: ranges of SC_TISSUE_GUARD_RANGE nodes, each its largest
 * squared displacement and whether a value is not finite; the ranges' maxima and flags combined
 * afterwards (a maximum and an OR: the serial loop's result for any split). */
#define SC_TISSUE_GUARD_RANGE 4096u
#define SC_TISSUE_GUARD_RANGES ((SC_MAX_NODES + SC_TISSUE_GUARD_RANGE - 1u) / SC_TISSUE_GUARD_RANGE)
typedef struct guard_job {
    const sc_nodes *n;
    const sc_mesh *m;
    float maxd2[SC_TISSUE_GUARD_RANGES];
    uint8_t bad[SC_TISSUE_GUARD_RANGES];
} guard_job;

static void job_guard(void *arg, uint32_t r)
{
    guard_job *j = (guard_job *)arg;
    const sc_nodes *n = j->n;
    const sc_mesh *m = j->m;
    const uint32_t i0 = r * SC_TISSUE_GUARD_RANGE;
    const uint32_t i1 =
        i0 + SC_TISSUE_GUARD_RANGE < m->node_count ? i0 + SC_TISSUE_GUARD_RANGE : m->node_count;
    float maxd2 = 0.0f;
    float acc = 0.0f;
    for (uint32_t i = i0; i < i1; i++) {
        const float dx = n->x[i] - m->rest_x[i], dy = n->y[i] - m->rest_y[i],
                    dz = n->z[i] - m->rest_z[i];
        const float d2 = dx * dx + dy * dy + dz * dz;
        maxd2 = d2 > maxd2 ? d2 : maxd2;
        acc += d2 * 0.0f + (n->vx[i] + n->vy[i] + n->vz[i]) * 0.0f;
    }
    j->maxd2[r] = maxd2;
    j->bad[r] = (uint8_t)!isfinite(acc);
}

/* Guard pass: finite check, largest displacement. O(N), on the pool. */
static sc_tissue_guard guard(sc_tissue *t)
{
    guard_job j;
    j.n = &t->nodes;
    j.m = &t->mesh;
    const uint32_t ranges = (t->mesh.node_count + SC_TISSUE_GUARD_RANGE - 1u) / SC_TISSUE_GUARD_RANGE;
    SC_ASSERT(ranges <= SC_TISSUE_GUARD_RANGES);
    sc_pool_run(t->pool, job_guard, &j, ranges);
    float maxd2 = 0.0f;
    int bad = 0;
    for (uint32_t r = 0; r < ranges && r < SC_TISSUE_GUARD_RANGES; r++) {
        maxd2 = j.maxd2[r] > maxd2 ? j.maxd2[r] : maxd2;
        bad |= j.bad[r];
    }
    const sc_nodes *n = &t->nodes;
    const float maxd = sqrtf(maxd2);
    t->stats.max_disp_mm = maxd;
    if (bad || !isfinite(maxd)) {
        return SC_TISSUE_GUARD_NOT_FINITE;
    }
    if (maxd > t->box_diag_mm) {
        return SC_TISSUE_GUARD_DISPLACEMENT;
    }
    if (t->method == SC_TISSUE_MSDS && t->msds.def.integrator == (uint8_t)SC_MSDS_EXPLICIT) {
        /* the explicit scheme's runaway (its scaled masses); the implicit step cannot gain
         * energy (backward Euler on a positive semi-definite K dissipates) and its solve is
         * checked for finiteness below */
        const float ek = sc_msds_kinetic_energy_j(&t->msds, n);
        if (!isfinite(ek) || ek > t->msds.energy_limit_j) {
            return SC_TISSUE_GUARD_ENERGY;
        }
    }
    if (sc_fem_status(&t->fem) != SC_OK) {
        return SC_TISSUE_GUARD_SOLVER; /* the FEM's or the implicit MSDS's solve */
    }
    if (t->def.skin_enabled) {
        if (!sc_skin_is_finite(&t->skin) ||
            !(sc_skin_max_displacement_mm(&t->skin) <= t->box_diag_mm)) {
            return SC_TISSUE_GUARD_SKIN;
        }
    }
    return SC_TISSUE_GUARD_OK;
}

int sc_tissue_step(sc_tissue *t, const sc_pose *probe)
{
    SC_ASSERT(t != NULL);
    int rc = sc_collider_set_pose(&t->collider, probe);
    const sc_collider_grid g = mesh_grid(&t->mesh);
    sc_collider_detect(&t->collider, &g, t->nodes.x, t->nodes.y, t->nodes.z,
                       t->mesh.node_fixed, t->stats.max_disp_mm, &t->contacts);
    t->tip_contacts = 0u;
    if (t->tip_active) {
        t->tip_contacts = sc_collider_append_sphere(
            t->tip_mm, t->tip_radius_mm, t->def.collider.margin_mm, t->mesh.node_count,
            t->nodes.x, t->nodes.y, t->nodes.z, t->mesh.node_fixed, &t->contacts);
    }
    t->stats.contacts = t->contacts.count;
#if SC_PHYS_LUMEN
    sc_lumen_apply(&t->lumen, &t->mesh, &t->nodes);
#endif
    if (t->method == SC_TISSUE_MSDS && t->msds.def.integrator == (uint8_t)SC_MSDS_EXPLICIT) {
        t->stats.kinematic = 0u;
        step_msds(t);
    } else {
        step_kinematic(t, t->method == SC_TISSUE_MSDS);
    }
#if SC_PHYS_LUMEN
    sc_lumen_clear(&t->lumen, &t->mesh, &t->nodes);
#endif
    uint32_t mpr = t->contacts.mpr_calls;
    if (t->def.skin_enabled) {
        sc_skin_step(&t->skin, &t->collider);
        mpr += t->skin.contacts.mpr_calls;
    }
    t->stats.mpr_calls = mpr;
    t->stats.frames++;
    const sc_tissue_guard why = guard(t);
    if (why != SC_TISSUE_GUARD_OK) {
        t->stats.faults++;
        t->stats.last_fault = (uint32_t)why;
        if (sc_fem_status(&t->fem) != SC_OK) {
            /* the FEM's sticky status is cleared by re-initialising it on the same mesh */
            (void)sc_fem_init(&t->fem, &t->mesh, &t->mat, &t->def.fem);
        }
        sc_tissue_reset(t);
        return SC_ERR_PHYS_UNSTABLE;
    }
    return rc;
}

void sc_tissue_set_tip(sc_tissue *t, int active, const float tip_mm[3], float radius_mm)
{
    if (t == NULL) {
        return;
    }
    t->tip_active = 0u;
    if (!active || tip_mm == NULL || !isfinite(radius_mm) || !(radius_mm > 0.0f) ||
        !isfinite(tip_mm[0]) || !isfinite(tip_mm[1]) || !isfinite(tip_mm[2])) {
        return;
    }
    for (uint32_t a = 0; a < 3u; a++) {
        t->tip_mm[a] = tip_mm[a];
    }
    t->tip_radius_mm = radius_mm;
    t->tip_active = 1u;
}

#if SC_PHYS_LUMEN
int sc_tissue_set_drive(sc_tissue *t, const sc_lumen_drive *d)
{
    if (t == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    return sc_lumen_set_drive(&t->lumen, d);
}

void sc_tissue_set_valsalva(sc_tissue *t, int on)
{
    SC_ASSERT(t != NULL);
    sc_lumen_set_valsalva(&t->lumen, on);
}

int sc_tissue_set_frame_s(sc_tissue *t, float frame_s)
{
    if (t == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    return sc_lumen_set_frame_s(&t->lumen, frame_s);
}
#endif

static uint64_t fnv(uint64_t h, const float *v, uint32_t count)
{
    const unsigned char *b = (const unsigned char *)v;
    const size_t bytes = (size_t)count * sizeof(float);
    for (size_t i = 0; i < bytes; i++) {
        h ^= b[i];
        h *= 0x100000001B3u;
    }
    return h;
}

uint64_t sc_tissue_state_hash(const sc_tissue *t)
{
    uint64_t h = 0xCBF29CE484222325u;
    const uint32_t nn = t->mesh.node_count;
    h = fnv(h, t->nodes.x, nn);
    h = fnv(h, t->nodes.y, nn);
    h = fnv(h, t->nodes.z, nn);
    h = fnv(h, t->nodes.vx, nn);
    h = fnv(h, t->nodes.vy, nn);
    h = fnv(h, t->nodes.vz, nn);
    h = fnv(h, t->skin.x, t->skin.count);
    h = fnv(h, t->skin.y, t->skin.count);
    h = fnv(h, t->skin.z, t->skin.count);
    return h;
}

/* The probe's force on the worker pool: the contacts cut into ranges of SC_TISSUE_FORCE_RANGE,
 * each range's sum formed in contact order, the ranges' sums added in range order afterwards.
 * Up to one range (256 contacts) that is the serial loop's sum bit for bit; beyond, the same bits
 * for every worker count (the sum's order differs from the serial loop's). Why the pool:
 * 27 blocks of 60 matrix rows per contact miss the cache after the imaging stage (a 64x32x32
 * press, 761 contacts: 0.17 ms warm, about 1 ms in the real loop). */
#define SC_TISSUE_FORCE_RANGE 256u
#define SC_TISSUE_FORCE_RANGES ((SC_MAX_CONTACTS + SC_TISSUE_FORCE_RANGE - 1u) / SC_TISSUE_FORCE_RANGE)
typedef struct force_job {
    const sc_tissue *t;
    float f[SC_TISSUE_FORCE_RANGES][3];
} force_job;

static void job_force(void *arg, uint32_t r)
{
    force_job *jb = (force_job *)arg;
    const sc_tissue *t = jb->t;
    const sc_mesh *m = &t->mesh;
    const sc_nodes *n = &t->nodes;
    const uint32_t nx = m->nx, ny = m->ny;
    const uint32_t q0 = r * SC_TISSUE_FORCE_RANGE;
    const uint32_t q1 = q0 + SC_TISSUE_FORCE_RANGE < t->contacts.count
                            ? q0 + SC_TISSUE_FORCE_RANGE
                            : t->contacts.count;
    const float *const x[3] = {n->x, n->y, n->z};
    const float *const x0[3] = {m->rest_x, m->rest_y, m->rest_z};
    float f[3] = {0.0f, 0.0f, 0.0f};
    for (uint32_t q = q0; q < q1; q++) {
        const uint32_t i = t->contacts.c[q].node;
        const uint32_t ci[3] = {i % nx, (i / nx) % ny, i / (nx * ny)};
        sc_grid_row_disp(&t->fem.grid, i, ci, x, x0, f);
    }
    jb->f[r][0] = f[0];
    jb->f[r][1] = f[1];
    jb->f[r][2] = f[2];
}

float sc_tissue_probe_force_n(const sc_tissue *t, float out[3])
{
    float f[3] = {0.0f, 0.0f, 0.0f};
    if (out != NULL) {
        out[0] = out[1] = out[2] = 0.0f;
    }
    if (t == NULL || t->build_phase != (uint8_t)SC_TISSUE_BUILD_DONE || t->mesh.node_count == 0u ||
        (t->method == SC_TISSUE_MSDS && t->msds.def.integrator == (uint8_t)SC_MSDS_EXPLICIT)) {
        return -1.0f;
    }
    force_job jb; /* 12 B per range: 3 KB at 64x32x32, 24 B on the MCU's limits */
    jb.t = t;
    const uint32_t ranges =
        (t->contacts.count + SC_TISSUE_FORCE_RANGE - 1u) / SC_TISSUE_FORCE_RANGE;
    SC_ASSERT(ranges <= SC_TISSUE_FORCE_RANGES);
    sc_pool_run(t->pool, job_force, &jb, ranges);
    for (uint32_t r = 0; r < ranges && r < SC_TISSUE_FORCE_RANGES; r++) {
        f[0] += jb.f[r][0]; /* (0 + a range's sum is that sum: a sum from 0 is never -0) */
        f[1] += jb.f[r][1];
        f[2] += jb.f[r][2];
    }
    if (out != NULL) {
        out[0] = f[0];
        out[1] = f[1];
        out[2] = f[2];
    }
    return sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
}

void sc_tissue_set_pool(sc_tissue *t, const sc_pool_dev *pool)
{
    SC_ASSERT(t != NULL);
    t->pool = pool;
    t->collider.pool = pool; /* (the contact phase's init copies t->pool too) */
#if SC_PHYS_LUMEN
    t->lumen.pool = pool; /* (the labels phase's init copies t->pool too) */
#endif
    if (t->build_phase > (uint8_t)SC_TISSUE_BUILD_FEM) {
        t->fem.grid.pool = pool; /* before: the FEM phase copies t->pool (and until then the
                                    FEM's storage holds the springs) */
    }
}
