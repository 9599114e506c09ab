/*
 * sc_rtcfg.h: the engine's runtime configuration: one text file of `key = value` lines.
 *
 * Syntax: one setting per line, `key = value`; blank lines and lines whose first non-blank
 * character is '#' are ignored; a '#' preceded by a blank ends the line's value (comment);
 * leading and trailing blanks of key and value are dropped; lines end with LF or CR LF; a line
 * is at most SC_RTCFG_LINE_MAX bytes. Every key has a default (sc_rtcfg_default) and a range;
 * a key may appear once per file. The keys, their defaults, ranges and meaning are in the table
 * this module exports (sc_rtcfg_key_describe) and in the documented default file
 * config/sonocomp.conf.
 *
 * Every bad line is refused with its line number, the key and a reason in words; parsing goes
 * on after an error so that one run reports all of them; the settings of refused lines keep
 * their previous values, and the caller must not use the result when any line was refused.
 *
 * Thread and memory rules: pure functions over caller buffers and a caller-owned sc_rtcfg;
 * reentrant. Never allocates, never calls the OS or stdio (the platform reads the file), no
 * locale: numbers are plain decimal ("1.5", "-3", "2e-3").
 */
#ifndef SC_RTCFG_H
#define SC_RTCFG_H

#include <stddef.h>
#include <stdint.h>

#include "sc_config.h"

/* Network interface names are at most 15 characters (Linux IFNAMSIZ 16 with the NUL). */
#define SC_RTCFG_IFNAME_MAX 16u
#define SC_RTCFG_HOST_MAX   64u
#define SC_RTCFG_REASON_MAX 128u
#define SC_RTCFG_KEY_MAX    32u

typedef enum sc_rtcfg_target {
    SC_RTCFG_TARGET_NONE = 0, /* "none": images are computed and discarded */
    SC_RTCFG_TARGET_UDP,      /* "udp:HOST:PORT": display link (docs/display-link.md) */
    SC_RTCFG_TARGET_PNG,      /* "png:DIR": each frame as a PNG file in DIR */
    SC_RTCFG_TARGET_DRM,      /* "drm" or "drm:/dev/dri/cardN": KMS dumb buffer */
    SC_RTCFG_TARGET_FBDEV,    /* "fbdev" or "fbdev:/dev/fbN" */
} sc_rtcfg_target;

typedef enum sc_rtcfg_method { SC_RTCFG_METHOD_MSDS = 0, SC_RTCFG_METHOD_FEM = 1 } sc_rtcfg_method;
typedef enum sc_rtcfg_geometry {
    SC_RTCFG_GEOMETRY_LINEAR = 0,
    SC_RTCFG_GEOMETRY_CURVILINEAR = 1
} sc_rtcfg_geometry;
typedef enum sc_rtcfg_tristate {
    SC_RTCFG_AUTO = 0,
    SC_RTCFG_ON = 1,
    SC_RTCFG_OFF = 2
} sc_rtcfg_tristate;

typedef struct sc_rtcfg {
    char can_interface[SC_RTCFG_IFNAME_MAX]; /* can.interface */
    /* display.target, split: kind, then host+port (UDP) or path (PNG dir, DRM/fbdev device;
     * empty: the sink's default device) */
    uint32_t display_target; /* sc_rtcfg_target */
    char display_host[SC_RTCFG_HOST_MAX];
    uint32_t display_port;
    char display_path[SC_RTCFG_PATH_MAX];
    uint32_t frame_rate_hz;
    char case_path[SC_RTCFG_PATH_MAX]; /* case: case file path */
    uint32_t physics_method;           /* sc_rtcfg_method */
    uint32_t physics_iterations;
    float physics_dt_s;
    uint32_t physics_cg_iterations; /* CG iterations per frame: stable MSDS, FEM */
    uint32_t image_geometry; /* sc_rtcfg_geometry */
    float image_depth_mm;
    float image_width_mm;   /* linear aperture */
    float image_sector_deg; /* curvilinear sector angle */
    uint32_t image_lines;
    uint32_t image_samples;
    float image_gain_db;
    float image_tgc_db[SC_BSCAN_TGC_BANDS]; /* shallow to deep bands */
    float image_dynamic_range_db;
    uint32_t rt_sched_fifo;                  /* bool */
    uint32_t rt_priority;                    /* SCHED_FIFO priority 1..99 */
    int32_t rt_cpu;                          /* -1: no pinning */
    uint32_t rt_mlock;                       /* bool */
    uint32_t rt_hugepages;                   /* bool: the engine's state on 2 MiB pages */
    char watchdog_device[SC_RTCFG_PATH_MAX]; /* "none", "soft" or a device path */
    uint32_t watchdog_timeout_ms;
    uint32_t tracker_timeout_ms;
    char can_auth_key[SC_RTCFG_PATH_MAX]; /* bench | 32 hex digits | file:/path */
    uint32_t can_auth_window;
    int32_t can_auth_floor_s; /* -1: no floor */
    uint32_t log_level;   /* sc_log_level of hal/sc_hal_log.h */
    uint32_t status_line; /* sc_rtcfg_tristate: auto = on when stderr is a terminal */
} sc_rtcfg;

