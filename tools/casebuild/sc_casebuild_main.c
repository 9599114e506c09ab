/* sc-casebuild: build, inspect and verify sonocomp case files.
 *
 *   sc-casebuild phantom <neck-ijv|femoral|femoral-dvt> -o OUT.scase [--seed N] [--spacing MM]
 *                        [--mesh-nodes NX,NY,NZ] (the same mesh box at another resolution)
 *                        [--acoustics engine|baked] [--speckle engine|baked]
 *   sc-casebuild import --volume V.{mha,mhd,nrrd,nhdr,dcm}|DICOMDIR/ [--labels L.{...}] -o
 * OUT.scase
 *                [--name NAME] [--description TEXT] [--spacing MM] [--window LO:HI]
 *                [--mesh-nodes NX,NY,NZ] [--mesh-box X0,Y0,Z0,SX,SY,SZ]
 *                [--depth-axis AX] [--lateral-axis AX] [--label-map V=NAME,...]
 *                [--max-voxels N] [--allow-data-path yes]
 *                [--calibration 12 numbers] [--registration 12 numbers] (row-major R, then t)
 *                [--heart-rate BPM] [--pulse-kpa KPA] [--waveform arterial|sine]
 *                [--breathing BPM] [--venous-swing-kpa KPA] [--valsalva-kpa KPA] (DRIV section)
 *   sc-casebuild reconstruct --sequence SEQ.igs.mha -o OUT.scase [--transform NAME]
 *                [--image-to-probe 12 numbers] [--recon-spacing MM] [--splat nearest|trilinear]
 *                [--fill-passes N] [--volume-out V.mha] [import options]
 *   sc-casebuild info CASE.scase
 *   sc-casebuild verify CASE.scase...
 *   sc-casebuild slice CASE.scase --axis x|y|z --index N -o OUT.pgm [--labels]
 *   sc-casebuild isosurface CASE.scase --label L -o OUT.{ply,obj} [--sigma MM] [--iterations N]
 *   sc-casebuild bench [--repeat N] CASE.scase...   (validating loader timing, a table)
 *
 * Exit status: 0 success, 1 a case refused / an input unreadable, 2 usage.
 */
#include <errno.h>
#include <math.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_case.h"
#include "sc_casesurf.h"
#include "sc_caseimport.h"
#include "sc_err.h"
#include "sc_isosurface.h"
#include "sc_labels.h"
#include "sc_phantom.h"
#include "sc_reconstruct.h"
#include "sc_storage_linux.h"

static const char *const label_names[] = {
#define LBL_NAME_(name, value, text) [value] = text,
    SC_LABEL_LIST(LBL_NAME_)
#undef LBL_NAME_
};

static int usage(void)
{
    fprintf(stderr,
            "usage:\n"
            "  sc-casebuild phantom <neck-ijv|femoral|femoral-dvt> -o OUT.scase [--seed N] "
            "[--spacing MM]\n"
            "               [--mesh-nodes NX,NY,NZ]  (the phantom's mesh box at this resolution)\n"
            "               [--acoustics engine|baked]  (engine: the engine computes shadows and\n"
            "               enhancement along the beam; baked, the default: in the voxels)\n"
            "               [--speckle engine|baked]  (engine: the engine forms the speckle from\n"
            "               its scatterers and the beam's PSF; baked, the default: in the voxels)\n"
            "  sc-casebuild import --volume FILE [--labels FILE] -o OUT.scase [--name NAME]\n"
            "               [--description TEXT] [--spacing MM] [--window LO:HI]\n"
            "               [--mesh-nodes NX,NY,NZ] [--mesh-box X0,Y0,Z0,SX,SY,SZ]\n"
            "               [--depth-axis AX] [--lateral-axis AX]  (AX: +i -i +j -j +k -k of the\n"
            "                source grid, or L R A P S I when the file states a patient frame)\n"
            "               [--label-map V=NAME,...[,*=NAME]]  (source label -> vein, artery, ...)\n"
            "               [--max-voxels N] (ceiling per image and case, default 67108864)\n"
            "               [--allow-data-path yes] (data files outside the header's folder)\n"
            "               [--calibration R00,..,R22,TX,TY,TZ]  (image -> probe, mm)\n"
            "               [--registration R00,..,R22,TX,TY,TZ] (tracker -> patient, mm)\n"
            "               [--heart-rate BPM] (0 none, 20..250) [--pulse-kpa KPA] (0..20)\n"
            "               [--waveform arterial|sine] [--breathing BPM] (0 none, 4..60)\n"
            "               [--venous-swing-kpa KPA] (0..5) [--valsalva-kpa KPA] (0..10)\n"
            "               (the patient's vessel drive, a DRIV section: the options given\n"
            "                change the engine's default drive; none given, no DRIV)\n"
            "               (FILE: .mha, .mhd, .nrrd, .nhdr, raw or compressed; .dcm or a DICOM\n"
            "                series folder when built with DCMTK)\n"
            "  sc-casebuild reconstruct --sequence SEQ.igs.mha -o OUT.scase [--transform NAME]\n"
            "               [--image-to-probe A00,..,A22,TX,TY,TZ] [--recon-spacing MM]\n"
            "               [--splat nearest|trilinear] [--fill-passes N] [--volume-out V.mha]\n"
            "               [import options but --volume]  (PLUS tracked 2D sequence)\n"
            "  sc-casebuild info CASE\n"
            "  sc-casebuild verify CASE...\n"
            "  sc-casebuild slice CASE --axis x|y|z --index N -o OUT.pgm [--labels]\n"
            "  sc-casebuild isosurface CASE --label L -o OUT.ply|OUT.obj [--sigma MM] "
            "[--iterations N]\n"
            "  sc-casebuild bench [--repeat N] CASE...   (loader timing table)\n");
    return 2;
}

