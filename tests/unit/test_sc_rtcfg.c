/* test_sc_rtcfg.c: runtime configuration: every key parsed, every class of bad value refused
 * with its line number and a reason, the documented default file equal to the defaults. */
#include "sc_test.h"

#include <stdio.h>
#include <string.h>

#include "sc_config.h"
#include "sc_err.h"
#include "sc_rtcfg.h"

static uint32_t parse_text(sc_rtcfg *c, const char *text, sc_rtcfg_error *errs, uint32_t max)
{
    uint32_t stored = 0;
    uint32_t bad = sc_rtcfg_parse(c, text, strlen(text), errs, max, &stored);
    assert_true(stored <= max);
    return bad;
}

static void defaults_follow_the_compile_time_limits(void **state)
{
    (void)state;
    sc_rtcfg c;
    sc_rtcfg_default(&c);
    assert_string_equal(c.can_interface, "can0");
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_UDP);
    assert_string_equal(c.display_host, "127.0.0.1");
    assert_int_equal(c.display_port, 5600);
    assert_int_equal(c.frame_rate_hz, SC_FRAME_RATE_DEFAULT_HZ);
    assert_int_equal(c.physics_method, SC_RTCFG_METHOD_MSDS);
    assert_int_equal(c.physics_iterations, SC_PHYS_ITERATIONS_DEFAULT);
    assert_int_equal(c.physics_cg_iterations, SC_PHYS_CG_ITERATIONS_DEFAULT);
    /* the default is printed with 6 decimals and parsed back: 0.01 round-trips exactly */
    assert_memory_equal(&c.physics_dt_s, &(float){SC_PHYS_DT_DEFAULT_S}, sizeof(float));
    assert_int_equal(c.image_geometry, SC_RTCFG_GEOMETRY_LINEAR);
    assert_true(c.image_lines <= SC_MAX_SCAN_LINES && c.image_samples <= SC_MAX_SCAN_SAMPLES);
    assert_int_equal(c.rt_cpu, -1);
    assert_int_equal(c.rt_sched_fifo, 1);
    assert_string_equal(c.watchdog_device, "soft");
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        assert_true(c.image_tgc_db[i] >= 0.0f && c.image_tgc_db[i] <= 0.0f);
    }
}

static void every_key_is_described_and_its_default_text_parses_to_the_default(void **state)
{
    (void)state;
    sc_rtcfg def;
    sc_rtcfg_default(&def);
    assert_true(sc_rtcfg_key_count() >= 24u);
    for (uint32_t i = 0; i < sc_rtcfg_key_count(); i++) {
        sc_rtcfg_key_info k;
        assert_int_equal(sc_rtcfg_key_describe(i, &k), 0);
        assert_true(strlen(k.name) > 0u && strlen(k.help) > 0u);
        assert_true(strlen(k.default_text) > 0u && strlen(k.range_text) > 0u);
        sc_rtcfg c = def;
        sc_rtcfg_error e;
        assert_int_equal(sc_rtcfg_set(&c, k.name, k.default_text, &e), 0);
        assert_memory_equal(&c, &def, sizeof c);
    }
    sc_rtcfg_key_info k;
    assert_int_equal(sc_rtcfg_key_describe(sc_rtcfg_key_count(), &k), SC_ERR_RANGE);
}

