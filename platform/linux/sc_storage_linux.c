/* sc_storage_linux.c: mmap'd read-only case files, see sc_storage_linux.h. */
#include "sc_storage_linux.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sc_err.h"

/* What an empty file maps to: a valid pointer with size 0. */
static const uint8_t sc_storage_linux_empty[1];

static int storage_open(void *ctx, const char *name, const uint8_t **data, size_t *size)
{
    sc_storage_linux *s = (sc_storage_linux *)ctx;
    if (s == NULL || name == NULL || name[0] == '\0' || data == NULL || size == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    char path[SC_STORAGE_LINUX_PATH_MAX];
    int n;
    if (name[0] == '/' || s->base_dir == NULL || s->base_dir[0] == '\0') {
        n = snprintf(path, sizeof path, "%s", name);
    } else {
        n = snprintf(path, sizeof path, "%s/%s", s->base_dir, name);
    }
    if (n < 0 || (size_t)n >= sizeof path) {
        return SC_ERR_NO_SPACE;
    }
    /* O_NONBLOCK: a FIFO (or a device) must not block the open; it is refused below */
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        s->last_errno = errno;
        return (errno == ENOENT || errno == ENOTDIR) ? SC_ERR_NOT_FOUND : SC_ERR_IO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size < 0) {
        s->last_errno = errno != 0 ? errno : EINVAL;
        (void)close(fd);
        return SC_ERR_IO;
    }
    if ((uint64_t)st.st_size > (uint64_t)SIZE_MAX ||
        (uint64_t)st.st_size > (uint64_t)SC_STORAGE_LINUX_MAX_BYTES) {
        s->last_errno = EFBIG;
        (void)close(fd);
        return SC_ERR_IO;
    }
    size_t len = (size_t)st.st_size;
    if (len == 0u) {
        (void)close(fd);
        *data = sc_storage_linux_empty;
        *size = 0;
        s->last_errno = 0;
        s->open_count++;
        return SC_OK;
    }
    /* The bytes are copied into memory the appliance owns (anonymous, read-only once filled):
     * a file mapping would raise SIGBUS on access after the file was truncated underneath;
     * the case loader reads every byte at load anyway. */
    void *p = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) {
        s->last_errno = errno;
        (void)close(fd);
        return SC_ERR_IO;
    }
    size_t got = 0;
    while (got < len) {
        const ssize_t r = read(fd, (uint8_t *)p + got, len - got);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r <= 0) { /* an error, or the file shrank while read */
            s->last_errno = r < 0 ? errno : EIO;
            (void)close(fd);
            (void)munmap(p, len);
            return SC_ERR_IO;
        }
        got += (size_t)r;
    }
    (void)close(fd);
    (void)mprotect(p, len, PROT_READ);
    *data = (const uint8_t *)p;
    *size = len;
    s->last_errno = 0;
    s->open_count++;
    return SC_OK;
}

static void storage_close(void *ctx, const uint8_t *data, size_t size)
{
    sc_storage_linux *s = (sc_storage_linux *)ctx;
    if (data == NULL) {
        return;
    }
    if (size > 0u && data != sc_storage_linux_empty) {
        (void)munmap((void *)(uintptr_t)data, size);
    }
    if (s != NULL && s->open_count > 0u) {
        s->open_count--;
    }
}

static const sc_storage_ops sc_storage_linux_ops = {
    .open = storage_open,
    .close = storage_close,
};

void sc_storage_linux_init(sc_storage_linux *s, const char *base_dir)
{
    s->base_dir = base_dir;
    s->last_errno = 0;
    s->open_count = 0;
}

sc_storage_dev sc_storage_linux_dev(sc_storage_linux *s)
{
    return (sc_storage_dev){.ops = &sc_storage_linux_ops, .ctx = s};
}

int sc_storage_linux_list(const char *dir, const char *suffix,
                          char (*names)[SC_STORAGE_LINUX_NAME_MAX], uint32_t max,
                          uint32_t *count)
{
    if (!suffix || !names || !count) {
        return SC_ERR_INVALID_ARG;
    }
    *count = 0;
    const char *d = (dir && dir[0] != '\0') ? dir : ".";
    DIR *dp = opendir(d);
    if (!dp) {
        return errno == ENOENT ? SC_ERR_NOT_FOUND : SC_ERR_IO;
    }
    const size_t sl = strlen(suffix);
    int rc = 0;
    for (struct dirent *de = readdir(dp); de != NULL; de = readdir(dp)) {
        const size_t n = strlen(de->d_name);
        if (n <= sl || n >= SC_STORAGE_LINUX_NAME_MAX || strcmp(de->d_name + n - sl, suffix) != 0 ||
            de->d_name[0] == '.') {
            continue;
        }
        struct stat st;
        if (fstatat(dirfd(dp), de->d_name, &st, 0) != 0 || !S_ISREG(st.st_mode)) {
            continue;
        }
        /* insertion in order; beyond max the last in order falls off */
        uint32_t i = *count;
        while (i > 0u && strcmp(names[i - 1u], de->d_name) > 0) {
            i--;
        }
        if (i >= max) {
            rc = SC_ERR_NO_SPACE;
            continue;
        }
        const uint32_t last = *count < max ? *count : max - 1u;
        if (*count >= max) {
            rc = SC_ERR_NO_SPACE;
        }
        for (uint32_t j = last; j > i; j--) {
            memcpy(names[j], names[j - 1u], SC_STORAGE_LINUX_NAME_MAX);
        }
        memcpy(names[i], de->d_name, n + 1u);
        if (*count < max) {
            (*count)++;
        }
    }
    closedir(dp);
    return rc;
}

FILE *sc_fopen_regular(const char *path)
{
    if (path == NULL) {
        errno = EINVAL;
        return NULL;
    }
    const int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        return NULL;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const int e = errno != 0 && !S_ISREG(st.st_mode) ? EINVAL : errno;
        (void)close(fd);
        errno = e != 0 ? e : EINVAL;
        return NULL;
    }
    const int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) != 0) {
        const int e = errno;
        (void)close(fd);
        errno = e;
        return NULL;
    }
    FILE *f = fdopen(fd, "r");
    if (f == NULL) {
        const int e = errno;
        (void)close(fd);
        errno = e;
    }
    return f;
}
