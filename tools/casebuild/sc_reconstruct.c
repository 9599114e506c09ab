/* sc_reconstruct.c: PLUS sequence reader and freehand reconstruction, see sc_reconstruct.h. */
#include "sc_reconstruct.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "sc_err.h"

static int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
{
    if (err != NULL && errlen > 0u) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return rc;
}

void sc_plusseq_free(sc_plus_seq *seq)
{
    if (seq != NULL) {
        sc_image_free(&seq->frames);
        free(seq->transform);
        free(seq->valid);
        seq->transform = NULL;
        seq->valid = NULL;
    }
}

/* 16 finite numbers of a rigid 4x4 (rotation orthonormal within 1e-3, last row 0 0 0 1,
 * translation within SC_IMPORT_MAX_ORIGIN_MM); 0 ok */
static int parse_rigid(const char *val, double m[16])
{
    const char *s = val;
    for (int i = 0; i < 16; i++) {
        char *end;
        errno = 0;
        m[i] = strtod(s, &end);
        if (end == s || errno || !isfinite(m[i])) {
            return -1;
        }
        s = end;
    }
    while (isspace((unsigned char)*s)) {
        s++;
    }
    if (*s) {
        return -1;
    }
    if (fabs(m[12]) > 1e-6 || fabs(m[13]) > 1e-6 || fabs(m[14]) > 1e-6 ||
        fabs(m[15] - 1.0) > 1e-6) {
        return -1;
    }
    for (int a = 0; a < 3; a++) {
        if (fabs(m[a * 4 + 3]) > SC_IMPORT_MAX_ORIGIN_MM) {
            return -1;
        }
        for (int b = 0; b < 3; b++) {
            const double dot = m[a] * m[b] + m[4 + a] * m[4 + b] + m[8 + a] * m[8 + b];
            if (!(fabs(dot - (a == b ? 1.0 : 0.0)) <= 1e-3)) {
                return -1;
            }
        }
    }
    return 0;
}