static void documented_default_file_sets_every_key_to_its_default(void **state)
{
    (void)state;
    static char text[16384];
    FILE *f = fopen(SC_SOURCE_DIR "/config/sonocomp.conf", "rb");
    assert_non_null(f);
    size_t n = fread(text, 1, sizeof text - 1u, f);
    fclose(f);
    text[n] = '\0';
    sc_rtcfg def, c;
    sc_rtcfg_default(&def);
    /* start from a state where every key differs from its default, so that the file has to set
     * them all: a key missing from the file leaves a difference */
    memset(&c, 0x5A, sizeof c);
    sc_rtcfg_error errs[4];
    assert_int_equal(parse_text(&c, text, errs, 4u), 0);
    for (uint32_t i = 0; i < sc_rtcfg_key_count(); i++) {
        sc_rtcfg_key_info k;
        sc_rtcfg_key_describe(i, &k);
        char needle[300];
        snprintf(needle, sizeof needle, "\n%s = %s\n", k.name, k.default_text);
        if (!strstr(text, needle)) {
            print_error("default file lacks \"%s = %s\"\n", k.name, k.default_text);
        }
        assert_non_null(strstr(text, needle));
    }
    /* text fields: compare up to their NUL; numeric fields bit-exact */
    assert_string_equal(c.can_interface, def.can_interface);
    assert_string_equal(c.display_host, def.display_host);
    assert_string_equal(c.case_path, def.case_path);
    assert_string_equal(c.watchdog_device, def.watchdog_device);
    assert_int_equal(c.display_target, def.display_target);
    assert_int_equal(c.display_port, def.display_port);
    assert_int_equal(c.frame_rate_hz, def.frame_rate_hz);
    assert_int_equal(c.physics_method, def.physics_method);
    assert_int_equal(c.physics_iterations, def.physics_iterations);
    assert_int_equal(c.physics_cg_iterations, def.physics_cg_iterations);
    assert_memory_equal(&c.physics_dt_s, &def.physics_dt_s, sizeof(float));
    assert_int_equal(c.image_geometry, def.image_geometry);
    assert_memory_equal(&c.image_depth_mm, &def.image_depth_mm, sizeof(float));
    assert_memory_equal(&c.image_width_mm, &def.image_width_mm, sizeof(float));
    assert_memory_equal(&c.image_sector_deg, &def.image_sector_deg, sizeof(float));
    assert_int_equal(c.image_lines, def.image_lines);
    assert_int_equal(c.image_samples, def.image_samples);
    assert_memory_equal(&c.image_gain_db, &def.image_gain_db, sizeof(float));
    assert_memory_equal(c.image_tgc_db, def.image_tgc_db, sizeof def.image_tgc_db);
    assert_memory_equal(&c.image_dynamic_range_db, &def.image_dynamic_range_db, sizeof(float));
    assert_int_equal(c.rt_sched_fifo, def.rt_sched_fifo);
    assert_int_equal(c.rt_priority, def.rt_priority);
    assert_int_equal(c.rt_cpu, def.rt_cpu);
    assert_int_equal(c.rt_mlock, def.rt_mlock);
    assert_int_equal(c.rt_hugepages, def.rt_hugepages);
    assert_int_equal(c.watchdog_timeout_ms, def.watchdog_timeout_ms);
    assert_int_equal(c.tracker_timeout_ms, def.tracker_timeout_ms);
    assert_int_equal(c.log_level, def.log_level);
    assert_int_equal(c.status_line, def.status_line);
}