/* One refused line. */
typedef struct sc_rtcfg_error {
    int err;                          /* SC_ERR_CFG_* */
    uint32_t line;                    /* 1-based line number; 0 for sc_rtcfg_set */
    char key[SC_RTCFG_KEY_MAX];       /* the key as written (truncated), or "" */
    char reason[SC_RTCFG_REASON_MAX]; /* e.g. "500 is outside 1 .. 240" */
} sc_rtcfg_error;

/* Description of one key, for --help and the documentation test. The texts are generated
 * from the limits this build was compiled with (config/sc_config.h). */
typedef struct sc_rtcfg_key_info {
    const char *name;
    const char *help;
    char default_text[SC_RTCFG_REASON_MAX]; /* parses to the default */
    char range_text[SC_RTCFG_REASON_MAX];   /* what is accepted, in words */
} sc_rtcfg_key_info;

/* Fill every key with its default. O(keys). Never fails (the defaults are checked by a test). */
void sc_rtcfg_default(sc_rtcfg *cfg);

/* Apply the lines of text[0..len) over cfg (call sc_rtcfg_default first). Refused lines are
 * reported in errs[0 .. max_errs) (further ones only counted) and leave their keys unchanged.
 * Returns the number of refused lines (0: all good); *n_errs_stored, if not NULL, receives
 * how many were stored. O(len + lines x keys), never allocates. Error codes in errs:
 * SC_ERR_CFG_SYNTAX (no '=', empty key, control character), SC_ERR_CFG_KEY (unknown key),
 * SC_ERR_CFG_VALUE (malformed or empty value, not finite, wrong count), SC_ERR_CFG_RANGE (out
 * of range), SC_ERR_CFG_DUPLICATE (key already set in this text), SC_ERR_CFG_TOO_LONG (line or
 * value above its limit). text may contain NUL bytes only as a syntax error. */
uint32_t sc_rtcfg_parse(sc_rtcfg *cfg, const char *text, size_t len, sc_rtcfg_error *errs,
                        uint32_t max_errs, uint32_t *n_errs_stored);

/* Set one key from a value string (command-line override, e.g. --set image.depth_mm=60).
 * Returns 0 or the SC_ERR_CFG_* code, with *err filled (line 0) when err is not NULL.
 * O(keys + value length). */
int sc_rtcfg_set(sc_rtcfg *cfg, const char *key, const char *value, sc_rtcfg_error *err);

/* Key table: number of keys, and the description of the i-th (SC_ERR_RANGE past the end).
 * O(1). */
uint32_t sc_rtcfg_key_count(void);
int sc_rtcfg_key_describe(uint32_t i, sc_rtcfg_key_info *out);

/* Text names of enumerated values (static strings; "?" when out of range). */
const char *sc_rtcfg_target_name(uint32_t target);
const char *sc_rtcfg_method_name(uint32_t method);
const char *sc_rtcfg_geometry_name(uint32_t geometry);

#endif /* SC_RTCFG_H */
