/*
 * sc_case_drive.h: the optional DRIV section of a case file (docs/case-format.md, "DRIV"): the
 * patient's cardiac and respiratory drive of the vessel lumens (sc_lumen.h): heart rate, arterial
 * pulse pressure, waveform, breathing rate, venous swing, Valsalva rise. The engine applies it at
 * the case swap; a later CmdVessels overrides it (sc_engine.c).
 *
 * Payload (little-endian, 32 bytes, version 1):
 *   u32 version (1), f32 heart rate (1/min: 0 none, else 20..250), f32 pulse pressure (Pa,
 *   0..20,000), u32 waveform (0 arterial, 1 sine), f32 breathing rate (1/min: 0 none, else
 *   4..60), f32 venous swing (Pa, 0..5,000), f32 Valsalva rise (Pa, 0..10,000), u32 0.
 * Every rule is sc_lumen_drive_validate's plus version, size and the reserved word; a DRIV that
 * breaks one refuses the whole case (SC_ERR_CASE_DRIVE), a second DRIV is SC_ERR_CASE_SECTION.
 * A file without DRIV is valid (the engine keeps the drive it has: a CmdVessels' or
 * config/sc_materials.h's defaults); readers older than the section skip it (unknown tag).
 *
 * Pure functions over caller memory; never allocate, never call the OS.
 */
#ifndef SC_CASE_DRIVE_H
#define SC_CASE_DRIVE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_lumen.h"

#define SC_CASE_TAG_DRIV_U32    0x56495244u /* "DRIV" */
#define SC_CASE_DRIVE_VERSION   1u
#define SC_CASE_DRIVE_SIZE      32u

/* The decoded section. present 0: the case has none (d then holds zeros). */
typedef struct sc_case_drive {
    uint8_t present;
    sc_lumen_drive d; /* valsalva (the manoeuvre held) is always 0 from a file */
} sc_case_drive;

/* Validate a DRIV payload p[0..n) and fill *out (present 1). O(1). Errors: SC_ERR_INVALID_ARG
 * (NULL), SC_ERR_CASE_DRIVE (size, version, reserved word, waveform, a non-finite or out-of-
 * range value); *out untouched on error. */
int sc_case_drive_parse(const uint8_t *p, uint64_t n, sc_case_drive *out);

/* Find DRIV in a case image whose framing is already validated and parse it; none: present 0
 * and SC_OK. O(sections). Errors: sc_case_drive_parse's, SC_ERR_CASE_SECTION (two DRIV),
 * SC_ERR_CASE_TRUNCATED. */
int sc_case_drive_find(const uint8_t *bytes, size_t size, sc_case_drive *out);

/* Encode a drive (valsalva ignored) into out[SC_CASE_DRIVE_SIZE]. For builders. Errors:
 * SC_ERR_INVALID_ARG (NULL), sc_lumen_drive_validate's. O(1). */
int sc_case_drive_encode(const sc_lumen_drive *d, uint8_t out[SC_CASE_DRIVE_SIZE]);

#endif /* SC_CASE_DRIVE_H */