static void every_key_accepts_a_valid_non_default_value(void **state)
{
    (void)state;
    const char *text = "can.interface = vcan0\n"
                       "display.target = udp:display.local:6000\n"
                       "frame_rate_hz = 240\n"
                       "case = /var/lib/sonocomp/femoral vein.sccase\n"
                       "physics.method = fem\n"
                       "physics.iterations = 35\n"
                       "physics.dt_s = 2.5e-3\n"
                       "physics.cg_iterations = 8\n"
                       "image.geometry = curvilinear\n"
                       "image.depth_mm = 120.5\n"
                       "image.width_mm = 50\n"
                       "image.sector_deg = 75\n"
                       "image.lines = 128\n"
                       "image.samples = 512\n"
                       "image.gain_db = -12.25\n"
                       "image.tgc_db = -20, -1.5, 0, 1 2 3,4 , 20\n"
                       "image.dynamic_range_db = 72\n"
                       "rt.sched_fifo = no\n"
                       "rt.priority = 99\n"
                       "rt.cpu = 1\n"
                       "rt.mlock = off\n"
                       "rt.hugepages = no\n"
                       "watchdog.device = /dev/watchdog0\n"
                       "watchdog.timeout_ms = 250\n"
                       "tracker.timeout_ms = 5000\n"
                       "can.auth_key = 00112233445566778899AABBCCDDEEFF\n"
                       "can.auth_window = 16\n"
                       "can.auth_floor_s = -1\n"
                       "log.level = debug\n"
                       "status.line = off\n";
    sc_rtcfg c;
    sc_rtcfg_default(&c);
    sc_rtcfg_error errs[4];
    assert_int_equal(parse_text(&c, text, errs, 4u), 0);
    assert_string_equal(c.can_interface, "vcan0");
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_UDP);
    assert_string_equal(c.display_host, "display.local");
    assert_int_equal(c.display_port, 6000);
    assert_int_equal(c.frame_rate_hz, 240);
    assert_string_equal(c.case_path, "/var/lib/sonocomp/femoral vein.sccase");
    assert_int_equal(c.physics_method, SC_RTCFG_METHOD_FEM);
    assert_int_equal(c.physics_iterations, 35);
    assert_int_equal(c.physics_cg_iterations, 8);
    /* decimal parsing: within one float ulp of the value (float has 24 bits) */
    assert_float_equal(c.physics_dt_s, 0.0025f, 0.0025f * 1.2e-7f);
    assert_int_equal(c.image_geometry, SC_RTCFG_GEOMETRY_CURVILINEAR);
    assert_float_equal(c.image_depth_mm, 120.5f, 0.0f);
    assert_float_equal(c.image_width_mm, 50.0f, 0.0f);
    assert_float_equal(c.image_sector_deg, 75.0f, 0.0f);
    assert_int_equal(c.image_lines, 128);
    assert_int_equal(c.image_samples, 512);
    assert_float_equal(c.image_gain_db, -12.25f, 0.0f);
    const float tgc[8] = {-20.0f, -1.5f, 0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 20.0f};
    for (int i = 0; i < 8; i++) {
        assert_float_equal(c.image_tgc_db[i], tgc[i], 0.0f);
    }
    assert_float_equal(c.image_dynamic_range_db, 72.0f, 0.0f);
    assert_int_equal(c.rt_sched_fifo, 0);
    assert_int_equal(c.rt_priority, 99);
    assert_int_equal(c.rt_cpu, 1);
    assert_int_equal(c.rt_mlock, 0);
    assert_int_equal(c.rt_hugepages, 0);
    assert_string_equal(c.watchdog_device, "/dev/watchdog0");
    assert_int_equal(c.watchdog_timeout_ms, 250);
    assert_int_equal(c.tracker_timeout_ms, 5000);
    assert_string_equal(c.can_auth_key, "00112233445566778899AABBCCDDEEFF");
    assert_int_equal(c.can_auth_window, 16);
    assert_int_equal(c.can_auth_floor_s, -1);
    assert_int_equal(sc_rtcfg_set(&c, "can.auth_key", "file:/etc/sonocomp/cmd.key", NULL), 0);
    assert_string_equal(c.can_auth_key, "file:/etc/sonocomp/cmd.key");
    /* not a key: 31 or 33 digits, a non-hex digit, a relative file */
    const char *bad[] = {"00112233445566778899AABBCCDDEEF", "00112233445566778899AABBCCDDEEFF0",
                         "g0112233445566778899AABBCCDDEEFF", "file:cmd.key", "Bench"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sc_rtcfg_error e;
        assert_int_equal(sc_rtcfg_set(&c, "can.auth_key", bad[i], &e), SC_ERR_CFG_VALUE);
        assert_string_equal(c.can_auth_key, "file:/etc/sonocomp/cmd.key");
    }
    assert_int_equal(sc_rtcfg_set(&c, "can.auth_window", "0", NULL), SC_ERR_CFG_RANGE);
    assert_int_equal(sc_rtcfg_set(&c, "can.auth_window", "32769", NULL), SC_ERR_CFG_RANGE);
    assert_int_equal(c.log_level, 0);
    assert_int_equal(c.status_line, SC_RTCFG_OFF);
}

static void display_targets_of_every_kind_parse(void **state)
{
    (void)state;
    sc_rtcfg c;
    sc_rtcfg_default(&c);
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "png:/tmp/frames", NULL), 0);
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_PNG);
    assert_string_equal(c.display_path, "/tmp/frames");
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "drm", NULL), 0);
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_DRM);
    assert_string_equal(c.display_path, "");
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "drm:/dev/dri/card1", NULL), 0);
    assert_string_equal(c.display_path, "/dev/dri/card1");
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "fbdev:/dev/fb0", NULL), 0);
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_FBDEV);
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "fbdev", NULL), 0);
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "none", NULL), 0);
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_NONE);
    assert_int_equal(sc_rtcfg_set(&c, "display.target", "udp:10.0.0.2:1", NULL), 0);
    assert_int_equal(c.display_port, 1);
    assert_string_equal(sc_rtcfg_target_name(c.display_target), "udp");
}

typedef struct bad_case {
    const char *key;
    const char *value;
    int err;
} bad_case;