/* drive: the case's DRIV section (the patient's vessel drive), NULL for none */
static int write_case_file(const sc_case_def *def, const sc_lumen_drive *drive, const char *path)
{
    size_t need = sc_case_encoded_size(def);
    if (need == 0u) {
        fprintf(stderr, "sc-casebuild: case too large to encode\n");
        return 1;
    }
    uint8_t *buf = malloc(need);
    if (buf == NULL) {
        fprintf(stderr, "sc-casebuild: out of memory (%zu bytes)\n", need);
        return 1;
    }
    size_t n = 0;
    int rc = sc_case_write(def, buf, need, &n);
    if (rc == SC_OK) {
        /* the writer does not validate semantics: the loader must accept what we ship */
        sc_case c;
        rc = sc_case_load(buf, n, &c);
    }
    if (rc == SC_OK) {
        /* the console's surfaces (SURF), embedded in the rest mesh, then the whole reloaded */
        uint8_t *surf = NULL;
        size_t surf_n = 0;
        rc = sc_casesurf_build(def, &surf, &surf_n);
        uint8_t *grown = rc == SC_OK ? realloc(buf, need + surf_n + 4u * SC_CASE_ALIGN) : NULL;
        if (rc == SC_OK && grown == NULL) {
            rc = SC_ERR_NO_SPACE;
        }
        if (rc == SC_OK) {
            buf = grown;
            rc = sc_case_append_section(buf, need + surf_n + 4u * SC_CASE_ALIGN, &n,
                                        SC_CASE_TAG_SURF_U32, surf, surf_n);
        }
        free(surf);
        if (rc == SC_OK && drive != NULL) {
            /* the patient's drive (DRIV), into the spare room of the buffer above */
            uint8_t dp[SC_CASE_DRIVE_SIZE];
            rc = sc_case_drive_encode(drive, dp);
            if (rc == SC_OK) {
                rc = sc_case_append_section(buf, need + surf_n + 4u * SC_CASE_ALIGN, &n,
                                            SC_CASE_TAG_DRIV_U32, dp, sizeof dp);
            }
        }
        if (rc == SC_OK) {
            sc_case c;
            rc = sc_case_load(buf, n, &c);
        }
    }
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: refusing to write an invalid case: %s (%s)\n",
                sc_err_name(rc), sc_err_str(rc));
        free(buf);
        return 1;
    }
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "wb");
    if (f == NULL || fwrite(buf, 1, n, f) != n || fclose(f) != 0) {
        fprintf(stderr, "sc-casebuild: cannot write %s: %s\n", tmp, strerror(errno));
        free(buf);
        return 1;
    }
    free(buf);
    if (rename(tmp, path) != 0) {
        fprintf(stderr, "sc-casebuild: cannot rename %s to %s: %s\n", tmp, path, strerror(errno));
        return 1;
    }
    return 0;
}

/* Map a case through Linux storage and load it; prints the refusal. */
static int open_case(sc_storage_linux *st, sc_storage_dev *dev, const char *path,
                     const uint8_t **data, size_t *size, sc_case *c)
{
    sc_storage_linux_init(st, NULL);
    *dev = sc_storage_linux_dev(st);
    int rc = sc_storage_open(dev, path, data, size);
    if (rc != SC_OK) {
        fprintf(stderr, "%s: cannot open: %s (%s)\n", path, sc_err_name(rc),
                st->last_errno ? strerror(st->last_errno) : sc_err_str(rc));
        return rc;
    }
    rc = sc_case_load(*data, *size, c);
    if (rc != SC_OK) {
        fprintf(stderr, "%s: REFUSED: %s (%s)\n", path, sc_err_name(rc), sc_err_str(rc));
        sc_storage_close(dev, *data, *size);
    }
    return rc;
}

static void print_xform(const char *what, const sc_xform *x)
{
    printf("%-22s R [%.4f %.4f %.4f; %.4f %.4f %.4f; %.4f %.4f %.4f] t [%.3f %.3f %.3f] mm\n", what,
           (double)x->r[0], (double)x->r[1], (double)x->r[2], (double)x->r[3], (double)x->r[4],
           (double)x->r[5], (double)x->r[6], (double)x->r[7], (double)x->r[8], (double)x->t_mm[0],
           (double)x->t_mm[1], (double)x->t_mm[2]);
}

