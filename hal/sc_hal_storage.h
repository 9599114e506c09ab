/*
 * sc_hal_storage.h: read-only case storage.
 *
 * A case is a named, immutable byte image: mmap'd read-only on Linux, a flash region on an
 * MCU, a const array in tests. open() maps it and hands out a pointer valid until close();
 * the core never writes through it and never copies the volume. Both ops are mandatory.
 * open: SC_ERR_NOT_FOUND for an unknown name, SC_ERR_IO when the platform cannot map it.
 */
#ifndef SC_HAL_STORAGE_H
#define SC_HAL_STORAGE_H

#include <stddef.h>
#include <stdint.h>

typedef struct sc_storage_ops {
    int (*open)(void *ctx, const char *name, const uint8_t **data, size_t *size);
    void (*close)(void *ctx, const uint8_t *data, size_t size);
} sc_storage_ops;

typedef struct sc_storage_dev {
    const sc_storage_ops *ops;
    void *ctx;
} sc_storage_dev;

static inline int sc_storage_open(const sc_storage_dev *dev, const char *name,
                                  const uint8_t **data, size_t *size)
{
    return dev->ops->open(dev->ctx, name, data, size);
}

static inline void sc_storage_close(const sc_storage_dev *dev, const uint8_t *data, size_t size)
{
    dev->ops->close(dev->ctx, data, size);
}

#endif /* SC_HAL_STORAGE_H */