static void every_class_of_bad_value_is_refused_with_a_reason(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        /* integers: malformed, fractional, below, above, negative, overflowing */
        {"frame_rate_hz", "sixty", SC_ERR_CFG_VALUE},
        {"frame_rate_hz", "60.5", SC_ERR_CFG_VALUE},
        {"frame_rate_hz", "0", SC_ERR_CFG_RANGE},
        {"frame_rate_hz", "241", SC_ERR_CFG_RANGE},
        {"frame_rate_hz", "-60", SC_ERR_CFG_RANGE},
        {"frame_rate_hz", "99999999999999999999999999999999999", SC_ERR_CFG_RANGE},
        {"frame_rate_hz", "60 Hz", SC_ERR_CFG_VALUE},
        {"physics.iterations", "0", SC_ERR_CFG_RANGE},
        {"physics.iterations", "201", SC_ERR_CFG_RANGE},
        {"physics.cg_iterations", "0", SC_ERR_CFG_RANGE},
        {"physics.cg_iterations", "201", SC_ERR_CFG_RANGE},
        {"physics.cg_iterations", "-3", SC_ERR_CFG_RANGE},
        {"physics.cg_iterations", "8.5", SC_ERR_CFG_VALUE},
        {"image.lines", "15", SC_ERR_CFG_RANGE},
        {"image.lines", "513", SC_ERR_CFG_RANGE},
        {"image.samples", "0x100", SC_ERR_CFG_VALUE},
        {"rt.priority", "100", SC_ERR_CFG_RANGE},
        {"rt.cpu", "-2", SC_ERR_CFG_RANGE},
        {"rt.cpu", "1024", SC_ERR_CFG_RANGE},
        {"rt.cpu", "--1", SC_ERR_CFG_VALUE},
        {"watchdog.timeout_ms", "99", SC_ERR_CFG_RANGE},
        {"tracker.timeout_ms", "5001", SC_ERR_CFG_RANGE},
        /* reals: not finite, malformed, out of range */
        {"physics.dt_s", "nan", SC_ERR_CFG_VALUE},
        {"physics.dt_s", "inf", SC_ERR_CFG_VALUE},
        {"physics.dt_s", "1e999", SC_ERR_CFG_RANGE},
        {"physics.dt_s", "0", SC_ERR_CFG_RANGE},
        {"physics.dt_s", "0.2", SC_ERR_CFG_RANGE},
        {"physics.dt_s", "1.2.3", SC_ERR_CFG_VALUE},
        {"physics.dt_s", "1e", SC_ERR_CFG_VALUE},
        {"physics.dt_s", ".", SC_ERR_CFG_VALUE},
        {"physics.dt_s", "0,01", SC_ERR_CFG_VALUE},
        {"image.depth_mm", "9.99", SC_ERR_CFG_RANGE},
        {"image.depth_mm", "300.01", SC_ERR_CFG_RANGE},
        {"image.width_mm", "4", SC_ERR_CFG_RANGE},
        {"image.sector_deg", "151", SC_ERR_CFG_RANGE},
        {"image.gain_db", "-41", SC_ERR_CFG_RANGE},
        {"image.dynamic_range_db", "19", SC_ERR_CFG_RANGE},
        /* lists: too few, too many, one bad member, one out of range */
        {"image.tgc_db", "0 0 0 0 0 0 0", SC_ERR_CFG_VALUE},
        {"image.tgc_db", "0 0 0 0 0 0 0 0 0", SC_ERR_CFG_VALUE},
        {"image.tgc_db", "0 0 0 x 0 0 0 0", SC_ERR_CFG_VALUE},
        {"image.tgc_db", "0 0 0 0 0 0 0 21", SC_ERR_CFG_RANGE},
        /* enums and booleans */
        {"physics.method", "MSDS", SC_ERR_CFG_VALUE},
        {"physics.method", "sph", SC_ERR_CFG_VALUE},
        {"image.geometry", "phased", SC_ERR_CFG_VALUE},
        {"rt.sched_fifo", "maybe", SC_ERR_CFG_VALUE},
        {"rt.mlock", "2", SC_ERR_CFG_VALUE},
        {"log.level", "verbose", SC_ERR_CFG_VALUE},
        {"status.line", "sometimes", SC_ERR_CFG_VALUE},
        /* text kinds */
        {"can.interface", "can 0", SC_ERR_CFG_VALUE},
        {"can.interface", "can0/1", SC_ERR_CFG_VALUE},
        {"can.interface", "a_very_long_ifname", SC_ERR_CFG_TOO_LONG},
        {"watchdog.device", "dev/watchdog", SC_ERR_CFG_VALUE},
        {"display.target", "tcp:1.2.3.4:5", SC_ERR_CFG_VALUE},
        {"display.target", "udp:1.2.3.4", SC_ERR_CFG_VALUE},
        {"display.target", "udp::5600", SC_ERR_CFG_VALUE},
        {"display.target", "udp:host_name:5600", SC_ERR_CFG_VALUE},
        {"display.target", "udp:1.2.3.4:0", SC_ERR_CFG_RANGE},
        {"display.target", "udp:1.2.3.4:65536", SC_ERR_CFG_RANGE},
        {"display.target", "udp:1.2.3.4:http", SC_ERR_CFG_VALUE},
        {"display.target", "png:", SC_ERR_CFG_VALUE},
        {"display.target", "drm:card0", SC_ERR_CFG_VALUE},
        {"display.target", "UDP:1.2.3.4:5", SC_ERR_CFG_VALUE},
        /* empty */
        {"case", "", SC_ERR_CFG_VALUE},
        {"no.such.key", "1", SC_ERR_CFG_KEY},
    };
    sc_rtcfg def;
    sc_rtcfg_default(&def);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        sc_rtcfg c = def;
        sc_rtcfg_error e;
        memset(&e, 0, sizeof e);
        int rc = sc_rtcfg_set(&c, cases[i].key, cases[i].value, &e);
        if (rc != cases[i].err) {
            print_error("%s = \"%s\": got %s (%s)\n", cases[i].key, cases[i].value, sc_err_name(rc),
                        e.reason);
        }
        assert_int_equal(rc, cases[i].err);
        assert_int_equal(e.err, cases[i].err);
        assert_string_equal(e.key, cases[i].key);
        assert_true(strlen(e.reason) > 5u);      /* a reason in words */
        assert_memory_equal(&c, &def, sizeof c); /* nothing changed */
    }
    /* the reason names the value and the range */
    sc_rtcfg c = def;
    sc_rtcfg_error e;
    sc_rtcfg_set(&c, "frame_rate_hz", "500", &e);
    assert_string_equal(e.reason, "500 is outside 1 .. 240");
    sc_rtcfg_set(&c, "physics.dt_s", "0.5", &e);
    assert_string_equal(e.reason, "0.5 is outside 0.0001 .. 0.1");
    sc_rtcfg_set(&c, "physics.method", "sph", &e);
    assert_string_equal(e.reason, "sph is not one of msds | fem");
    /* a path longer than its buffer */
    char longpath[SC_RTCFG_PATH_MAX + 2u];
    memset(longpath, 'a', sizeof longpath - 1u);
    longpath[sizeof longpath - 1u] = '\0';
    assert_int_equal(sc_rtcfg_set(&c, "case", longpath, &e), SC_ERR_CFG_TOO_LONG);
    longpath[SC_RTCFG_PATH_MAX - 1u] = '\0'; /* exactly the limit */
    assert_int_equal(sc_rtcfg_set(&c, "case", longpath, &e), 0);
}