int sc_plusseq_read(const char *path, const sc_read_limits *lim_in, const char *transform,
                    sc_plus_seq *seq, char *err, size_t errlen)
{
    if (path == NULL || seq == NULL) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "no sequence");
    }
    memset(seq, 0, sizeof *seq);
    const char *tname = transform ? transform : "ProbeToTracker";
    if (strlen(tname) + 1u > sizeof seq->name || strlen(tname) == 0u) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "--transform '%s': a name up to %zu chars",
                    tname, sizeof seq->name - 1u);
    }
    snprintf(seq->name, sizeof seq->name, "%s", tname);
    sc_read_limits lim = lim_in ? *lim_in : sc_read_default_limits();
    lim.allow_sequence = 1;
    int rc = sc_image_read_ex(path, &lim, &seq->frames, err, errlen);
    if (rc != SC_OK) {
        return rc;
    }
    if (seq->frames.type != SC_ELEM_U8 && seq->frames.type != SC_ELEM_I8 &&
        seq->frames.type != SC_ELEM_U16) {
        sc_plusseq_free(seq);
        return fail(err, errlen, SC_ERR_NOT_SUPPORTED, "%s: ElementType: 8/16-bit frames", path);
    }
    const uint32_t nf = seq->frames.dim[2];
    seq->transform = calloc((size_t)nf * 16u, sizeof(double));
    seq->valid = calloc(nf, 1);
    uint8_t *have = calloc(nf, 1);
    FILE *f = fopen(path, "rb");
    if (seq->transform == NULL || seq->valid == NULL || have == NULL || f == NULL) {
        free(have);
        if (f) {
            fclose(f);
        }
        sc_plusseq_free(seq);
        return fail(err, errlen, SC_ERR_NO_SPACE, "%s: out of memory", path);
    }
    memset(seq->valid, 1, nf);
    /* the header again, for the per-frame fields (the pixel reader ignored them) */
    static char line[65536];
    char key_t[96], key_s[112];
    snprintf(key_t, sizeof key_t, "_%sTransform", tname);
    snprintf(key_s, sizeof key_s, "_%sTransformStatus", tname);
    rc = SC_OK;
    while (rc == SC_OK && fgets(line, sizeof line, f) != NULL) {
        char *eq = strchr(line, '=');
        if (eq == NULL) {
            continue;
        }
        *eq = 0;
        char *key = line, *val = eq + 1;
        while (isspace((unsigned char)*key)) {
            key++;
        }
        char *ke = key + strlen(key);
        while (ke > key && isspace((unsigned char)ke[-1])) {
            *--ke = 0;
        }
        while (isspace((unsigned char)*val)) {
            val++;
        }
        char *ve = val + strlen(val);
        while (ve > val && isspace((unsigned char)ve[-1])) {
            *--ve = 0;
        }
        if (strcasecmp(key, "ElementDataFile") == 0) {
            break;
        }
        if (strcasecmp(key, "UltrasoundImageOrientation") == 0) {
            if (strlen(val) != 2u || strchr("MU", val[0]) == NULL || strchr("FN", val[1]) == NULL) {
                rc = fail(err, errlen, SC_ERR_NOT_SUPPORTED,
                          "%s: UltrasoundImageOrientation '%s' (MF, UF, MN or UN)", path, val);
            }
            seq->flip_u = val[0] == 'U';
            seq->flip_v = val[1] == 'N';
            continue;
        }
        if (strncmp(key, "Seq_Frame", 9) != 0) {
            continue;
        }
        char *end;
        errno = 0;
        const unsigned long k = strtoul(key + 9, &end, 10);
        if (end == key + 9 || errno || *end != '_') {
            continue;
        }
        const int is_t = strcmp(end, key_t) == 0, is_s = strcmp(end, key_s) == 0;
        if (!is_t && !is_s) {
            continue;
        }
        if (k >= nf) {
            rc = fail(err, errlen, SC_ERR_PARSE, "%s: %s: frame %lu beyond the %u frames", path,
                      key, k, nf);
        } else if (is_t) {
            if (parse_rigid(val, seq->transform + k * 16u) != 0) {
                rc = fail(err, errlen, SC_ERR_PARSE,
                          "%s: %s: not 16 finite numbers of a rigid 4x4 matrix (row-major, last "
                          "row 0 0 0 1, translation within %g mm)",
                          path, key, SC_IMPORT_MAX_ORIGIN_MM);
            }
            have[k] = 1;
        } else {
            seq->valid[k] = strcasecmp(val, "OK") == 0;
        }
    }
    fclose(f);
    uint32_t missing = nf, nvalid = 0;
    for (uint32_t k = 0; k < nf; k++) {
        if (!have[k] && missing == nf) {
            missing = k;
        }
        if (!have[k]) {
            seq->valid[k] = 0;
        }
        nvalid += seq->valid[k];
    }
    free(have);
    if (rc == SC_OK && missing < nf) {
        rc = fail(err, errlen, SC_ERR_PARSE,
                  "%s: frame %u has no Seq_Frame%04u_%sTransform (--transform names another)", path,
                  missing, missing, tname);
    }
    if (rc == SC_OK && nvalid < 2u) {
        rc = fail(err, errlen, SC_ERR_PARSE, "%s: %u frames with a valid %s transform (2 needed)",
                  path, nvalid, tname);
    }
    if (rc != SC_OK) {
        sc_plusseq_free(seq);
        return rc;
    }
    seq->valid_count = nvalid;
    return SC_OK;
}

sc_recon_opts sc_recon_default_opts(void)
{
    sc_recon_opts o;
    memset(&o, 0, sizeof o);
    o.spacing_mm = 0.5;
    o.trilinear = 1;
    o.fill_passes = 3;
    o.image_to_probe[0] = o.image_to_probe[4] = o.image_to_probe[8] = 1.0;
    o.max_voxels = SC_IMPORT_DEFAULT_MAX_VOXELS;
    return o;
}

