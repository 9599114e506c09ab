/*
 * sc_hal_log.h: structured log records from the core.
 *
 * The core has no printf: it emits a record of a level, a static event name (a string
 * literal with static storage), an sc_err code and two integer arguments. The platform formats
 * it (text line, journald, a ring in RAM on an MCU). Must be non-blocking and bounded: a
 * platform that cannot keep up drops and counts. Mandatory when the device is present; a NULL
 * ops pointer in sc_log_dev means "no log" and the inline wrapper does nothing.
 */
#ifndef SC_HAL_LOG_H
#define SC_HAL_LOG_H

#include <stdint.h>

typedef enum sc_log_level {
    SC_LOG_DEBUG = 0,
    SC_LOG_INFO,
    SC_LOG_WARN,
    SC_LOG_ERROR,
} sc_log_level;

/* The level's lower-case name ("debug", "info", "warn", "error"), "?" otherwise. O(1). */
static inline const char *sc_log_level_name(sc_log_level level)
{
    switch (level) {
    case SC_LOG_DEBUG:
        return "debug";
    case SC_LOG_INFO:
        return "info";
    case SC_LOG_WARN:
        return "warn";
    case SC_LOG_ERROR:
        return "error";
    }
    return "?";
}

typedef struct sc_log_ops {
    void (*write)(void *ctx, sc_log_level level, const char *event, int err, int64_t a,
                  int64_t b);
} sc_log_ops;

typedef struct sc_log_dev {
    const sc_log_ops *ops;
    void *ctx;
} sc_log_dev;

static inline void sc_log(const sc_log_dev *dev, sc_log_level level, const char *event, int err,
                          int64_t a, int64_t b)
{
    if (dev && dev->ops) {
        dev->ops->write(dev->ctx, level, event, err, a, b);
    }
}

#endif /* SC_HAL_LOG_H */