static int cmd_info(int argc, char **argv)
{
    if (argc != 1) {
        return usage();
    }
    sc_storage_linux st;
    sc_storage_dev dev;
    const uint8_t *data;
    size_t size;
    sc_case c;
    if (open_case(&st, &dev, argv[0], &data, &size, &c) != SC_OK) {
        return 1;
    }
    const sc_volume *v = &c.volume;
    printf("file                   %s (%zu bytes, format v%u, id %08" PRIx32 ")\n", argv[0], size,
           SC_CASE_VERSION, c.case_id);
    printf("name                   %s\n", c.name);
    printf("description            ");
    for (const char *p = c.description; *p; p++) {
        putchar(*p);
        if (*p == '\n') {
            printf("                       ");
        }
    }
    putchar('\n');
    printf("grid                   %u x %u x %u voxels (%" PRIu64 ")\n", v->dim[0], v->dim[1],
           v->dim[2], c.voxel_count);
    printf("spacing                %.4g x %.4g x %.4g mm\n", (double)v->spacing_mm[0],
           (double)v->spacing_mm[1], (double)v->spacing_mm[2]);
    printf("extent                 x [%.2f, %.2f] y [%.2f, %.2f] z [%.2f, %.2f] mm\n",
           (double)v->origin_mm[0],
           (double)(v->origin_mm[0] + v->spacing_mm[0] * (float)(v->dim[0] - 1u)),
           (double)v->origin_mm[1],
           (double)(v->origin_mm[1] + v->spacing_mm[1] * (float)(v->dim[1] - 1u)),
           (double)v->origin_mm[2],
           (double)(v->origin_mm[2] + v->spacing_mm[2] * (float)(v->dim[2] - 1u)));
    printf("orientation            [%.4f %.4f %.4f; %.4f %.4f %.4f; %.4f %.4f %.4f]\n",
           (double)c.orientation[0], (double)c.orientation[1], (double)c.orientation[2],
           (double)c.orientation[3], (double)c.orientation[4], (double)c.orientation[5],
           (double)c.orientation[6], (double)c.orientation[7], (double)c.orientation[8]);
    printf("mesh                   %u x %u x %u nodes, box origin [%.2f %.2f %.2f] size [%.2f "
           "%.2f %.2f] mm\n",
           c.mesh.nx, c.mesh.ny, c.mesh.nz, (double)c.mesh.origin_mm[0],
           (double)c.mesh.origin_mm[1], (double)c.mesh.origin_mm[2], (double)c.mesh.size_mm[0],
           (double)c.mesh.size_mm[1], (double)c.mesh.size_mm[2]);
    print_xform("image -> probe", &c.image_to_probe);
    print_xform("tracker -> patient", &c.tracker_to_patient);
    print_xform("tracker -> volume", &c.tracker_to_volume);
    if (c.drive.present) {
        const sc_lumen_drive *d = &c.drive.d;
        printf("vessel drive           heart %.0f / min, pulse %.1f kPa, %s waveform, breathing "
               "%.0f / min, venous swing %.2f kPa, Valsalva %.1f kPa\n",
               (double)d->heart_rate_bpm, (double)d->pulse_pa * 1e-3,
               d->wave == (uint8_t)SC_LUMEN_WAVE_SINE ? "sine" : "arterial",
               (double)d->resp_rate_bpm, (double)d->resp_pa * 1e-3, (double)d->valsalva_pa * 1e-3);
    } else {
        printf("vessel drive           none (the engine's)\n");
    }
    uint64_t hist[SC_MAX_LABELS];
    sc_case_label_histogram(&c, hist);
    uint64_t ihist[256] = {0};
    for (uint64_t i = 0; i < c.voxel_count; i++) {
        ihist[v->voxels[i]]++;
    }
    printf("\nlabel  name       voxels      share   E (Pa)     Poisson  density (kg/m3)\n");
    for (uint32_t l = 0; l < c.material_count; l++) {
        const char *nm =
            l < sizeof label_names / sizeof label_names[0] && label_names[l] ? label_names[l] : "-";
        printf("%5u  %-9s %10" PRIu64 "  %6.2f%%  %-9.4g  %-7.3f  %.0f\n", l, nm, hist[l],
               100.0 * (double)hist[l] / (double)c.voxel_count, (double)c.materials[l].e_pa,
               (double)c.materials[l].poisson, (double)c.materials[l].density_kg_m3);
    }
    /* labels present and absent (an absent vein or artery means no compression measure) */
    printf("\nlabels found          ");
    for (uint32_t l = 0; l < c.material_count && l < SC_LABEL_COUNT; l++) {
        if (hist[l] != 0u) {
            printf(" %s", label_names[l]);
        }
    }
    printf("\nlabels absent         ");
    int absent = 0;
    for (uint32_t l = 0; l < SC_LABEL_COUNT; l++) {
        if (l >= c.material_count || hist[l] == 0u) {
            printf(" %s", label_names[l]);
            absent = 1;
        }
    }
    printf("%s\n", absent ? "" : " none");
    if (hist[SC_LABEL_VEIN] == 0u || hist[SC_LABEL_ARTERY] == 0u) {
        printf("note                   no %s label: the engine reports no %s area ratio for "
               "this case\n",
               hist[SC_LABEL_VEIN] == 0u ? "vein" : "artery",
               hist[SC_LABEL_VEIN] == 0u ? "vein" : "artery");
    }
    uint64_t acc = 0;
    int p5 = -1, p50 = -1, p95 = -1;
    for (int g = 0; g < 256; g++) {
        acc += ihist[g];
        if (p5 < 0 && acc * 20u >= c.voxel_count) {
            p5 = g;
        }
        if (p50 < 0 && acc * 2u >= c.voxel_count) {
            p50 = g;
        }
        if (p95 < 0 && acc * 20u >= c.voxel_count * 19u) {
            p95 = g;
        }
    }
    printf("\nintensity percentiles  p5 %d  p50 %d  p95 %d\n", p5, p50, p95);
    sc_storage_close(&dev, data, size);
    return 0;
}

static int cmd_verify(int argc, char **argv)
{
    if (argc < 1) {
        return usage();
    }
    int bad = 0;
    for (int i = 0; i < argc; i++) {
        sc_storage_linux st;
        sc_storage_dev dev;
        const uint8_t *data;
        size_t size;
        sc_case c;
        if (open_case(&st, &dev, argv[i], &data, &size, &c) != SC_OK) {
            bad = 1;
            continue;
        }
        printf("%s: OK (%s, %u x %u x %u, id %08" PRIx32 ")\n", argv[i], c.name, c.volume.dim[0],
               c.volume.dim[1], c.volume.dim[2], c.case_id);
        sc_storage_close(&dev, data, size);
    }
    return bad;
}