/* frame k's pixel -> tracker map: p = base + u * eu + v * ev */
static void frame_map(const sc_plus_seq *seq, const sc_recon_opts *o, uint32_t k, double base[3],
                      double eu[3], double ev[3])
{
    const double *t = seq->transform + (size_t)k * 16u, *a = o->image_to_probe;
    const double sx = seq->frames.spacing[0], sy = seq->frames.spacing[1];
    for (int r = 0; r < 3; r++) {
        /* probe = A * img + a_t; tracker = R * probe + t */
        double cu = 0.0, cv = 0.0, c0 = 0.0;
        for (int c = 0; c < 3; c++) {
            cu += t[r * 4 + c] * a[c * 3 + 0];
            cv += t[r * 4 + c] * a[c * 3 + 1];
            c0 += t[r * 4 + c] * a[9 + c];
        }
        eu[r] = cu * sx;
        ev[r] = cv * sy;
        base[r] = c0 + t[r * 4 + 3];
    }
    /* a stored pixel (u, v) of a U? or ?N frame is the MF pixel (W-1-u, v) or (u, H-1-v) */
    const double wm = (double)(seq->frames.dim[0] - 1u), hm = (double)(seq->frames.dim[1] - 1u);
    for (int r = 0; r < 3; r++) {
        if (seq->flip_u) {
            base[r] += wm * eu[r];
            eu[r] = -eu[r];
        }
        if (seq->flip_v) {
            base[r] += hm * ev[r];
            ev[r] = -ev[r];
        }
    }
}

