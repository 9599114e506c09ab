/* test_storage_linux.c: the Linux hal storage reads case files into memory it owns, names
 * missing and unreadable files, refuses a FIFO without blocking, keeps a running case intact
 * when its file is truncated underneath, and a corrupt file on disk is refused by the loader
 * through it; the case folder listing. */
#include "sc_test.h"
#include "sc_test_tmpdir.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sc_case.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_storage_linux.h"

static char g_dir[128];

static void write_file(const char *name, const uint8_t *data, size_t n)
{
    char p[256];
    snprintf(p, sizeof p, "%s/%s", g_dir, name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    if (n) {
        assert_int_equal(fwrite(data, 1, n, f), n);
    }
    assert_int_equal(fclose(f), 0);
}

static size_t make_case(uint8_t **out)
{
    static uint8_t vox[8 * 8 * 8], lab[8 * 8 * 8];
    for (size_t i = 0; i < sizeof vox; i++) {
        vox[i] = (uint8_t)i;
        lab[i] = (uint8_t)(i % SC_LABEL_COUNT);
    }
    sc_case_def d = sc_case_default_def();
    d.name = "tiny";
    for (int a = 0; a < 3; a++) {
        d.volume.dim[a] = 8;
        d.volume.spacing_mm[a] = 1.0f;
    }
    d.volume.voxels = vox;
    d.volume.labels = lab;
    d.material_count = SC_LABEL_COUNT;
    for (uint32_t m = 0; m < SC_LABEL_COUNT; m++) {
        d.materials[m] = (sc_case_material){1e4f, 0.45f, 1000.0f};
    }
    d.mesh.nx = d.mesh.ny = d.mesh.nz = 4;
    for (int a = 0; a < 3; a++) {
        d.mesh.origin_mm[a] = 0.0f;
        d.mesh.size_mm[a] = 7.0f;
    }
    size_t need = sc_case_encoded_size(&d), n = 0;
    *out = malloc(need);
    assert_int_equal(sc_case_write(&d, *out, need, &n), SC_OK);
    return n;
}

static void mapped_case_loads_and_points_into_the_mapping(void **state)
{
    (void)state;
    uint8_t *bytes;
    size_t n = make_case(&bytes);
    write_file("tiny.scase", bytes, n);
    sc_storage_linux st;
    sc_storage_linux_init(&st, g_dir);
    sc_storage_dev dev = sc_storage_linux_dev(&st);
    const uint8_t *data = NULL;
    size_t size = 0;
    assert_int_equal(sc_storage_open(&dev, "tiny.scase", &data, &size), SC_OK);
    assert_int_equal(size, n);
    assert_int_equal(st.open_count, 1);
    assert_memory_equal(data, bytes, n);
    sc_case c;
    assert_int_equal(sc_case_load(data, size, &c), SC_OK);
    assert_true(c.volume.voxels >= data && c.volume.voxels < data + size);
    assert_string_equal(c.name, "tiny");
    sc_storage_close(&dev, data, size);
    assert_int_equal(st.open_count, 0);
    /* an absolute path ignores the base directory */
    char p[256];
    snprintf(p, sizeof p, "%s/tiny.scase", g_dir);
    sc_storage_linux_init(&st, "/nonexistent");
    assert_int_equal(sc_storage_open(&dev, p, &data, &size), SC_OK);
    sc_storage_close(&dev, data, size);
    free(bytes);
}

static void missing_unreadable_and_empty_files_are_named(void **state)
{
    (void)state;
    sc_storage_linux st;
    sc_storage_linux_init(&st, g_dir);
    sc_storage_dev dev = sc_storage_linux_dev(&st);
    const uint8_t *data = NULL;
    size_t size = 0;
    assert_int_equal(sc_storage_open(&dev, "nope.scase", &data, &size), SC_ERR_NOT_FOUND);
    assert_true(st.last_errno != 0);
    /* a directory is not a case */
    char p[256];
    snprintf(p, sizeof p, "%s/adir", g_dir);
    assert_int_equal(mkdir(p, 0700), 0);
    assert_int_equal(sc_storage_open(&dev, "adir", &data, &size), SC_ERR_IO);
    /* an empty file maps as size 0 and the loader calls it truncated */
    write_file("empty.scase", NULL, 0);
    assert_int_equal(sc_storage_open(&dev, "empty.scase", &data, &size), SC_OK);
    assert_int_equal(size, 0);
    sc_case c;
    assert_int_equal(sc_case_load(data, size, &c), SC_ERR_CASE_TRUNCATED);
    sc_storage_close(&dev, data, size);
    assert_int_equal(sc_storage_open(&dev, "", &data, &size), SC_ERR_INVALID_ARG);
}

static void fifo_is_refused_without_blocking(void **state)
{
    (void)state;
    char p[256];
    snprintf(p, sizeof p, "%s/pipe.scase", g_dir);
    assert_int_equal(mkfifo(p, 0600), 0);
    sc_storage_linux st;
    sc_storage_linux_init(&st, g_dir);
    sc_storage_dev dev = sc_storage_linux_dev(&st);
    const uint8_t *data = NULL;
    size_t size = 0;
    /* no writer ever opens the FIFO: a blocking open would hang this test */
    assert_int_equal(sc_storage_open(&dev, "pipe.scase", &data, &size), SC_ERR_IO);
    assert_int_equal(st.open_count, 0);
    /* the same for the configuration, CAN logs and pose scripts */
    errno = 0;
    assert_null(sc_fopen_regular(p));
    assert_int_equal(errno, EINVAL);
    assert_null(sc_fopen_regular(g_dir)); /* a directory */
    write_file("plain.txt", (const uint8_t *)"x\n", 2);
    snprintf(p, sizeof p, "%s/plain.txt", g_dir);
    FILE *f = sc_fopen_regular(p);
    assert_non_null(f);
    assert_int_equal(fgetc(f), 'x');
    fclose(f);
}

static void truncating_the_file_under_a_running_case_changes_nothing(void **state)
{
    (void)state;
    uint8_t *bytes = NULL;
    const size_t n = make_case(&bytes);
    write_file("run.scase", bytes, n);
    sc_storage_linux st;
    sc_storage_linux_init(&st, g_dir);
    sc_storage_dev dev = sc_storage_linux_dev(&st);
    const uint8_t *data = NULL;
    size_t size = 0;
    assert_int_equal(sc_storage_open(&dev, "run.scase", &data, &size), SC_OK);
    char p[256];
    snprintf(p, sizeof p, "%s/run.scase", g_dir);
    assert_int_equal(truncate(p, 0), 0); /* a file mapping would now SIGBUS on every access */
    sc_case c;
    assert_int_equal(sc_case_load(data, size, &c), SC_OK);
    assert_memory_equal(data, bytes, n);
    sc_storage_close(&dev, data, size);
    free(bytes);
}

static void case_folder_lists_only_regular_case_files_in_name_order(void **state)
{
    (void)state;
    char d[256];
    snprintf(d, sizeof d, "%s/folder", g_dir);
    assert_int_equal(mkdir(d, 0700), 0);
    const char *files[] = {"c.scase", "a.scase", "b.scase", "notes.txt", ".hidden.scase"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char p[300];
        snprintf(p, sizeof p, "%s/%s", d, files[i]);
        FILE *f = fopen(p, "w");
        assert_non_null(f);
        fclose(f);
    }
    char sub[300];
    snprintf(sub, sizeof sub, "%s/dir.scase", d);
    assert_int_equal(mkdir(sub, 0700), 0);
    char names[4][SC_STORAGE_LINUX_NAME_MAX];
    uint32_t count = 0;
    assert_int_equal(sc_storage_linux_list(d, ".scase", names, 4, &count), SC_OK);
    assert_int_equal(count, 3);
    assert_string_equal(names[0], "a.scase");
    assert_string_equal(names[1], "b.scase");
    assert_string_equal(names[2], "c.scase");
    /* more files than room: the first in order, and the caller is told */
    assert_int_equal(sc_storage_linux_list(d, ".scase", names, 2, &count), SC_ERR_NO_SPACE);
    assert_int_equal(count, 2);
    assert_string_equal(names[0], "a.scase");
    assert_string_equal(names[1], "b.scase");
    snprintf(sub, sizeof sub, "%s/none", g_dir);
    assert_int_equal(sc_storage_linux_list(sub, ".scase", names, 2, &count), SC_ERR_NOT_FOUND);
}

static void corrupt_file_on_disk_is_refused_through_storage(void **state)
{
    (void)state;
    uint8_t *bytes;
    size_t n = make_case(&bytes);
    bytes[n - 100u] ^= 0x10u; /* a bit in the XFRM payload: bytes n-128 .. n-33 */
    write_file("bad.scase", bytes, n);
    write_file("cut.scase", bytes, n / 2u);
    sc_storage_linux st;
    sc_storage_linux_init(&st, g_dir);
    sc_storage_dev dev = sc_storage_linux_dev(&st);
    const uint8_t *data;
    size_t size;
    sc_case c;
    assert_int_equal(sc_storage_open(&dev, "bad.scase", &data, &size), SC_OK);
    assert_int_equal(sc_case_load(data, size, &c), SC_ERR_CASE_CRC);
    sc_storage_close(&dev, data, size);
    assert_int_equal(sc_storage_open(&dev, "cut.scase", &data, &size), SC_OK);
    assert_int_equal(sc_case_load(data, size, &c), SC_ERR_CASE_TRUNCATED);
    sc_storage_close(&dev, data, size);
    free(bytes);
}

static int setup(void **state)
{
    (void)state;
    return sc_test_tmpdir_make(g_dir, sizeof g_dir, "sc_storage");
}

static int teardown(void **state)
{
    (void)state;
    return sc_test_tmpdir_remove(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(mapped_case_loads_and_points_into_the_mapping),
        cmocka_unit_test(missing_unreadable_and_empty_files_are_named),
        cmocka_unit_test(corrupt_file_on_disk_is_refused_through_storage),
        cmocka_unit_test(fifo_is_refused_without_blocking),
        cmocka_unit_test(truncating_the_file_under_a_running_case_changes_nothing),
        cmocka_unit_test(case_folder_lists_only_regular_case_files_in_name_order),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