/* Strict command-line numbers: the whole string, finite, inside [lo, hi]; else a message
 * naming the option and exit status 2. */
static int num_f32(const char *opt, const char *s, double lo, double hi, float *out)
{
    char *end;
    errno = 0;
    const double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi) {
        fprintf(stderr, "sc-casebuild: %s '%s': a number in [%g, %g]\n", opt, s, lo, hi);
        return -1;
    }
    *out = (float)v;
    return 0;
}

static int num_u64(const char *opt, const char *s, uint64_t lo, uint64_t hi, uint64_t *out)
{
    char *end;
    errno = 0;
    const unsigned long long v = strtoull(s, &end, 0);
    if (errno || end == s || *end || s[0] == '-' || s[0] == '+' || v < lo || v > hi) {
        fprintf(stderr, "sc-casebuild: %s '%s': an integer in [%" PRIu64 ", %" PRIu64 "]\n", opt,
                s, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

static int num_u32(const char *opt, const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    uint64_t v;
    if (num_u64(opt, s, lo, hi, &v) != 0) {
        return -1;
    }
    *out = (uint32_t)v;
    return 0;
}

static int cmd_phantom(int argc, char **argv)
{
    sc_phantom_def pd = sc_phantom_default_def();
    const char *out = NULL;
    if (argc < 1) {
        return usage();
    }
    int kind = sc_phantom_kind_from_name(argv[0]);
    if (kind < 0) {
        fprintf(stderr, "sc-casebuild: unknown phantom '%s'\n", argv[0]);
        return usage();
    }
    pd.kind = (sc_phantom_kind)kind;
    uint32_t mesh_nodes[3] = {0u, 0u, 0u}; /* 0: the phantom's own mesh */
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-o") == 0 && i + 1 < argc) {
            out = argv[++i];
        } else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            if (num_u64("--seed", argv[++i], 0u, UINT64_MAX, &pd.seed) != 0) {
                return 2;
            }
        } else if (strcmp(argv[i], "--spacing") == 0 && i + 1 < argc) {
            if (num_f32("--spacing", argv[++i], 0.1, 2.0, &pd.spacing_mm) != 0) {
                return 2;
            }
        } else if (strcmp(argv[i], "--acoustics") == 0 && i + 1 < argc) {
            const char *a = argv[++i];
            if (strcmp(a, "engine") != 0 && strcmp(a, "baked") != 0) {
                fprintf(stderr, "sc-casebuild: --acoustics wants engine or baked, got '%s'\n", a);
                return 2;
            }
            pd.engine_acoustics = strcmp(a, "engine") == 0;
        } else if (strcmp(argv[i], "--speckle") == 0 && i + 1 < argc) {
            const char *a = argv[++i];
            if (strcmp(a, "engine") != 0 && strcmp(a, "baked") != 0) {
                fprintf(stderr, "sc-casebuild: --speckle wants engine or baked, got '%s'\n", a);
                return 2;
            }
            pd.engine_speckle = strcmp(a, "engine") == 0;
        } else if (strcmp(argv[i], "--mesh-nodes") == 0 && i + 1 < argc) {
            const char *val = argv[++i];
            char buf[64];
            const uint32_t maxn[3] = {SC_MAX_MESH_NX, SC_MAX_MESH_NY, SC_MAX_MESH_NZ};
            snprintf(buf, sizeof buf, "%s", val);
            char *save = NULL, *tok = strtok_r(buf, ",", &save);
            for (int k = 0; k < 3; k++) {
                if (tok == NULL || num_u32("--mesh-nodes", tok, 2u, maxn[k], &mesh_nodes[k])) {
                    fprintf(stderr,
                            "sc-casebuild: --mesh-nodes '%s': NX,NY,NZ, each 2..%u,%u,%u\n", val,
                            maxn[0], maxn[1], maxn[2]);
                    return 2;
                }
                tok = strtok_r(NULL, ",", &save);
            }
            if (tok != NULL) {
                fprintf(stderr, "sc-casebuild: --mesh-nodes '%s': three counts\n", val);
                return 2;
            }
        } else {
            return usage();
        }
    }
    if (out == NULL) {
        return usage();
    }
    sc_phantom p;
    int rc = sc_phantom_generate(&pd, &p);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: phantom: %s\n", sc_err_name(rc));
        return 1;
    }
    if (mesh_nodes[0] != 0u) { /* the same mesh box at another resolution */
        p.def.mesh.nx = mesh_nodes[0];
        p.def.mesh.ny = mesh_nodes[1];
        p.def.mesh.nz = mesh_nodes[2];
    }
    sc_lumen_drive drive;
    rc = sc_phantom_drive(pd.kind, &drive);
    if (rc == SC_OK) {
        rc = write_case_file(&p.def, &drive, out);
    }
    sc_phantom_free(&p);
    return rc;
}

static int parse_floats(const char *s, float *v, int n)
{
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        const double d = strtod(s, &end);
        if (end == s || errno || !isfinite(d) || fabs(d) > 1e6) {
            return -1;
        }
        v[i] = (float)d;
        s = end;
        if (i + 1 < n) {
            if (*s != ',') {
                return -1;
            }
            s++;
        }
    }
    return *s == '\0' ? 0 : -1;
}

/* A drive option's number: the whole string, finite, and 0 (none; when zero_none) or within
 * [lo, hi] (sc_lumen_drive_validate's ranges, in the option's unit). */
