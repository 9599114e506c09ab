// bench_bullet.cpp: see bench_bullet.h (what Bullet is asked to do per frame).
#include "bench_bullet.h"

#include <cmath>
#include <cstdio>
#include <new>
#include <unordered_set>
#include <vector>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

namespace {

// Lengths in mm (as our mesh): Bullet's soft body has absolute tolerances tuned for metre-sized
// scenes (the sparse SDF's 0.25 voxel, margins), which at a 40 mm block in metres would be
// coarser than the block; in mm the SDF voxel is 0.25 mm. Masses in kg, time in s.
constexpr btScalar kMm = btScalar(1);
constexpr btScalar kDt = btScalar(1.0 / 60.0);
constexpr float kProbeHalfHeightMm = 10.0f;

} // namespace

struct bb_sim {
    btSoftBodyRigidBodyCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
    btBoxShape *probe_shape = nullptr;
    btDefaultMotionState probe_motion;
    btRigidBody *probe = nullptr;
    btSoftBody *body = nullptr;
    std::vector<btVector3> rest;
    float probe_x = 0, probe_y = 0;
    uint32_t links = 0;
};

extern "C" int bb_available(void)
{
    return 1;
}

extern "C" bb_sim *bb_create(const bb_mesh *m, char *err, size_t errn)
{
    if (m == nullptr || m->nodes == 0 || m->tets == 0) {
        std::snprintf(err, errn, "empty mesh");
        return nullptr;
    }
    bb_sim *s = new (std::nothrow) bb_sim();
    if (s == nullptr) {
        std::snprintf(err, errn, "out of memory");
        return nullptr;
    }
    s->world.setGravity(btVector3(0, 0, 0));
    btSoftBodyWorldInfo &wi = s->world.getWorldInfo();
    wi.m_gravity.setValue(0, 0, 0);
    wi.air_density = 0;
    wi.m_sparsesdf.Initialize();

    s->rest.resize(m->nodes);
    std::vector<btScalar> mass(m->nodes, btScalar(1));
    for (uint32_t i = 0; i < m->nodes; i++) {
        s->rest[i] = btVector3(m->x[i] * kMm, m->y[i] * kMm, m->z[i] * kMm);
    }
    // the nodes as btSoftBodyHelpers::CreateFromTetGenData creates them
    btSoftBody *b = new btSoftBody(&wi, int(m->nodes), s->rest.data(), mass.data());
    b->getCollisionShape()->setMargin(btScalar(0.5) * kMm);
    btSoftBody::Material *mat = b->m_materials[0];
    mat->m_kLST = 1;
    mat->m_kAST = 1;
    mat->m_kVST = 1;
    std::unordered_set<uint64_t> seen;
    seen.reserve(size_t(m->tets) * 2);
    static const int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (uint32_t t = 0; t < m->tets; t++) {
        const uint32_t *v = m->tet[t];
        b->appendTetra(int(v[0]), int(v[1]), int(v[2]), int(v[3]), mat);
        for (const auto &e : kEdge) {
            uint32_t a = v[e[0]], c = v[e[1]];
            if (a > c) {
                std::swap(a, c);
            }
            if (seen.insert(uint64_t(a) << 32 | c).second) {
                b->appendLink(int(a), int(c), mat);
            }
        }
    }
    s->links = uint32_t(seen.size());
    const btScalar box_mm3 = btScalar(m->box_mm[0] * m->box_mm[1] * m->box_mm[2]);
    b->setTotalMass(btScalar(1e-6) * box_mm3, false); // 1000 kg/m^3
    for (uint32_t i = 0; i < m->nodes; i++) {
        if (m->fixed[i]) {
            b->setMass(int(i), 0);
        }
    }
    b->m_cfg.piterations = 10;
    b->m_cfg.viterations = 0;
    b->m_cfg.diterations = 0;
    b->m_cfg.kDP = btScalar(0.1);
    b->m_cfg.kCHR = 1;
    b->m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
    s->world.addSoftBody(b);
    s->body = b;

    s->probe_shape = new btBoxShape(btVector3(m->probe_half_mm[0] * kMm,
                                              m->probe_half_mm[1] * kMm, kProbeHalfHeightMm * kMm));
    s->probe_shape->setMargin(btScalar(0.5) * kMm);
    s->probe_x = m->probe_xy_mm[0];
    s->probe_y = m->probe_xy_mm[1];
    btRigidBody::btRigidBodyConstructionInfo ci(0, &s->probe_motion, s->probe_shape);
    s->probe = new btRigidBody(ci);
    s->probe->setCollisionFlags(s->probe->getCollisionFlags() |
                                btCollisionObject::CF_KINEMATIC_OBJECT);
    s->probe->setActivationState(DISABLE_DEACTIVATION);
    s->world.addRigidBody(s->probe);
    bb_set_probe(s, -5.0f);
    return s;
}

extern "C" void bb_set_probe(bb_sim *s, float face_z_mm)
{
    // depth grows with z: the probe face is the box's max-z side, placed at depth face_z_mm
    btTransform t;
    t.setIdentity();
    t.setOrigin(btVector3(s->probe_x * kMm, s->probe_y * kMm, (face_z_mm - kProbeHalfHeightMm) * kMm));
    s->probe_motion.setWorldTransform(t);
    s->probe->setWorldTransform(t);
}

extern "C" void bb_step(bb_sim *s)
{
    s->world.stepSimulation(kDt, 0);
}

extern "C" double bb_max_disp_mm(const bb_sim *s)
{
    double worst = 0;
    const btSoftBody::tNodeArray &n = s->body->m_nodes;
    for (int i = 0; i < n.size(); i++) {
        const double d = double((n[i].m_x - s->rest[size_t(i)]).length());
        if (d > worst || std::isnan(d)) {
            worst = d;
        }
    }
    return worst / double(kMm);
}

extern "C" uint32_t bb_links(const bb_sim *s)
{
    return s->links;
}

extern "C" void bb_destroy(bb_sim *s)
{
    if (s == nullptr) {
        return;
    }
    s->world.removeRigidBody(s->probe);
    s->world.removeSoftBody(s->body);
    delete s->probe;
    delete s->body;
    delete s->probe_shape;
    delete s;
}