int sc_reconstruct(const sc_plus_seq *seq, const sc_recon_opts *o, sc_image *vol,
                   sc_recon_stats *st, char *err, size_t errlen)
{
    if (seq == NULL || o == NULL || vol == NULL || st == NULL) {
        return fail(err, errlen, SC_ERR_INVALID_ARG, "no sequence");
    }
    memset(st, 0, sizeof *st);
    if (!(o->spacing_mm >= 0.05 && o->spacing_mm <= 10.0) || o->fill_passes > 64u) {
        return fail(err, errlen, SC_ERR_INVALID_ARG,
                    "reconstruction spacing %g mm (0.05 .. 10) or fill passes %u (0 .. 64)",
                    o->spacing_mm, o->fill_passes);
    }
    for (int i = 0; i < 12; i++) {
        if (!isfinite(o->image_to_probe[i]) || fabs(o->image_to_probe[i]) > 1e5) {
            return fail(err, errlen, SC_ERR_INVALID_ARG, "--image-to-probe: finite, |x| <= 1e5");
        }
    }
    const sc_image *fr = &seq->frames;
    const uint32_t W = fr->dim[0], H = fr->dim[1], N = fr->dim[2];
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double beam[3] = {0, 0, 0};
    for (uint32_t k = 0; k < N; k++) {
        if (!seq->valid[k]) {
            continue;
        }
        double b[3], eu[3], ev[3];
        frame_map(seq, o, k, b, eu, ev);
        const double nv = sqrt(ev[0] * ev[0] + ev[1] * ev[1] + ev[2] * ev[2]);
        for (int c = 0; c < 4; c++) {
            const double u = (c & 1) ? (double)(W - 1u) : 0.0, v = (c & 2) ? (double)(H - 1u) : 0.0;
            for (int r = 0; r < 3; r++) {
                const double p = b[r] + u * eu[r] + v * ev[r];
                lo[r] = p < lo[r] ? p : lo[r];
                hi[r] = p > hi[r] ? p : hi[r];
            }
        }
        for (int r = 0; r < 3 && nv > 0.0; r++) {
            beam[r] += (seq->flip_v ? -ev[r] : ev[r]) / nv; /* the MF depth direction */
        }
    }
    const double sp = o->spacing_mm;
    uint32_t dim[3];
    for (int r = 0; r < 3; r++) {
        const double nd = floor((hi[r] - lo[r]) / sp) + 2.0;
        if (!(nd >= 1.0 && nd <= (double)SC_MAX_VOLUME_DIM)) {
            return fail(err, errlen, SC_ERR_CASE_DIMS,
                        "reconstruction grid axis %d: %.4g mm at %.4g mm is above %u voxels", r,
                        hi[r] - lo[r], sp, SC_MAX_VOLUME_DIM);
        }
        dim[r] = (uint32_t)nd;
    }
    const uint64_t n = (uint64_t)dim[0] * dim[1] * dim[2];
    if (n > o->max_voxels || n > SC_MAX_VOLUME_VOXELS) {
        return fail(err, errlen, SC_ERR_CASE_DIMS,
                    "reconstruction grid %u x %u x %u above the ceiling of %llu voxels", dim[0],
                    dim[1], dim[2], (unsigned long long)o->max_voxels);
    }
    double *acc = calloc((size_t)n, sizeof(double));
    float *w = calloc((size_t)n, sizeof(float));
    uint8_t *mask = calloc((size_t)n, 1);
    if (acc == NULL || w == NULL || mask == NULL) {
        free(acc);
        free(w);
        free(mask);
        return fail(err, errlen, SC_ERR_NO_SPACE, "out of memory for %llu voxels",
                    (unsigned long long)n);
    }
    const size_t sy = dim[0], sz = (size_t)dim[0] * dim[1];
    for (uint32_t k = 0; k < N; k++) {
        if (!seq->valid[k]) {
            continue;
        }
        double b[3], eu[3], ev[3];
        frame_map(seq, o, k, b, eu, ev);
        const double *px = fr->data + (size_t)k * W * H;
        for (uint32_t v = 0; v < H; v++) {
            for (uint32_t u = 0; u < W; u++) {
                const double val = px[(size_t)v * W + u];
                double g[3];
                for (int r = 0; r < 3; r++) {
                    g[r] = (b[r] + (double)u * eu[r] + (double)v * ev[r] - lo[r]) / sp;
                }
                st->pixels++;
                if (!o->trilinear) {
                    const long i = lround(g[0]), j = lround(g[1]), l = lround(g[2]);
                    if (i < 0 || j < 0 || l < 0 || i >= (long)dim[0] || j >= (long)dim[1] ||
                        l >= (long)dim[2]) {
                        continue;
                    }
                    const size_t idx = (size_t)i + sy * (size_t)j + sz * (size_t)l;
                    acc[idx] += val;
                    w[idx] += 1.0f;
                    continue;
                }
                const long i0 = (long)floor(g[0]), j0 = (long)floor(g[1]), l0 = (long)floor(g[2]);
                const double f[3] = {g[0] - (double)i0, g[1] - (double)j0, g[2] - (double)l0};
                for (int c = 0; c < 8; c++) {
                    const long i = i0 + (c & 1), j = j0 + ((c >> 1) & 1), l = l0 + ((c >> 2) & 1);
                    if (i < 0 || j < 0 || l < 0 || i >= (long)dim[0] || j >= (long)dim[1] ||
                        l >= (long)dim[2]) {
                        continue;
                    }
                    const double wt = ((c & 1) ? f[0] : 1.0 - f[0]) *
                                      (((c >> 1) & 1) ? f[1] : 1.0 - f[1]) *
                                      (((c >> 2) & 1) ? f[2] : 1.0 - f[2]);
                    const size_t idx = (size_t)i + sy * (size_t)j + sz * (size_t)l;
                    acc[idx] += wt * val;
                    w[idx] += (float)wt;
                }
            }
        }
    }
    /* normalise; 1e-3 of a pixel's weight is too little to trust (a far corner of a splat) */
    for (uint64_t i = 0; i < n; i++) {
        if (w[i] > 1e-3f) {
            acc[i] /= (double)w[i];
            mask[i] = 1;
            st->filled++;
        } else {
            acc[i] = 0.0;
        }
    }
    /* hole filling: an empty voxel takes the mean of its filled 3x3x3 neighbours, pass by
     * pass, reading only what earlier passes filled (order-independent) */
    for (uint32_t pass = 0; pass < o->fill_passes; pass++) {
        uint64_t added = 0;
        for (uint32_t l = 0; l < dim[2]; l++) {
            for (uint32_t j = 0; j < dim[1]; j++) {
                for (uint32_t i = 0; i < dim[0]; i++) {
                    const size_t idx = i + sy * j + sz * l;
                    if (mask[idx] != 0u) {
                        continue;
                    }
                    double s = 0.0;
                    uint32_t cnt = 0;
                    for (int dl = -1; dl <= 1; dl++) {
                        for (int dj = -1; dj <= 1; dj++) {
                            for (int di = -1; di <= 1; di++) {
                                const long ii = (long)i + di, jj = (long)j + dj, ll = (long)l + dl;
                                if (ii < 0 || jj < 0 || ll < 0 || ii >= (long)dim[0] ||
                                    jj >= (long)dim[1] || ll >= (long)dim[2]) {
                                    continue;
                                }
                                const size_t q = (size_t)ii + sy * (size_t)jj + sz * (size_t)ll;
                                if (mask[q] != 0u && mask[q] <= pass + 1u) {
                                    s += acc[q];
                                    cnt++;
                                }
                            }
                        }
                    }
                    /* a hole, not the outside: at least 2 filled neighbours */
                    if (cnt >= 2u) {
                        acc[idx] = s / (double)cnt;
                        mask[idx] = (uint8_t)(pass + 2u); /* readable from the next pass */
                        added++;
                    }
                }
            }
        }
        st->hole_filled += added;
        if (added == 0u) {
            break;
        }
    }
    st->voxels = n;
    st->empty = n - st->filled - st->hole_filled;
    const double nb = sqrt(beam[0] * beam[0] + beam[1] * beam[1] + beam[2] * beam[2]);
    for (int r = 0; r < 3; r++) {
        st->beam_dir[r] = nb > 0.0 ? beam[r] / nb : (r == 2 ? 1.0 : 0.0);
    }
    free(w);
    free(mask);
    memset(vol, 0, sizeof *vol);
    for (int r = 0; r < 3; r++) {
        vol->dim[r] = dim[r];
        vol->spacing[r] = sp;
        vol->origin[r] = lo[r];
        vol->dir[r * 3 + r] = 1.0;
        vol->lps[r * 3 + r] = 1.0;
    }
    vol->type = SC_ELEM_F64;
    vol->data = acc;
    return SC_OK;
}

