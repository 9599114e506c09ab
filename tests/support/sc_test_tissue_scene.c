/* sc_test_tissue_scene.c: clinical block scene for the physics and imaging tests. */
#include "sc_test_tissue_scene.h"

#include "sc_labels.h"

#define SC_SCENE_SPACING_MM 0.5f
#define SC_SCENE_MAX_DX 129u /* 64 mm / 0.5 + 1 */
#define SC_SCENE_MAX_DY 49u
#define SC_SCENE_MAX_DZ 81u

static uint8_t s_labels[SC_SCENE_MAX_DX * SC_SCENE_MAX_DY * SC_SCENE_MAX_DZ];
static uint8_t s_voxels[SC_SCENE_MAX_DX * SC_SCENE_MAX_DY * SC_SCENE_MAX_DZ];

sc_test_scene_params sc_test_scene_default_params(void)
{
    sc_test_scene_params p;
    p.size_mm[0] = 40.0f;
    p.size_mm[1] = 20.0f;
    p.size_mm[2] = 30.0f;
    p.fat_mm = 20.0f;
    p.vessel_z_mm = 10.0f;
    p.vein_x_mm = 13.0f;
    p.vein_r_mm = 3.0f;
    p.artery_x_mm = 27.0f;
    p.artery_r_mm = 3.0f;
    p.probe_x_mm = 20.0f;
    p.probe_y_mm = 10.0f;
    p.probe_half_mm[0] = 18.0f;
    p.probe_half_mm[1] = 6.0f;
    p.probe_round_mm = 1.0f;
    p.vein_label = SC_LABEL_VEIN;
    p.nx = 32u;
    p.ny = 16u;
    p.nz = 16u;
    return p;
}

static uint32_t dim_of(float size_mm, uint32_t max)
{
    uint32_t d = (uint32_t)(size_mm / SC_SCENE_SPACING_MM) + 1u;
    return d > max ? max : d;
}

void sc_test_scene_build(sc_test_scene *s, const sc_test_scene_params *p)
{
    s->p = *p;
    const uint32_t dx = dim_of(p->size_mm[0], SC_SCENE_MAX_DX);
    const uint32_t dy = dim_of(p->size_mm[1], SC_SCENE_MAX_DY);
    const uint32_t dz = dim_of(p->size_mm[2], SC_SCENE_MAX_DZ);
    for (uint32_t k = 0; k < dz; k++) {
        for (uint32_t j = 0; j < dy; j++) {
            for (uint32_t i = 0; i < dx; i++) {
                const float x = (float)i * SC_SCENE_SPACING_MM;
                const float z = (float)k * SC_SCENE_SPACING_MM;
                uint8_t l = z < p->fat_mm ? SC_LABEL_FAT : SC_LABEL_MUSCLE;
                uint8_t v = z < p->fat_mm ? 70u : 120u;
                const float dvx = x - p->vein_x_mm, dvz = z - p->vessel_z_mm;
                const float dax = x - p->artery_x_mm, daz = z - p->vessel_z_mm;
                if (dvx * dvx + dvz * dvz <= p->vein_r_mm * p->vein_r_mm) {
                    l = p->vein_label;
                    v = p->vein_label == SC_LABEL_VEIN ? 8u : 60u; /* anechoic / clot */
                } else if (dax * dax + daz * daz <= p->artery_r_mm * p->artery_r_mm) {
                    l = SC_LABEL_ARTERY;
                    v = 10u;
                }
                /* deterministic speckle-like texture */
                v = (uint8_t)(v + ((i * 7u + j * 13u + k * 29u) % 17u));
                const uint32_t at = i + dx * (j + dy * k);
                s_labels[at] = l;
                s_voxels[at] = v;
            }
        }
    }
    s->vol.dim[0] = dx;
    s->vol.dim[1] = dy;
    s->vol.dim[2] = dz;
    for (int d = 0; d < 3; d++) {
        s->vol.spacing_mm[d] = SC_SCENE_SPACING_MM;
        s->vol.origin_mm[d] = 0.0f;
    }
    s->vol.voxels = s_voxels;
    s->vol.labels = s_labels;
    s->mesh = sc_mesh_default_def();
    s->mesh.nx = p->nx;
    s->mesh.ny = p->ny;
    s->mesh.nz = p->nz;
    for (int d = 0; d < 3; d++) {
        s->mesh.origin_mm[d] = 0.0f;
        s->mesh.size_mm[d] = p->size_mm[d];
    }
}

sc_pose sc_test_scene_probe(const sc_test_scene *s, float face_z_mm)
{
    sc_pose q = sc_pose_identity();
    q.pos_mm[0] = s->p.probe_x_mm;
    q.pos_mm[1] = s->p.probe_y_mm;
    q.pos_mm[2] = face_z_mm;
    return q;
}

sc_collider_def sc_test_scene_collider(const sc_test_scene *s)
{
    sc_collider_def d = sc_collider_default_def();
    d.shape = SC_COLLIDER_ROUNDED_BOX;
    d.half_mm[0] = s->p.probe_half_mm[0];
    d.half_mm[1] = s->p.probe_half_mm[1];
    d.round_radius_mm = s->p.probe_round_mm;
    return d;
}

sc_tissue_def sc_test_scene_tissue_def(const sc_test_scene *s, sc_tissue_method m)
{
    sc_tissue_def d = sc_tissue_default_def();
    d.mesh = s->mesh;
    d.collider = sc_test_scene_collider(s);
    d.skin.origin_mm[0] = 0.0f;
    d.skin.origin_mm[1] = 0.0f;
    d.skin.size_mm[0] = s->p.size_mm[0];
    d.skin.size_mm[1] = s->p.size_mm[1];
    d.skin.z_mm = 0.0f;
    d.method = m;
    return d;
}
