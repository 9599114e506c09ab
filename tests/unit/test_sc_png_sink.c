/* test_sc_png_sink.c: the PNG display sink writes one file per frame (scan-converted raster of
 * the configured size), never blocks the caller (a frame arriving while the writer is busy is
 * skipped and counted), and refuses lines out of protocol. */
#include "sc_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sc_err.h"
#include "sc_png_sink.h"
#include "sc_scanconv.h"
#include "sc_test_png.h"

static void send_frame(sc_display_dev *d, uint32_t no, uint16_t lines, int skip_line)
{
    const sc_display_frame_info info = {.frame_no = no,
                                        .lines = lines,
                                        .samples = 64u,
                                        .geometry_id = 0u,
                                        .flags = 0u,
                                        .depth_mm = 40.0f,
                                        .width_mm = 38.0f,
                                        .radius_mm = 0.0f};
    uint8_t s[64];
    assert_int_equal(sc_display_frame_begin(d, &info), 0);
    for (uint16_t l = 0; l < lines; l++) {
        if ((int)l == skip_line) {
            continue;
        }
        memset(s, (int)(l * 3u), sizeof s);
        assert_int_equal(sc_display_line(d, no, l, s, 64u), 0);
    }
    (void)sc_display_frame_end(d, SC_DISPLAY_END_PLAIN(no));
}

static uint64_t wait_written(sc_png_sink *s, uint64_t n)
{
    sc_png_sink_stats st;
    for (int i = 0; i < 5000; i++) {
        sc_png_sink_get_stats(s, &st);
        if (st.frames_written + st.write_errors >= n) {
            break;
        }
        usleep(1000);
    }
    return st.frames_written;
}

static void each_frame_becomes_one_png_of_the_configured_size(void **state)
{
    (void)state;
    char dir[] = "/tmp/sc_png_sink_XXXXXX";
    assert_non_null(mkdtemp(dir));
    sc_png_sink *s = NULL;
    const sc_png_sink_def def = {.dir = dir, .width_px = 200u, .height_px = 150u};
    assert_int_equal(sc_png_sink_open(&s, &def), 0);
    sc_display_dev d = sc_png_sink_dev(s);
    for (uint32_t f = 1; f <= 3u; f++) {
        send_frame(&d, f, 32u, f == 2u ? 5 : -1);
        assert_int_equal(wait_written(s, f), f);
    }
    sc_png_sink_stats st;
    sc_png_sink_get_stats(s, &st);
    assert_int_equal(st.frames, 3u);
    assert_int_equal(st.frames_incomplete, 1u);
    assert_int_equal(st.frames_busy, 0u);
    sc_png_sink_close(s);
    uint8_t *img[4] = {NULL};
    for (uint32_t f = 1; f <= 3u; f++) {
        char path[128];
        snprintf(path, sizeof path, "%s/frame_%06u.png", dir, f);
        uint32_t w = 0, h = 0, ch = 0;
        assert_int_equal(sc_test_png_read(path, &w, &h, &ch, &img[f]), 0);
        /* the image's box in the 200 x 150 canvas: 38 x 40 mm at 40/150 mm per pixel is
         * 142 x 150, no black columns beside it */
        assert_int_equal(w, 142u);
        assert_int_equal(h, 150u);
        const sc_display_frame_info g = {.lines = 32u, .samples = 64u, .depth_mm = 40.0f,
                                         .width_mm = 38.0f};
        uint32_t fw = 0, fh = 0;
        sc_scanconv_fit_size(&g, 200u, 150u, &fw, &fh);
        assert_int_equal(w, fw);
        assert_int_equal(h, fh);
        assert_int_equal(ch, 1u);
        uint32_t lit = 0;
        for (uint32_t i = 0; i < w * h; i++) {
            lit += img[f][i] != 0u;
        }
        assert_true(lit > w * h / 2u); /* the lines' echoes, scan converted */
        remove(path);
    }
    /* frames 1 and 3 carried the same lines; frame 2 lost line 5 */
    assert_memory_equal(img[1], img[3], 142u * 150u);
    assert_memory_not_equal(img[1], img[2], 142u * 150u);
    for (uint32_t f = 1; f <= 3u; f++) {
        free(img[f]);
    }
    rmdir(dir);
}

static void frames_while_the_writer_is_busy_are_skipped_not_waited_for(void **state)
{
    (void)state;
    char dir[] = "/tmp/sc_png_sink_XXXXXX";
    assert_non_null(mkdtemp(dir));
    sc_png_sink *s = NULL;
    const sc_png_sink_def def = {.dir = dir, .width_px = 1024u, .height_px = 1024u};
    assert_int_equal(sc_png_sink_open(&s, &def), 0);
    sc_display_dev d = sc_png_sink_dev(s);
    for (uint32_t f = 0; f < 200u; f++) {
        send_frame(&d, f, 16u, -1);
    }
    sc_png_sink_close(s); /* finishes the pending file */
    /* every frame was either written or skipped; with 200 back-to-back frames of 1 MiB files
     * the writer cannot have kept up with all of them */
    char cmd[160];
    snprintf(cmd, sizeof cmd, "ls %s | wc -l", dir);
    FILE *p = popen(cmd, "r");
    int files = 0;
    assert_int_equal(fscanf(p, "%d", &files), 1);
    pclose(p);
    assert_true(files >= 1 && files < 200);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

static void protocol_violations_are_refused(void **state)
{
    (void)state;
    assert_int_equal(
        sc_png_sink_open(&(sc_png_sink *){NULL}, &(sc_png_sink_def){.dir = "/nonexistent-dir"}),
        SC_ERR_NOT_FOUND);
    sc_png_sink *s = NULL;
    assert_int_equal(sc_png_sink_open(&s, &(sc_png_sink_def){.dir = "/tmp", .max_frames = 1u}), 0);
    sc_display_dev d = sc_png_sink_dev(s);
    uint8_t smp[8] = {0};
    assert_int_equal(sc_display_line(&d, 1u, 0u, smp, 8u), SC_ERR_STATE);
    const sc_display_frame_info bad = {.frame_no = 1u,
                                       .lines = 0u,
                                       .samples = 8u,
                                       .geometry_id = 0u,
                                       .flags = 0u,
                                       .depth_mm = 40.0f,
                                       .width_mm = 38.0f,
                                       .radius_mm = 0.0f};
    assert_int_equal(sc_display_frame_begin(&d, &bad), SC_ERR_RANGE);
    const sc_display_frame_info ok = {.frame_no = 1u,
                                      .lines = 4u,
                                      .samples = 8u,
                                      .geometry_id = 0u,
                                      .flags = 0u,
                                      .depth_mm = 40.0f,
                                      .width_mm = 38.0f,
                                      .radius_mm = 0.0f};
    assert_int_equal(sc_display_frame_begin(&d, &ok), 0);
    assert_int_equal(sc_display_line(&d, 1u, 4u, smp, 8u), SC_ERR_STATE);
    assert_int_equal(sc_display_line(&d, 1u, 0u, smp, 7u), SC_ERR_STATE);
    assert_int_equal(sc_display_frame_end(&d, SC_DISPLAY_END_PLAIN(2u)), SC_ERR_STATE);
    sc_png_sink_stats st;
    sc_png_sink_get_stats(s, &st);
    assert_int_equal(st.protocol_errors, 5u);
    sc_png_sink_close(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(each_frame_becomes_one_png_of_the_configured_size),
        cmocka_unit_test(frames_while_the_writer_is_busy_are_skipped_not_waited_for),
        cmocka_unit_test(protocol_violations_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