static void syntax_errors_report_their_line_numbers_and_parsing_goes_on(void **state)
{
    (void)state;
    const char *text = "# comment\n"                             /* 1 */
                       "\n"                                      /* 2 */
                       "frame_rate_hz = 30\n"                    /* 3 ok */
                       "this line has no equals\n"               /* 4 syntax */
                       " = 5\n"                                  /* 5 syntax: no key */
                       "image.depht_mm = 50\n"                   /* 6 unknown key */
                       "frame_rate_hz = 50\n"                    /* 7 duplicate of line 3 */
                       "image.lines =\n"                         /* 8 empty value */
                       "image.samples = 1\x01\n"                 /* 9 control character */
                       "image.depth_mm = 500\n"                  /* 10 range */
                       "   image.gain_db   =   6   # six dB\r\n" /* 11 ok, CRLF, comment */
                       "display.target = png:/tmp/a#b\n"         /* 12 ok: '#' inside value */
                       "rt.cpu = 0";                             /* 13 ok, no final newline */
    sc_rtcfg c;
    sc_rtcfg_default(&c);
    sc_rtcfg_error errs[16];
    uint32_t stored = 0;
    uint32_t bad = sc_rtcfg_parse(&c, text, strlen(text), errs, 16u, &stored);
    assert_int_equal(bad, 7u);
    assert_int_equal(stored, 7u);
    const struct {
        uint32_t line;
        int err;
    } expect[] = {{4, SC_ERR_CFG_SYNTAX},    {5, SC_ERR_CFG_SYNTAX}, {6, SC_ERR_CFG_KEY},
                  {7, SC_ERR_CFG_DUPLICATE}, {8, SC_ERR_CFG_VALUE},  {9, SC_ERR_CFG_SYNTAX},
                  {10, SC_ERR_CFG_RANGE}};
    for (uint32_t i = 0; i < 7u; i++) {
        assert_int_equal(errs[i].line, expect[i].line);
        assert_int_equal(errs[i].err, expect[i].err);
        assert_true(strlen(errs[i].reason) > 5u);
    }
    assert_string_equal(errs[2].key, "image.depht_mm");
    assert_string_equal(errs[3].reason, "already set on line 3");
    assert_string_equal(errs[5].reason, "control character in column 18");
    /* good lines applied, refused ones left at their previous values */
    assert_int_equal(c.frame_rate_hz, 30);
    assert_int_equal(c.image_lines, 256);
    assert_float_equal(c.image_depth_mm, 40.0f, 0.0f);
    assert_float_equal(c.image_gain_db, 6.0f, 0.0f);
    assert_int_equal(c.display_target, SC_RTCFG_TARGET_PNG);
    assert_string_equal(c.display_path, "/tmp/a#b");
    assert_int_equal(c.rt_cpu, 0);
}

