/* sc_hs_storage.c: named in-memory case images, see sc_hs_storage.h. */
#include "sc_hs_storage.h"

#include <string.h>

#include "sc_err.h"

void sc_hs_storage_init(sc_hs_storage *s)
{
    memset(s, 0, sizeof(*s));
}

int sc_hs_storage_add(sc_hs_storage *s, const char *name, const uint8_t *data, size_t size)
{
    if (!name || !data) {
        return SC_ERR_INVALID_ARG;
    }
    if (s->count >= SC_HS_STORAGE_MAX) {
        return SC_ERR_NO_SPACE;
    }
    s->entries[s->count++] = (sc_hs_storage_entry){.name = name, .data = data, .size = size};
    return SC_OK;
}

static int hs_open(void *ctx, const char *name, const uint8_t **data, size_t *size)
{
    sc_hs_storage *s = ctx;
    for (uint32_t i = 0; i < s->count; i++) {
        if (strcmp(s->entries[i].name, name) == 0) {
            *data = s->entries[i].data;
            *size = s->entries[i].size;
            s->opens++;
            return SC_OK;
        }
    }
    return SC_ERR_NOT_FOUND;
}

static void hs_close(void *ctx, const uint8_t *data, size_t size)
{
    (void)data;
    (void)size;
    ((sc_hs_storage *)ctx)->closes++;
}

static const sc_storage_ops hs_storage_ops = {.open = hs_open, .close = hs_close};

sc_storage_dev sc_hs_storage_dev(sc_hs_storage *s)
{
    return (sc_storage_dev){.ops = &hs_storage_ops, .ctx = s};
}
