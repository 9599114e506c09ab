/*
 * sc_materials.h: default material table, one row per label of config/sc_labels.h.
 *
 * Columns: Young's modulus E (Pa), Poisson ratio nu, density rho (kg/m^3). A case file may
 * carry its own table (MATL section); this one is the default and the test scenes' table.
 * Linear elasticity at the small strains of a compression exam; the values are effective
 * moduli for the tissue as the probe sees it (a vessel is modelled as a solid inclusion whose
 * modulus lumps the wall and the lumen pressure), so vein/artery/thrombus are chosen to give
 * the clinical behaviour (vein collapses, artery and thrombosed vein resist) within the ranges
 * that elastography reports.
 *
 * Sources (ranges):
 *  - skin: 0.1-1 MPa in vivo indentation at low strain (Pailler-Mattei et al., Med Eng Phys
 *    2008, 4.5-8 kPa for the dermis under indentation; higher with the epidermis): 100 kPa.
 *  - fat: 2-4 kPa (Samani et al., Phys Med Biol 2007, breast fat 3.25 +- 0.91 kPa): 3.5 kPa.
 *  - muscle (relaxed, transverse): 10-30 kPa by shear-wave elastography (E = 3 mu,
 *    mu 3-10 kPa; Eby et al., J Biomech 2013): 15 kPa.
 *  - vein: a low-pressure lumen (5-15 mmHg, 0.7-2 kPa) collapses once the probe pressure
 *    exceeds the venous pressure; as a solid this is a very low effective modulus: 0.15 kPa.
 *  - artery: lumen at ~100 mmHg (13 kPa) plus a stiff wall (0.3-1 MPa incremental modulus):
 *    the inclusion resists compression; effective 300 kPa.
 *  - nerve: 30-100 kPa (shear-wave elastography of the median/sciatic nerve): 50 kPa.
 *  - thrombus: organised/chronic thrombus 20-60 kPa, stiffer than fat and like muscle
 *    (Xie et al., Ultrasound Med Biol 2005; shear-wave studies of DVT): 40 kPa.
 *  - bone: cortical bone 10-20 GPa; its nodes are fixed anyway: 10 GPa.
 * Poisson ratios: soft tissue is nearly incompressible (0.45-0.49); 0.45 keeps the linear FEM
 * well conditioned. The vein uses 0.3: the lumen's blood leaves the section, the vessel does
 * not keep its volume. Bone 0.3. Densities: ICRP 89 / Duck, "Physical properties of tissue",
 * 1990: fat 920, soft tissue 1050-1090, blood 1060, bone 1900.
 * Label 0 (outside, air above the skin) gets the fat row so that a mesh box that pokes out of
 * the body stays well posed; a case should not put its mesh there.
 */
#ifndef SC_MATERIALS_H
#define SC_MATERIALS_H

/* X(label enumerator, E_pa, poisson, density_kg_m3) in the order of config/sc_labels.h */
#define SC_MATERIAL_LIST(X)                                                                    \
    X(SC_LABEL_OUTSIDE, 3.5e3f, 0.45f, 920.0f)                                                 \
    X(SC_LABEL_SKIN, 100.0e3f, 0.45f, 1090.0f)                                                 \
    X(SC_LABEL_FAT, 3.5e3f, 0.45f, 920.0f)                                                     \
    X(SC_LABEL_MUSCLE, 15.0e3f, 0.45f, 1050.0f)                                                \
    X(SC_LABEL_VEIN, 0.15e3f, 0.3f, 1060.0f)                                                   \
    X(SC_LABEL_ARTERY, 300.0e3f, 0.45f, 1060.0f)                                               \
    X(SC_LABEL_NERVE, 50.0e3f, 0.45f, 1075.0f)                                                 \
    X(SC_LABEL_THROMBUS, 40.0e3f, 0.45f, 1060.0f)                                              \
    X(SC_LABEL_BONE, 10.0e9f, 0.3f, 1900.0f)

#endif /* SC_MATERIALS_H */