static int drive_num(const char *opt, const char *s, int zero_none, double lo, double hi,
                     const char *unit, float *out)
{
    char *end;
    errno = 0;
    const double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) ||
        !((zero_none && !(v < 0.0) && !(v > 0.0)) || (v >= lo && v <= hi))) {
        fprintf(stderr, "sc-casebuild: %s '%s': %s%g..%g %s\n", opt, s,
                zero_none ? "0 (none) or " : "", lo, hi, unit);
        return -1;
    }
    *out = (float)v;
    return 0;
}

/* The vessel drive options (the case's DRIV section): 0 taken, 1 not one, 2 bad value (a
 * message printed). The first one given starts the drive from sc_lumen_drive_default(). */
static int parse_drive_opt(const char *a, const char *val, sc_import_opts *o)
{
    sc_lumen_drive d = o->has_drive ? o->drive : sc_lumen_drive_default();
    float v = 0.0f;
    int rc = 0;
    if (strcmp(a, "--heart-rate") == 0) {
        rc = drive_num(a, val, 1, 20.0, 250.0, "beats per minute", &d.heart_rate_bpm);
    } else if (strcmp(a, "--pulse-kpa") == 0) {
        rc = drive_num(a, val, 0, 0.0, 20.0, "kPa (arterial pulse pressure)", &v);
        d.pulse_pa = v * 1e3f;
    } else if (strcmp(a, "--waveform") == 0) {
        if (strcmp(val, "arterial") != 0 && strcmp(val, "sine") != 0) {
            fprintf(stderr, "sc-casebuild: --waveform '%s': arterial or sine\n", val);
            return 2;
        }
        d.wave = (uint8_t)(val[0] == 's' ? SC_LUMEN_WAVE_SINE : SC_LUMEN_WAVE_ARTERIAL);
    } else if (strcmp(a, "--breathing") == 0) {
        rc = drive_num(a, val, 1, 4.0, 60.0, "breaths per minute", &d.resp_rate_bpm);
    } else if (strcmp(a, "--venous-swing-kpa") == 0) {
        rc = drive_num(a, val, 0, 0.0, 5.0, "kPa (venous respiratory swing)", &v);
        d.resp_pa = v * 1e3f;
    } else if (strcmp(a, "--valsalva-kpa") == 0) {
        rc = drive_num(a, val, 0, 0.0, 10.0, "kPa (venous rise in a Valsalva manoeuvre)", &v);
        d.valsalva_pa = v * 1e3f;
    } else {
        return 1;
    }
    if (rc != 0) {
        return 2;
    }
    const int vrc = sc_lumen_drive_validate(&d); /* the loader's rules, to the last bit */
    if (vrc != SC_OK) {
        fprintf(stderr, "sc-casebuild: %s '%s': the vessel drive is refused (%s)\n", a, val,
                sc_err_name(vrc));
        return 2;
    }
    o->drive = d;
    o->has_drive = 1;
    return 0;
}

/* One option of import (also taken by reconstruct): 0 taken, 1 not an import option,
 * 2 bad value (a message printed). */
static int parse_import_opt(const char *a, const char *val, sc_import_opts *o, const char **out)
{
    const int drc = parse_drive_opt(a, val, o);
    if (drc != 1) {
        return drc;
    }
    if (strcmp(a, "-o") == 0) {
        *out = val;
    } else if (strcmp(a, "--volume") == 0) {
        o->volume_path = val;
    } else if (strcmp(a, "--labels") == 0) {
        o->labels_path = val;
    } else if (strcmp(a, "--name") == 0) {
        o->name = val;
    } else if (strcmp(a, "--description") == 0) {
        o->description = val;
    } else if (strcmp(a, "--spacing") == 0) {
        if (num_f32("--spacing", val, 0.01, 50.0, &o->spacing_mm) != 0) {
            return 2;
        }
    } else if (strcmp(a, "--window") == 0) {
        const char *colon = strchr(val, ':');
        char lo_s[64];
        if (colon == NULL || (size_t)(colon - val) >= sizeof lo_s) {
            fprintf(stderr, "sc-casebuild: --window '%s': LO:HI\n", val);
            return 2;
        }
        memcpy(lo_s, val, (size_t)(colon - val));
        lo_s[colon - val] = 0;
        if (num_f32("--window LO", lo_s, -1e30, 1e30, &o->window_lo) != 0 ||
            num_f32("--window HI", colon + 1, -1e30, 1e30, &o->window_hi) != 0) {
            return 2;
        }
        if (!(o->window_hi > o->window_lo)) {
            fprintf(stderr, "sc-casebuild: --window '%s': HI must be above LO\n", val);
            return 2;
        }
        o->has_window = 1;
    } else if (strcmp(a, "--mesh-nodes") == 0) {
        char buf[64];
        const uint32_t maxn[3] = {SC_MAX_MESH_NX, SC_MAX_MESH_NY, SC_MAX_MESH_NZ};
        snprintf(buf, sizeof buf, "%s", val);
        char *save = NULL, *tok = strtok_r(buf, ",", &save);
        for (int k = 0; k < 3; k++) {
            if (tok == NULL || num_u32("--mesh-nodes", tok, 2u, maxn[k], &o->mesh_nodes[k])) {
                fprintf(stderr, "sc-casebuild: --mesh-nodes '%s': NX,NY,NZ, each 2..%u,%u,%u\n",
                        val, maxn[0], maxn[1], maxn[2]);
                return 2;
            }
            tok = strtok_r(NULL, ",", &save);
        }
        if (tok != NULL) {
            fprintf(stderr, "sc-casebuild: --mesh-nodes '%s': three counts\n", val);
            return 2;
        }
    } else if (strcmp(a, "--max-voxels") == 0) {
        if (num_u64("--max-voxels", val, 1u, SC_MAX_VOLUME_VOXELS, &o->limits.max_voxels)) {
            return 2;
        }
    } else if (strcmp(a, "--allow-data-path") == 0) {
        if (strcmp(val, "yes") != 0 && strcmp(val, "no") != 0) {
            fprintf(stderr, "sc-casebuild: --allow-data-path '%s': yes or no\n", val);
            return 2;
        }
        o->limits.allow_data_path = strcmp(val, "yes") == 0;
    } else if (strcmp(a, "--depth-axis") == 0) {
        o->depth_axis = val;
    } else if (strcmp(a, "--lateral-axis") == 0) {
        o->lateral_axis = val;
    } else if (strcmp(a, "--label-map") == 0) {
        o->label_map = val;
    } else if (strcmp(a, "--calibration") == 0 || strcmp(a, "--registration") == 0) {
        float v[12];
        if (parse_floats(val, v, 12) != 0) {
            return 2;
        }
        sc_xform *x = a[2] == 'c' ? &o->image_to_probe : &o->tracker_to_patient;
        o->has_registration |= a[2] == 'r';
        memcpy(x->r, v, sizeof x->r);
        memcpy(x->t_mm, v + 9, sizeof x->t_mm);
    } else if (strcmp(a, "--mesh-box") == 0) {
        if (parse_floats(val, o->mesh_box_mm, 6) != 0) {
            fprintf(stderr, "sc-casebuild: --mesh-box '%s': six finite numbers (mm)\n", val);
            return 2;
        }
        o->has_mesh_box = 1;
    } else {
        return 1;
    }
    return 0;
}

