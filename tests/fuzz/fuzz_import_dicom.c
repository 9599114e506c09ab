/* fuzz_import_dicom.c: the case builder's DICOM reader (through DCMTK, C++ behind a C API)
 * takes any bytes as a .dcm file: no crash, no escaped C++ exception, no leak, no allocation
 * beyond the voxel ceiling (frame counts are checked before anything is sized by them). The
 * seeds are small volumes written by the fixture writer at start-up. Without DCMTK the
 * reader answers "not supported" and the target checks just that. */
#include "sc_fuzz_import.h" /* first: it sets _GNU_SOURCE */

#include <sys/stat.h>
#ifdef SC_HAVE_DCMTK
#include "sc_dicom.h"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_fuzz_import_run("in.dcm", data, size);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
#ifdef SC_HAVE_DCMTK
    /* i = 0: enhanced multi-frame 8 bit; 1: the same RLE-compressed; 2: one 16-bit slice */
    if (i > 2u) {
        return 0;
    }
    static double vals[4 * 3 * 3];
    for (size_t k = 0; k < sizeof vals / sizeof vals[0]; k++) {
        vals[k] = (double)((k * 37u) % 200u);
    }
    sc_image v;
    memset(&v, 0, sizeof v);
    v.dim[0] = 4;
    v.dim[1] = 3;
    v.dim[2] = 3;
    for (int a = 0; a < 3; a++) {
        v.spacing[a] = 0.5 + 0.25 * a;
        v.origin[a] = 10.0 * a;
        v.dir[a * 3 + a] = 1.0;
    }
    v.data = vals;
    char dir[128];
    snprintf(dir, sizeof dir, "%s/seed%u", sc_fuzz_import_dir(), i);
    if (mkdir(dir, 0700) != 0) {
        return 0;
    }
    const int mf = i < 2u;
    if (sc_dicom_write_fixture(dir, &v, i == 2u ? 16 : 8, 0, 1.0, 0.0, mf, i == 1u) != SC_OK) {
        return 0;
    }
    char f[256];
    if (mf) {
        snprintf(f, sizeof f, "%s/volume.dcm", dir);
    } else {
        snprintf(f, sizeof f, "%s/IM0003.dcm", dir); /* the first slice's name */
    }
    FILE *fp = fopen(f, "rb");
    if (fp == NULL) {
        return 0;
    }
    const size_t n = fread(buf, 1, cap, fp);
    fclose(fp);
    return n;
#else
    static const char junk[] = "DICM not really";
    return i == 0u ? sc_fuzz_import_copy(junk, sizeof junk - 1u, buf, cap) : 0;
#endif
}
