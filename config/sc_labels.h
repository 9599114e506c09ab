/*
 * sc_labels.h: tissue labels of the case label map, shared by the case builder, the material
 * table and the B-scan compression measure. Values are stored in case files: never renumber.
 */
#ifndef SC_LABELS_H
#define SC_LABELS_H

#define SC_LABEL_LIST(X)                                                                       \
    X(SC_LABEL_OUTSIDE, 0, "outside") /* air above the skin / outside the body */              \
    X(SC_LABEL_SKIN, 1, "skin")                                                                \
    X(SC_LABEL_FAT, 2, "fat")                                                                  \
    X(SC_LABEL_MUSCLE, 3, "muscle")                                                            \
    X(SC_LABEL_VEIN, 4, "vein")                                                                \
    X(SC_LABEL_ARTERY, 5, "artery")                                                            \
    X(SC_LABEL_NERVE, 6, "nerve")                                                              \
    X(SC_LABEL_THROMBUS, 7, "thrombus")                                                        \
    X(SC_LABEL_BONE, 8, "bone")

enum {
#define SC_LABEL_ENUM_(name, value, text) name = (value),
    SC_LABEL_LIST(SC_LABEL_ENUM_)
#undef SC_LABEL_ENUM_
        SC_LABEL_COUNT
};

#endif /* SC_LABELS_H */