static void print_import(const char *out, const sc_import_result *r)
{
    static const char axis_names[] = "ijk";
    printf("%s: case frame x = %c%c, y = %c%c, z (depth) = %c%c of the source grid; mesh box %s "
           "[%.2f %.2f %.2f] + [%.2f %.2f %.2f] mm\n",
           out, r->frame_sign[0] > 0 ? '+' : '-', axis_names[r->frame_axis[0]],
           r->frame_sign[1] > 0 ? '+' : '-', axis_names[r->frame_axis[1]],
           r->frame_sign[2] > 0 ? '+' : '-', axis_names[r->frame_axis[2]],
           r->mesh_box_derived ? "(from the labels)" : "(given)", (double)r->def.mesh.origin_mm[0],
           (double)r->def.mesh.origin_mm[1], (double)r->def.mesh.origin_mm[2],
           (double)r->def.mesh.size_mm[0], (double)r->def.mesh.size_mm[1],
           (double)r->def.mesh.size_mm[2]);
}

static int cmd_import(int argc, char **argv)
{
    sc_import_opts o = sc_import_default_opts();
    const char *out = NULL;
    for (int i = 0; i + 1 < argc || i < argc; i += 2) {
        if (i + 1 >= argc) {
            return usage();
        }
        const int rc = parse_import_opt(argv[i], argv[i + 1], &o, &out);
        if (rc == 1) {
            return usage();
        }
        if (rc == 2) {
            return 2;
        }
    }
    if (out == NULL || o.volume_path == NULL) {
        return usage();
    }
    sc_import_result r;
    char err[512];
    int rc = sc_import_case(&o, &r, err, sizeof err);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: import: %s: %s\n", sc_err_name(rc), err);
        return 1;
    }
    print_import(out, &r);
    rc = write_case_file(&r.def, o.has_drive ? &o.drive : NULL, out);
    sc_import_result_free(&r);
    return rc;
}

