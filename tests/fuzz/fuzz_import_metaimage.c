/* fuzz_import_metaimage.c: the case builder's MetaImage reader (sc_image_read_ex on .mha, and
 * on .mhd with a detached data.raw) takes any bytes: no crash, no leak, no read past the data,
 * no allocation beyond the voxel ceiling; a successful read has finite voxels and spacing in
 * range, a refusal a message. */
#include "sc_fuzz_import.h" /* first: it sets _GNU_SOURCE */

#include <zlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* the first byte picks inline (.mha) or detached (.mhd) */
    if (size == 0u) {
        return 0;
    }
    sc_fuzz_import_run((data[0] & 1u) ? "in.mhd" : "in.mha", data, size);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    static const char inline_u8[] = "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\n"
                                    "ElementSpacing = 0.5 0.5 1\nOffset = -1 2 3\n"
                                    "TransformMatrix = 0 1 0 -1 0 0 0 0 1\n"
                                    "AnatomicalOrientation = RAI\nElementType = MET_UCHAR\n"
                                    "ElementDataFile = LOCAL\n"
                                    "abcdefghijklmnopqrstuvwx";
    static const char detached[] = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_SHORT\n"
                                   "BinaryDataByteOrderMSB = True\nHeaderSize = -1\n"
                                   "ElementDataFile = data.raw\n";
    if (i == 0u) {
        return sc_fuzz_import_copy(inline_u8, sizeof inline_u8 - 1u, buf, cap);
    }
    if (i == 1u) {
        return sc_fuzz_import_copy(detached, sizeof detached - 1u, buf, cap);
    }
    if (i == 2u) {
        /* zlib-compressed float data inline */
        static const char hdr[] = "NDims = 3\nDimSize = 3 2 2\nElementType = MET_FLOAT\n"
                                  "CompressedData = True\nElementDataFile = LOCAL\n";
        float v[12];
        for (int k = 0; k < 12; k++) {
            v[k] = (float)k * 1.5f;
        }
        uint8_t z[256];
        uLongf zn = sizeof z;
        if (compress(z, &zn, (const Bytef *)v, sizeof v) != Z_OK || sizeof hdr - 1u + zn > cap) {
            return 0;
        }
        memcpy(buf, hdr, sizeof hdr - 1u);
        memcpy(buf + sizeof hdr - 1u, z, zn);
        return sizeof hdr - 1u + zn;
    }
    return 0;
}
