/*
 * sc_storage_linux.h: hal storage (sc_hal_storage.h) for Linux: a case is a regular file,
 * opened by path without blocking (a FIFO or a device is refused, never waited on) and read
 * whole into anonymous memory the appliance owns, read-only once filled: the core reads the
 * voxels there in place, and a file truncated or rewritten while its case runs cannot reach it
 * (a file mapping would raise SIGBUS). O(file size) per open, at most
 * SC_STORAGE_LINUX_MAX_BYTES. A relative name is resolved against the storage's base directory
 * (or the working directory when none is set); an absolute path is used as is.
 *
 * open: SC_ERR_NOT_FOUND (no such file), SC_ERR_IO (not readable, not a regular file, larger
 * than the ceiling (EFBIG), a short read; the reason is kept in last_errno), SC_ERR_NO_SPACE (path longer than
 * SC_STORAGE_LINUX_PATH_MAX), SC_ERR_INVALID_ARG. An empty file opens as size 0 (the case
 * loader then answers SC_ERR_CASE_TRUNCATED). close: munmap. One storage object per thread.
 */
#ifndef SC_STORAGE_LINUX_H
#define SC_STORAGE_LINUX_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sc_hal_storage.h"

#ifndef SC_STORAGE_LINUX_MAX_BYTES
#define SC_STORAGE_LINUX_MAX_BYTES (1024u * 1024u * 1024u) /* ceiling of a case file */
#endif
#ifndef SC_STORAGE_LINUX_PATH_MAX
#define SC_STORAGE_LINUX_PATH_MAX 4096u
#endif

typedef struct sc_storage_linux {
    const char *base_dir; /* may be NULL */
    int last_errno;       /* errno of the last failed open, 0 otherwise */
    uint32_t open_count;  /* mappings currently open */
} sc_storage_linux;

#ifndef SC_STORAGE_LINUX_NAME_MAX
#define SC_STORAGE_LINUX_NAME_MAX 256u /* a listed file name, with the NUL */
#endif

/* The regular files in dir (NULL: the working directory) whose names end in suffix, sorted
 * by name (strcmp), at most max of them into names[0..*count). Names that do not fit
 * SC_STORAGE_LINUX_NAME_MAX are skipped. O(directory entries x max). Errors: SC_ERR_INVALID_ARG,
 * SC_ERR_NOT_FOUND / SC_ERR_IO (the directory cannot be read), SC_ERR_NO_SPACE (more than max
 * files: the first max in order are listed). */
int sc_storage_linux_list(const char *dir, const char *suffix,
                          char (*names)[SC_STORAGE_LINUX_NAME_MAX], uint32_t max,
                          uint32_t *count);

/* fopen(path, "r") for input files (configuration, CAN logs, pose scripts) that must be
 * regular files: opened without blocking (a FIFO, device or directory is refused at once with
 * errno EINVAL/ENOENT/..., never waited on), then used as an ordinary blocking stream. NULL with
 * errno set on refusal. O(1). */
FILE *sc_fopen_regular(const char *path);

/* base_dir may be NULL; the string must outlive the storage. */
void sc_storage_linux_init(sc_storage_linux *s, const char *base_dir);
sc_storage_dev sc_storage_linux_dev(sc_storage_linux *s);

#endif /* SC_STORAGE_LINUX_H */
