/*
 * sc_materials.h: default material table, one row per label of config/sc_labels.h.
 *
 * Columns: Young's modulus E (Pa), Poisson ratio nu, density rho (kg/m^3). A case file may
 * carry its own table (MATL section); this one is the default and the test scenes' table.
 * Linear elasticity at the small strains of a compression exam; the values are effective
 * moduli for the tissue as the probe sees it. A vessel's tets (vein, artery) are its lumen:
 * what holds it open is the blood pressure through the lumen law (SC_LUMEN_LIST below,
 * core/physics/sc_lumen.h); their row here is only the filler (vein) or the wall's share
 * (artery) the solvers see as solid. A thrombus is solid clot.
 *
 * Sources (ranges):
 *  - skin: 0.1-1 MPa in vivo indentation at low strain (Pailler-Mattei et al., Med Eng Phys
 *    2008, 4.5-8 kPa for the dermis under indentation; higher with the epidermis): 100 kPa.
 *  - fat: 2-4 kPa (Samani et al., Phys Med Biol 2007, breast fat 3.25 +- 0.91 kPa): 3.5 kPa.
 *  - muscle (relaxed, transverse): 10-30 kPa by shear-wave elastography (E = 3 mu,
 *    mu 3-10 kPa; Eby et al., J Biomech 2013): 15 kPa.
 *  - vein: filler of the lumen (blood has no shear stiffness): 0.15 kPa, which keeps its tets
 *    well shaped; the venous pressure is the lumen law's.
 *  - artery: the wall (0.3-1 MPa incremental modulus, ~1 mm thick) spread over the lumen's
 *    tets: 30 kPa; the arterial pressure (93 mmHg) is the lumen law's. (It was 300 kPa as a
 *    solid inclusion lumping wall and pressure, before the lumen law.)
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
    X(SC_LABEL_ARTERY, 30.0e3f, 0.45f, 1060.0f)                                                \
    X(SC_LABEL_NERVE, 50.0e3f, 0.45f, 1075.0f)                                                 \
    X(SC_LABEL_THROMBUS, 40.0e3f, 0.45f, 1060.0f)                                              \
    X(SC_LABEL_BONE, 10.0e9f, 0.3f, 1900.0f)

/* Lumen laws (core/physics/sc_lumen.h): the labels whose tets are a blood-filled lumen, held
 * open by the blood pressure through a pressure-volume (tube) law; every other label is solid.
 * X(label enumerator, kind (1 vein, 2 artery), mean blood pressure H (Pa), lumen stiffness B (Pa))
 *  - vein: central/peripheral venous pressure 5-10 mmHg supine (0.7-1.3 kPa; Guyton, Textbook
 *    of Medical Physiology, ch. 15): 7.5 mmHg, 1.0 kPa; B 10 kPa (a vein is floppy: its
 *    cross-section follows a small pressure change).
 *  - artery: mean arterial pressure 93 mmHg (12.4 kPa); B 60 kPa: with the surrounding tissue
 *    the pulse pressure (40 mmHg) gives a carotid/femoral diameter change of a few percent
 *    (3-10% in vivo, Reneman et al., Ultrasound Med Biol 1986).
 * Thrombus: none (organised clot is solid, its material row above). */
#define SC_LUMEN_LIST(X)                                                                       \
    X(SC_LABEL_VEIN, 1u, 1.0e3f, 10.0e3f)                                                      \
    X(SC_LABEL_ARTERY, 2u, 12.4e3f, 60.0e3f)

/* The lumens' drive (sc_lumen_drive): heart rate 72 / min, arterial pulse pressure 40 mmHg
 * (5.3 kPa), breathing 15 / min with a venous swing of +-3 mmHg (0.4 kPa), a Valsalva
 * manoeuvre raising the venous pressure by 30 mmHg (4 kPa: the jugular vein distends). */
#define SC_LUMEN_HEART_RATE_BPM 72.0f
#define SC_LUMEN_PULSE_PA       5.3e3f
#define SC_LUMEN_RESP_RATE_BPM  15.0f
#define SC_LUMEN_RESP_PA        0.4e3f
#define SC_LUMEN_VALSALVA_PA    4.0e3f

#endif /* SC_MATERIALS_H */