/* reconstruct: a PLUS tracked sequence -> a volume (tracker frame) -> import as a case */
static int cmd_reconstruct(int argc, char **argv)
{
    sc_import_opts o = sc_import_default_opts();
    sc_recon_opts ro = sc_recon_default_opts();
    const char *out = NULL, *seq_path = NULL, *transform = NULL, *vol_out = NULL;
    for (int i = 0; i < argc; i += 2) {
        if (i + 1 >= argc) {
            return usage();
        }
        const char *a = argv[i], *val = argv[i + 1];
        if (strcmp(a, "--sequence") == 0) {
            seq_path = val;
        } else if (strcmp(a, "--transform") == 0) {
            transform = val;
        } else if (strcmp(a, "--volume-out") == 0) {
            vol_out = val;
        } else if (strcmp(a, "--recon-spacing") == 0) {
            float v;
            if (num_f32("--recon-spacing", val, 0.05, 10.0, &v) != 0) {
                return 2;
            }
            ro.spacing_mm = (double)v;
        } else if (strcmp(a, "--splat") == 0) {
            if (strcmp(val, "nearest") != 0 && strcmp(val, "trilinear") != 0) {
                fprintf(stderr, "sc-casebuild: --splat '%s': nearest or trilinear\n", val);
                return 2;
            }
            ro.trilinear = strcmp(val, "trilinear") == 0;
        } else if (strcmp(a, "--fill-passes") == 0) {
            if (num_u32("--fill-passes", val, 0u, 64u, &ro.fill_passes) != 0) {
                return 2;
            }
        } else if (strcmp(a, "--image-to-probe") == 0) {
            float v[12];
            if (parse_floats(val, v, 12) != 0) {
                fprintf(stderr, "sc-casebuild: --image-to-probe '%s': 12 finite numbers (3x3 "
                                "row-major, then the translation, mm)\n",
                        val);
                return 2;
            }
            for (int k = 0; k < 12; k++) {
                ro.image_to_probe[k] = (double)v[k];
            }
        } else if (strcmp(a, "--volume") == 0) {
            fprintf(stderr, "sc-casebuild: reconstruct takes --sequence, not --volume\n");
            return 2;
        } else {
            const int rc = parse_import_opt(a, val, &o, &out);
            if (rc == 1) {
                return usage();
            }
            if (rc == 2) {
                return 2;
            }
        }
    }
    if (out == NULL || seq_path == NULL) {
        return usage();
    }
    ro.max_voxels = o.limits.max_voxels;
    char err[512];
    sc_plus_seq seq;
    int rc = sc_plusseq_read(seq_path, &o.limits, transform, &seq, err, sizeof err);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: reconstruct: %s: %s\n", sc_err_name(rc), err);
        return 1;
    }
    sc_image vol;
    sc_recon_stats st;
    rc = sc_reconstruct(&seq, &ro, &vol, &st, err, sizeof err);
    const uint32_t nframes = seq.frames.dim[2], nvalid = seq.valid_count;
    sc_plusseq_free(&seq);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: reconstruct: %s: %s\n", sc_err_name(rc), err);
        return 1;
    }
    printf("%s: %u of %u frames, %" PRIu64 " pixels %s-splatted into %u x %u x %u at %.3g mm: "
           "%.1f%% from the frames, %.1f%% hole-filled, %.1f%% empty; beam (depth) direction "
           "[%.3f %.3f %.3f] in the tracker frame\n",
           seq_path, nvalid, nframes, st.pixels, ro.trilinear ? "trilinear" : "nearest",
           vol.dim[0], vol.dim[1], vol.dim[2], ro.spacing_mm,
           100.0 * (double)st.filled / (double)st.voxels,
           100.0 * (double)st.hole_filled / (double)st.voxels,
           100.0 * (double)st.empty / (double)st.voxels, st.beam_dir[0], st.beam_dir[1],
           st.beam_dir[2]);
    char tmp[4200];
    if (vol_out == NULL) {
        snprintf(tmp, sizeof tmp, "%s.volume.mha", out);
        vol_out = tmp;
    }
    rc = sc_image_write_mha(&vol, vol_out);
    sc_image_free(&vol);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: reconstruct: cannot write %s\n", vol_out);
        return 1;
    }
    /* depth: the grid axis (the tracker's) closest to the mean beam direction */
    char depth[4] = "+k";
    if (o.depth_axis == NULL) {
        int best = 0;
        for (int r = 1; r < 3; r++) {
            if (fabs(st.beam_dir[r]) > fabs(st.beam_dir[best])) {
                best = r;
            }
        }
        depth[0] = st.beam_dir[best] < 0.0 ? '-' : '+';
        depth[1] = (char)('i' + best);
        o.depth_axis = depth;
    }
    o.volume_path = vol_out;
    sc_import_result r;
    rc = sc_import_case(&o, &r, err, sizeof err);
    if (vol_out == tmp) {
        remove(tmp);
    }
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: reconstruct: import: %s: %s\n", sc_err_name(rc), err);
        return 1;
    }
    print_import(out, &r);
    rc = write_case_file(&r.def, o.has_drive ? &o.drive : NULL, out);
    sc_import_result_free(&r);
    return rc;
}

static int cmd_slice(int argc, char **argv)
{
    if (argc < 1) {
        return usage();
    }
    const char *path = argv[0], *out = NULL;
    int axis = 2, show_labels = 0;
    long index = -1;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--axis") == 0 && i + 1 < argc) {
            const char *ax = argv[++i];
            if ((ax[0] != 'x' && ax[0] != 'y' && ax[0] != 'z') || ax[1] != 0) {
                fprintf(stderr, "sc-casebuild: --axis '%s': x, y or z\n", ax);
                return 2;
            }
            axis = ax[0] - 'x';
        } else if (strcmp(argv[i], "--index") == 0 && i + 1 < argc) {
            uint32_t ix;
            if (num_u32("--index", argv[++i], 0u, SC_MAX_VOLUME_DIM - 1u, &ix) != 0) {
                return 2;
            }
            index = (long)ix;
        } else if (strcmp(argv[i], "-o") == 0 && i + 1 < argc) {
            out = argv[++i];
        } else if (strcmp(argv[i], "--labels") == 0) {
            show_labels = 1;
        } else {
            return usage();
        }
    }
    if (out == NULL) {
        return usage();
    }
    sc_storage_linux st;
    sc_storage_dev dev;
    const uint8_t *data;
    size_t size;
    sc_case c;
    if (open_case(&st, &dev, path, &data, &size, &c) != SC_OK) {
        return 1;
    }
    const uint32_t *d = c.volume.dim;
    if (index < 0) {
        index = (long)(d[axis] / 2u);
    }
    if ((unsigned long)index >= d[axis]) {
        fprintf(stderr, "sc-casebuild: index outside the grid\n");
        sc_storage_close(&dev, data, size);
        return 1;
    }
    /* image rows run along z (depth down) for x and y cuts, along y for a z cut */
    uint32_t w = axis == 0 ? d[1] : d[0];
    uint32_t h = axis == 2 ? d[1] : d[2];
    FILE *f = fopen(out, "wb");
    if (f == NULL) {
        fprintf(stderr, "sc-casebuild: cannot write %s\n", out);
        sc_storage_close(&dev, data, size);
        return 1;
    }
    fprintf(f, "P5\n%u %u\n255\n", w, h);
    const uint8_t *src = show_labels ? c.volume.labels : c.volume.voxels;
    for (uint32_t r = 0; r < h; r++) {
        for (uint32_t q = 0; q < w; q++) {
            size_t i, j, k;
            if (axis == 0) {
                i = (size_t)index, j = q, k = r;
            } else if (axis == 1) {
                i = q, j = (size_t)index, k = r;
            } else {
                i = q, j = r, k = (size_t)index;
            }
            uint8_t g = src[i + d[0] * (j + (size_t)d[1] * k)];
            if (show_labels) {
                g = (uint8_t)(g * 28u);
            }
            fputc(g, f);
        }
    }
    fclose(f);
    sc_storage_close(&dev, data, size);
    return 0;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Load time of the validating loader (CRC of every byte + one label pass) per case. */
