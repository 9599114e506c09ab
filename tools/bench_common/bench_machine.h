/* bench_machine.h: the line a benchmark prints about the machine it ran on, beside its kernels
 * line. Every figure of docs/performance.md is only meaningful against its machine. These VMs
 * have not always been the same CPU. The figures up to the scale6 session came from an x86-64-v4
 * EPYC. The scale7 session measured everything about 1.5x slower and read that as a loaded host.
 * The next session found a family 25 model 1 EPYC (512 KiB L2, AVX2 only) that gave the same
 * slower figures. Reads /proc/cpuinfo and
 * /sys/devices/system/cpu/cpu0/cache (Linux); whatever it cannot read it leaves out. */
#ifndef BENCH_MACHINE_H
#define BENCH_MACHINE_H

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "sc_cpu.h"
#include "sc_err.h"

/* the value of the first "key\t: value" line of /proc/cpuinfo whose key is `key`, into out */
static inline int bench_cpuinfo(const char *key, char *out, size_t size)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f == NULL) {
        return -1;
    }
    char line[512];
    const size_t kl = strlen(key);
    int found = -1;
    while (fgets(line, sizeof line, f) != NULL) {
        if (strncmp(line, key, kl) != 0) {
            continue;
        }
        const char *v = line + kl; /* only blanks between the key and ':' ("model name" is not
                                      "model") */
        while (*v == '\t' || *v == ' ') {
            v++;
        }
        if (*v != ':') {
            continue;
        }
        v++;
        while (*v == ' ') {
            v++;
        }
        snprintf(out, size, "%s", v);
        out[strcspn(out, "\n")] = '\0';
        found = 0;
        break;
    }
    fclose(f);
    return found;
}

/* the size of cpu0's cache of `level` (2 or 3) as sysfs gives it ("512K"), or "?" */
static inline void bench_cache_size(int level, char *out, size_t size)
{
    snprintf(out, size, "?");
    for (int i = 0; i < 8; i++) {
        char path[96], buf[32];
        snprintf(path, sizeof path, "/sys/devices/system/cpu/cpu0/cache/index%d/level", i);
        FILE *f = fopen(path, "r");
        if (f == NULL) {
            return;
        }
        const int ok = fgets(buf, sizeof buf, f) != NULL;
        fclose(f);
        if (!ok || buf[0] != (char)('0' + level)) {
            continue;
        }
        snprintf(path, sizeof path, "/sys/devices/system/cpu/cpu0/cache/index%d/size", i);
        f = fopen(path, "r");
        if (f == NULL) {
            return;
        }
        if (fgets(buf, sizeof buf, f) != NULL) {
            buf[strcspn(buf, "\n")] = '\0';
            snprintf(out, size, "%s", buf);
        }
        fclose(f);
        return;
    }
}

/* "machine: AMD EPYC (family 25 model 1), 2 CPUs, L2 512K, L3 32768K" */
static inline void bench_print_machine(void)
{
    char name[128] = "?", fam[16] = "?", model[16] = "?", l2[32], l3[32];
    (void)bench_cpuinfo("model name", name, sizeof name);
    (void)bench_cpuinfo("cpu family", fam, sizeof fam);
    (void)bench_cpuinfo("model", model, sizeof model);
    bench_cache_size(2, l2, sizeof l2);
    bench_cache_size(3, l3, sizeof l3);
    printf("machine: %s (family %s model %s), %ld CPUs online, L2 %s, L3 %s per cpu0\n", name,
           fam, model, sysconf(_SC_NPROCESSORS_ONLN), l2, l3);
}

/* The mat-vec's prefetch as sonocomp chooses it (sc_cpu.h: measured, or SONOCOMP_PREFETCH),
 * and its line: "mat-vec prefetch off (measured on 64x32x32: ...)" */
static inline void bench_select_prefetch(const char *prog)
{
    sc_cpu_prefetch pf;
    if (sc_cpu_select_prefetch(1, &pf) != SC_OK) {
        fprintf(stderr, "%s: SONOCOMP_PREFETCH not mesh, on or off (or no memory to measure)\n",
                prog);
    }
    char line[160];
    sc_cpu_prefetch_describe(&pf, line, sizeof line);
    printf("%s\n", line);
}

#endif /* BENCH_MACHINE_H */
