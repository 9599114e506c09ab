/*
 * sc_assert.h: assertions in three strengths.
 *
 * - SC_ASSERT(c): a programmer error (broken precondition inside the engine). Calls the
 *   overridable hook sc_assert_failed(), which the platform defines (hostsim: abort with a
 *   message; Linux appliance: log and let the watchdog reset; bare metal: breakpoint + reset).
 *   Compiled in unless SC_NO_ASSERT is defined.
 * - SC_VALIDATE(c): an expensive invariant (mesh orientation, CSR symmetry, ...), compiled
 *   only with SC_ENABLE_VALIDATE (the dev preset), same hook.
 * - Plain checked returns (negative sc_err) for anything the outside world can get wrong:
 *   outside input never reaches an assert.
 *
 * Never allocates; the hook must not return into the failing code path in release images.
 */
#ifndef SC_ASSERT_H
#define SC_ASSERT_H

/* Defined by the platform. file/line identify the call site; expr is the stringified test. */
void sc_assert_failed(const char *file, int line, const char *expr);

#ifdef SC_NO_ASSERT
#define SC_ASSERT(c) ((void)0)
#else
#define SC_ASSERT(c) ((c) ? (void)0 : sc_assert_failed(__FILE__, __LINE__, #c))
#endif

#ifdef SC_ENABLE_VALIDATE
#define SC_VALIDATE(c) SC_ASSERT(c)
#else
#define SC_VALIDATE(c) ((void)0)
#endif

#define SC_STATIC_ASSERT(c, msg) _Static_assert(c, msg)
#define SC_COUNT_OF(a) (sizeof(a) / sizeof((a)[0]))

#endif /* SC_ASSERT_H */