static void errors_beyond_the_caller_array_are_still_counted(void **state)
{
    (void)state;
    const char *text = "a = 1\nb = 2\nc = 3\nd = 4\n";
    sc_rtcfg c;
    sc_rtcfg_default(&c);
    sc_rtcfg_error errs[2];
    uint32_t stored = 99;
    assert_int_equal(sc_rtcfg_parse(&c, text, strlen(text), errs, 2u, &stored), 4u);
    assert_int_equal(stored, 2u);
    assert_int_equal(errs[1].line, 2u);
    assert_int_equal(sc_rtcfg_parse(&c, text, strlen(text), NULL, 0u, NULL), 4u);
}

static void overlong_lines_and_nul_bytes_are_refused(void **state)
{
    (void)state;
    static char text[2 * SC_RTCFG_LINE_MAX];
    memset(text, ' ', sizeof text);
    memcpy(text, "case = ", 7u);
    text[SC_RTCFG_LINE_MAX + 1u] = '\n'; /* line 1: LINE_MAX + 1 bytes */
    memcpy(text + SC_RTCFG_LINE_MAX + 2u, "rt.cpu = 1\n", 11u);
    size_t len = SC_RTCFG_LINE_MAX + 13u;
    sc_rtcfg c;
    sc_rtcfg_default(&c);
    sc_rtcfg_error errs[4];
    uint32_t stored = 0;
    assert_int_equal(sc_rtcfg_parse(&c, text, len, errs, 4u, &stored), 1u);
    assert_int_equal(errs[0].err, SC_ERR_CFG_TOO_LONG);
    assert_int_equal(errs[0].line, 1u);
    assert_int_equal(c.rt_cpu, 1);
    const char nul[] = "rt.cpu = 2\0\nrt.priority = 5\n";
    assert_int_equal(sc_rtcfg_parse(&c, nul, sizeof nul - 1u, errs, 4u, &stored), 1u);
    assert_int_equal(errs[0].err, SC_ERR_CFG_SYNTAX);
    assert_int_equal(c.rt_cpu, 1);
    assert_int_equal(c.rt_priority, 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(defaults_follow_the_compile_time_limits),
        cmocka_unit_test(every_key_is_described_and_its_default_text_parses_to_the_default),
        cmocka_unit_test(documented_default_file_sets_every_key_to_its_default),
        cmocka_unit_test(every_key_accepts_a_valid_non_default_value),
        cmocka_unit_test(display_targets_of_every_kind_parse),
        cmocka_unit_test(every_class_of_bad_value_is_refused_with_a_reason),
        cmocka_unit_test(syntax_errors_report_their_line_numbers_and_parsing_goes_on),
        cmocka_unit_test(errors_beyond_the_caller_array_are_still_counted),
        cmocka_unit_test(overlong_lines_and_nul_bytes_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
