/*
 * sc_err.h: the one error vocabulary of sonocomp.
 *
 * Every function that can fail returns int: 0 (SC_OK) on success or a negative sc_err
 * enumerator. A void function cannot fail by contract. The list below is the single source
 * of the enumerators and of their strings (X-macro), grouped in blocks per module so that
 * modules add codes without renumbering others. Codes are stable: they travel in status
 * frames and logs.
 *
 * Thread and memory rules: pure constants; sc_err_str() is reentrant, O(1), never allocates.
 */
#ifndef SC_ERR_H
#define SC_ERR_H

/* X(name, value, description) */
#define SC_ERR_LIST(X)                                                                         \
    /* generic: -1 .. -31 */                                                                   \
    X(SC_ERR_INVALID_ARG, -1, "invalid argument")                                              \
    X(SC_ERR_NO_SPACE, -2, "fixed capacity exhausted")                                         \
    X(SC_ERR_NOT_SUPPORTED, -3, "operation not supported by this device")                     \
    X(SC_ERR_WOULD_BLOCK, -4, "no data available now")                                         \
    X(SC_ERR_RANGE, -5, "value out of range")                                                  \
    X(SC_ERR_NOT_FINITE, -6, "value is NaN or infinite")                                       \
    X(SC_ERR_STATE, -7, "operation not allowed in the current state")                         \
    X(SC_ERR_IO, -8, "device or platform I/O error")                                           \
    X(SC_ERR_TIMEOUT, -9, "timed out")                                                         \
    X(SC_ERR_NOT_FOUND, -10, "not found")                                                      \
    X(SC_ERR_PARSE, -11, "malformed input")                                                    \
    X(SC_ERR_OVERFLOW, -12, "arithmetic overflow in a size")                                  \
    /* case file: -32 .. -63 */                                                                \
    X(SC_ERR_CASE_TRUNCATED, -32, "case file truncated")                                       \
    X(SC_ERR_CASE_MAGIC, -33, "case file magic wrong")                                         \
    X(SC_ERR_CASE_VERSION, -34, "case file version unsupported")                              \
    X(SC_ERR_CASE_CRC, -35, "case file section CRC mismatch")                                  \
    X(SC_ERR_CASE_DIMS, -36, "case volume dimensions invalid or above limits")                \
    X(SC_ERR_CASE_SPACING, -37, "case voxel spacing not finite or not positive")              \
    X(SC_ERR_CASE_TRANSFORM, -38, "case transform not finite or not rigid")                   \
    X(SC_ERR_CASE_LABEL, -39, "case label outside the material table")                        \
    X(SC_ERR_CASE_MESH_BOX, -40, "case mesh box outside the volume")                          \
    X(SC_ERR_CASE_MESH_NODES, -41, "case mesh node counts above limits")                      \
    X(SC_ERR_CASE_SECTION, -42, "case section missing, duplicated or misaligned")             \
    X(SC_ERR_CASE_MATERIAL, -43, "case material table invalid")                               \
    X(SC_ERR_CASE_TEXT, -44, "case name or description not terminated or not printable")     \
    X(SC_ERR_CASE_RESERVED, -45, "case reserved field or padding not zero")                   \
    X(SC_ERR_CASE_SIZE, -46, "case section size disagrees with its contents")                 \
    X(SC_ERR_CASE_DEPTH, -47, "case usable imaging depth not finite or out of range")         \
    X(SC_ERR_CASE_DRIVE, -58, "case DRIV section (vessel drive) invalid")                     \
    X(SC_ERR_CASE_SURFACE, -59, "case SURF section (console surfaces) invalid")                \
    /* CAN protocol and E2E: -64 .. -95 */                                                     \
    X(SC_ERR_CAN_ID, -64, "CAN identifier not in the protocol")                               \
    X(SC_ERR_CAN_DLC, -65, "CAN frame length wrong for the message")                          \
    X(SC_ERR_E2E_CRC, -66, "E2E CRC mismatch")                                                 \
    X(SC_ERR_E2E_SEQUENCE, -67, "E2E counter out of sequence")                                \
    X(SC_ERR_E2E_REPEATED, -68, "E2E counter repeated")                                        \
    X(SC_ERR_POSE_IMPLAUSIBLE, -69, "pose fails plausibility checks")                         \
    X(SC_ERR_CAN_BUS_OFF, -70, "CAN controller is bus-off")                                    \
    X(SC_ERR_CAN_SIGNAL, -71, "CAN signal value outside its range")                           \
    /* mesh and physics: -96 .. -127 */                                                        \
    X(SC_ERR_MESH_DIMS, -96, "mesh node counts invalid or above limits")                      \
    X(SC_ERR_MESH_ORIENTATION, -97, "tetrahedron not positively oriented")                    \
    X(SC_ERR_MESH_SPRINGS, -98, "spring count above limit")                                   \
    X(SC_ERR_PHYS_UNSTABLE, -99, "physics state diverged (NaN, Inf or runaway energy)")      \
    X(SC_ERR_FEM_PATTERN, -100, "FEM sparse pattern above limits")                            \
    /* imaging and display link: -128 .. -159 */                                               \
    X(SC_ERR_IMG_GEOMETRY, -128, "scan geometry invalid or above limits")                     \
    X(SC_ERR_DLINK_MAGIC, -129, "display link packet magic wrong")                            \
    X(SC_ERR_DLINK_VERSION, -130, "display link version unsupported")                         \
    X(SC_ERR_DLINK_CRC, -131, "display link packet CRC mismatch")                             \
    X(SC_ERR_DLINK_LENGTH, -132, "display link packet length wrong")                          \
    X(SC_ERR_DLINK_TYPE, -133, "display link packet type unknown")                            \
    X(SC_ERR_DLINK_FIELD, -134, "display link header field out of range")                     \
    /* configuration: -160 .. -191 */                                                          \
    X(SC_ERR_CFG_KEY, -160, "unknown configuration key")                                      \
    X(SC_ERR_CFG_VALUE, -161, "configuration value malformed")                                \
    X(SC_ERR_CFG_RANGE, -162, "configuration value out of range")                             \
    X(SC_ERR_CFG_SYNTAX, -163, "configuration line syntax error")                           \
    X(SC_ERR_CFG_DUPLICATE, -164, "configuration key given twice")                            \
    X(SC_ERR_CFG_TOO_LONG, -165, "configuration line or value too long")

typedef enum sc_err {
    SC_OK = 0,
#define SC_ERR_ENUM_(name, value, text) name = (value),
    SC_ERR_LIST(SC_ERR_ENUM_)
#undef SC_ERR_ENUM_
} sc_err;

/* Human-readable text of an error code (also SC_OK and unknown codes). O(n) in the number of
 * codes, never allocates, never returns NULL. */
const char *sc_err_str(int err);

/* The enumerator's name, e.g. "SC_ERR_CASE_CRC"; "SC_OK"; "SC_ERR_UNKNOWN" otherwise. */
const char *sc_err_name(int err);

#endif /* SC_ERR_H */
