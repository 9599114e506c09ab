/* fuzz_import_plusseq.c: the PLUS sequence reader (sc_plusseq_read: the MetaImage frames plus
 * per-frame Seq_FrameNNNN_ProbeToTrackerTransform / Status fields) and the reconstruction on
 * what it accepts take any bytes: no crash, no leak, no allocation beyond the ceilings; an
 * accepted sequence has at least 2 valid frames with rigid transforms, and its
 * reconstruction is finite. */
#include "sc_fuzz_import.h" /* first: it sets _GNU_SOURCE */

#include "sc_reconstruct.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[256], raw[256];
    sc_fuzz_import_put("in.igs.mha", data, size, path, sizeof path);
    sc_fuzz_import_put("data.raw", data, size, raw, sizeof raw);
    sc_read_limits lim = sc_read_default_limits();
    lim.max_voxels = SC_FUZZ_IMPORT_MAX_VOXELS;
    sc_plus_seq seq;
    char err[512];
    err[0] = 0;
    int rc = sc_plusseq_read(path, &lim, NULL, &seq, err, sizeof err);
    if (rc != SC_OK) {
        SC_FUZZ_CHECK(rc < 0 && err[0] != 0);
        return 0;
    }
    SC_FUZZ_CHECK(seq.valid_count >= 2u && seq.valid_count <= seq.frames.dim[2]);
    sc_recon_opts o = sc_recon_default_opts();
    o.max_voxels = SC_FUZZ_IMPORT_MAX_VOXELS;
    o.spacing_mm = 1.0;
    sc_image v;
    sc_recon_stats st;
    rc = sc_reconstruct(&seq, &o, &v, &st, err, sizeof err);
    if (rc == SC_OK) {
        const size_t n = (size_t)v.dim[0] * v.dim[1] * v.dim[2];
        SC_FUZZ_CHECK(n <= SC_FUZZ_IMPORT_MAX_VOXELS && st.voxels == n);
        for (size_t i = 0; i < n; i++) {
            SC_FUZZ_CHECK(isfinite(v.data[i]));
        }
        sc_image_free(&v);
    }
    sc_plusseq_free(&seq);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 1u) {
        return 0;
    }
    /* 4 x 3 pixel frames, 3 frames along y, the middle one INVALID (i = 1: detached data) */
    char hdr[2048];
    int n = snprintf(hdr, sizeof hdr,
                     "ObjectType = Image\nNDims = 3\nDimSize = 4 3 3\nElementSpacing = 0.5 0.5 1\n"
                     "ElementType = MET_UCHAR\nUltrasoundImageOrientation = MF\n");
    for (int k = 0; k < 3; k++) {
        n += snprintf(hdr + n, sizeof hdr - (size_t)n,
                      "Seq_Frame%04d_ProbeToTrackerTransform = 1 0 0 -1 0 0 1 %d 0 -1 0 2 0 0 0 "
                      "1\nSeq_Frame%04d_ProbeToTrackerTransformStatus = %s\n",
                      k, k, k, k == 1 ? "INVALID" : "OK");
    }
    n += snprintf(hdr + n, sizeof hdr - (size_t)n, "ElementDataFile = %s\n",
                  i == 0u ? "LOCAL" : "data.raw");
    if ((size_t)n + 36u > cap) {
        return 0;
    }
    memcpy(buf, hdr, (size_t)n);
    for (int k = 0; k < 36; k++) {
        buf[n + k] = (uint8_t)(k * 7);
    }
    return (size_t)n + 36u;
}
