/*
 * sc_hs_storage.h: read-only case storage for the host simulator: a fixed table of named
 * byte images (const arrays, or files the runner read into memory at start-up).
 */
#ifndef SC_HS_STORAGE_H
#define SC_HS_STORAGE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_hal_storage.h"

#ifndef SC_HS_STORAGE_MAX
#define SC_HS_STORAGE_MAX 8u
#endif

typedef struct sc_hs_storage_entry {
    const char *name;
    const uint8_t *data;
    size_t size;
} sc_hs_storage_entry;

typedef struct sc_hs_storage {
    sc_hs_storage_entry entries[SC_HS_STORAGE_MAX];
    uint32_t count;
    uint32_t opens, closes;
} sc_hs_storage;

void sc_hs_storage_init(sc_hs_storage *s);
/* Register a named image (name and data must outlive the storage). SC_ERR_NO_SPACE when full. */
int sc_hs_storage_add(sc_hs_storage *s, const char *name, const uint8_t *data, size_t size);
sc_storage_dev sc_hs_storage_dev(sc_hs_storage *s);

#endif /* SC_HS_STORAGE_H */