static int cmd_bench(int argc, char **argv)
{
    int repeat = 11;
    int first = 0;
    if (argc >= 2 && strcmp(argv[0], "--repeat") == 0) {
        uint32_t rp;
        if (num_u32("--repeat", argv[1], 1u, 1000u, &rp) != 0) {
            return 2;
        }
        repeat = (int)rp;
        first = 2;
    }
    if (argc <= first) {
        return usage();
    }
    printf("%-40s %10s %10s %9s %9s %9s %9s\n", "case", "MB", "voxels", "map ms", "load min",
           "load med", "GB/s");
    int bad = 0;
    for (int i = first; i < argc; i++) {
        sc_storage_linux st;
        sc_storage_linux_init(&st, NULL);
        sc_storage_dev dev = sc_storage_linux_dev(&st);
        const uint8_t *data;
        size_t size;
        double t0 = now_ms();
        int rc = sc_storage_open(&dev, argv[i], &data, &size);
        double t_map = now_ms() - t0;
        if (rc != SC_OK) {
            fprintf(stderr, "%s: %s\n", argv[i], sc_err_name(rc));
            bad = 1;
            continue;
        }
        double *t = malloc((size_t)repeat * sizeof *t);
        sc_case c;
        for (int r = 0; r < repeat && rc == SC_OK; r++) {
            double a = now_ms();
            rc = sc_case_load(data, size, &c);
            t[r] = now_ms() - a;
        }
        if (rc != SC_OK) {
            fprintf(stderr, "%s: REFUSED: %s\n", argv[i], sc_err_name(rc));
            bad = 1;
        } else {
            qsort(t, (size_t)repeat, sizeof *t, cmp_dbl);
            printf("%-40s %10.2f %10" PRIu64 " %9.3f %9.2f %9.2f %9.2f\n", argv[i],
                   (double)size / 1e6, c.voxel_count, t_map, t[0], t[repeat / 2],
                   (double)size / 1e6 / t[repeat / 2]);
        }
        free(t);
        sc_storage_close(&dev, data, size);
    }
    return bad;
}

static int cmd_isosurface(int argc, char **argv)
{
    if (argc < 1) {
        return usage();
    }
    const char *path = argv[0], *out = NULL;
    sc_iso_opts o = sc_iso_default_opts();
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--label") == 0 && i + 1 < argc) {
            const char *l = argv[++i];
            o.label = -1;
            for (unsigned k = 0; k < sizeof label_names / sizeof label_names[0]; k++) {
                if (label_names[k] && strcmp(label_names[k], l) == 0) {
                    o.label = (int)k;
                }
            }
            if (o.label < 0) {
                uint32_t lv;
                if (num_u32("--label", l, 0u, SC_MAX_LABELS - 1u, &lv) != 0) {
                    return 2;
                }
                o.label = (int)lv;
            }
        } else if (strcmp(argv[i], "--sigma") == 0 && i + 1 < argc) {
            if (num_f32("--sigma", argv[++i], 0.0, 20.0, &o.sigma_mm) != 0) {
                return 2;
            }
        } else if (strcmp(argv[i], "--iterations") == 0 && i + 1 < argc) {
            if (num_u32("--iterations", argv[++i], 0u, 1000u, &o.iterations) != 0) {
                return 2;
            }
        } else if (strcmp(argv[i], "-o") == 0 && i + 1 < argc) {
            out = argv[++i];
        } else {
            return usage();
        }
    }
    if (out == NULL) {
        return usage();
    }
    sc_storage_linux st;
    sc_storage_dev dev;
    const uint8_t *data;
    size_t size;
    sc_case c;
    if (open_case(&st, &dev, path, &data, &size, &c) != SC_OK) {
        return 1;
    }
    sc_iso_mesh m;
    int rc = sc_iso_extract(&c.volume, &o, &m);
    if (rc == SC_OK) {
        size_t len = strlen(out);
        int obj = len > 4u && strcmp(out + len - 4u, ".obj") == 0;
        rc = obj ? sc_iso_write_obj(&m, out) : sc_iso_write_ply(&m, out);
        if (rc == SC_OK) {
            printf("%s: label %d: %zu vertices, %zu triangles\n", out, o.label, m.vertex_count,
                   m.triangle_count);
        }
        sc_iso_mesh_free(&m);
    }
    sc_storage_close(&dev, data, size);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-casebuild: isosurface: %s\n", sc_err_name(rc));
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        return usage();
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "phantom") == 0) {
        return cmd_phantom(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "import") == 0) {
        return cmd_import(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "reconstruct") == 0) {
        return cmd_reconstruct(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "info") == 0) {
        return cmd_info(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "verify") == 0) {
        return cmd_verify(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "slice") == 0) {
        return cmd_slice(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "isosurface") == 0) {
        return cmd_isosurface(argc - 2, argv + 2);
    }
    if (strcmp(cmd, "bench") == 0) {
        return cmd_bench(argc - 2, argv + 2);
    }
    return usage();
}
