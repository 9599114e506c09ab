/* fuzz_import_nrrd.c: the case builder's NRRD reader (sc_image_read_ex on .nrrd, and on .nhdr
 * with a detached data.raw; raw, gzip and ascii encodings) takes any bytes: no crash, no leak,
 * no allocation or inflation beyond the voxel ceiling; a successful read has finite voxels and
 * spacing in range, a refusal a message. */
#include "sc_fuzz_import.h" /* first: it sets _GNU_SOURCE */

#include <zlib.h>

#ifdef SC_HAVE_TEEM
/* libnrrd 1.12 (Debian's libteem) leaks inside its own reader on malformed input: its gzip
 * reader's state (_nrrdGzOpen: the zlib stream and buffers, about 40 KB) when a gzip stream is
 * corrupt or ends early, and a field parser's scratch airArray (88 + 4096 bytes) when a header
 * line is malformed (tests/fuzz/regress/import_nrrd/teem-header-airarray). Bugs of the library,
 * not of sonocomp, in a one-shot host tool. Suppressed for allocations made under nrrdLoad's
 * reader only: the Nrrd that read_nrrd() itself creates (nrrdNew) is allocated outside it, so a
 * missing nrrdNuke() on any of our paths still fails the target. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:_nrrdGzOpen\nleak:_nrrdRead\n";
}
/* libteem is built without frame pointers: the fast unwinder stops inside it, before the
 * _nrrdRead frame the suppression names, so this target unwinds allocations the slow way. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "fast_unwind_on_malloc=0";
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0u) {
        return 0;
    }
    sc_fuzz_import_run((data[size - 1u] & 1u) ? "in.nhdr" : "in.nrrd", data, size);
    return 0;
}

static size_t gzip_seed(uint8_t *buf, size_t cap)
{
    static const char hdr[] = "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 3 2 2\n"
                              "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,2)\n"
                              "space origin: (1,2,3)\nencoding: gzip\nendian: big\n\n";
    uint8_t raw[24], z[256];
    for (int k = 0; k < 24; k++) {
        raw[k] = (uint8_t)(k * 11);
    }
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (deflateInit2(&zs, 6, Z_DEFLATED, 31, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        return 0;
    }
    zs.next_in = raw;
    zs.avail_in = sizeof raw;
    zs.next_out = z;
    zs.avail_out = sizeof z;
    const int ok = deflate(&zs, Z_FINISH) == Z_STREAM_END;
    const size_t zn = zs.total_out;
    deflateEnd(&zs);
    if (!ok || sizeof hdr - 1u + zn > cap) {
        return 0;
    }
    memcpy(buf, hdr, sizeof hdr - 1u);
    memcpy(buf + sizeof hdr - 1u, z, zn);
    return sizeof hdr - 1u + zn;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char *const text[] = {
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 2\nspacings: 0.5 0.5 1\n"
        "encoding: raw\n\nabcdefghijklmnopqrstuvwx",
        "NRRD0005\ntype: float\ndimension: 2\nsizes: 3 2\nencoding: ascii\n\n"
        "1 2.5 -3\n4e2 5 nan\n",
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nbyte skip: -1\nline skip: 1\n"
        "data file: data.raw\nencoding: raw\nendian: little\n\n",
    };
    if (i < sizeof text / sizeof text[0]) {
        return sc_fuzz_import_copy(text[i], strlen(text[i]), buf, cap);
    }
    if (i == sizeof text / sizeof text[0]) {
        return gzip_seed(buf, cap);
    }
    return 0;
}