int sc_image_write_mha(const sc_image *img, const char *path)
{
    FILE *f = fopen(path, "wb");
    if (f == NULL) {
        return SC_ERR_IO;
    }
    const double *d = img->dir;
    fprintf(f,
            "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
            "CompressedData = False\nTransformMatrix = %.17g %.17g %.17g %.17g %.17g %.17g %.17g "
            "%.17g %.17g\nOffset = %.17g %.17g %.17g\nElementSpacing = %.17g %.17g %.17g\n"
            "DimSize = %u %u %u\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n",
            d[0], d[3], d[6], d[1], d[4], d[7], d[2], d[5], d[8], img->origin[0], img->origin[1],
            img->origin[2], img->spacing[0], img->spacing[1], img->spacing[2], img->dim[0],
            img->dim[1], img->dim[2]);
    const size_t n = (size_t)img->dim[0] * img->dim[1] * img->dim[2];
    int ok = 1;
    for (size_t i = 0; i < n && ok; i++) {
        const float v = (float)img->data[i];
        uint8_t b[4];
        uint32_t u;
        memcpy(&u, &v, 4);
        for (int k = 0; k < 4; k++) {
            b[k] = (uint8_t)(u >> (8 * k));
        }
        ok = fwrite(b, 1, 4, f) == 4u;
    }
    if (fclose(f) != 0 || !ok) {
        return SC_ERR_IO;
    }
    return SC_OK;
}
