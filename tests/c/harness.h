/*
 * Tiny test harness for the C ABI tests, in the style of Box2D v3's tests/test_macros.h.
 *
 * A test is a function `static int name(void)` returning 0 on success. The ENSURE* macros print
 * file:line and the failing expression and make the enclosing test return 1. RUN_TEST runs one test,
 * counts it as passed or failed, and afterwards runs the cleanups the test registered with
 * harness_defer() (so a failing test does not leak what it created). HARNESS_SUMMARY() prints the final
 * "N passed, M failed" line and yields the process exit code.
 *
 * Single translation unit only: the counters are static.
 */

#ifndef KDW_TEST_HARNESS_H
#define KDW_TEST_HARNESS_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "kodawari.h"

static int harness_passed = 0;
static int harness_failed = 0;

/* ---- deferred cleanups ------------------------------------------------------------------------------ */

#define HARNESS_MAX_DEFERRED 64

typedef void (*harness_cleanup_fn)(void *context);

static harness_cleanup_fn harness_deferred_fn[HARNESS_MAX_DEFERRED];
static void *harness_deferred_context[HARNESS_MAX_DEFERRED];
static int harness_deferred_count = 0;

/* Registers `fn(context)` to run after the current test, whether it passes or fails. */
static inline void harness_defer(harness_cleanup_fn fn, void *context)
{
    if (harness_deferred_count == HARNESS_MAX_DEFERRED) {
        fprintf(stderr, "harness: more than %d deferred cleanups in one test\n", HARNESS_MAX_DEFERRED);
        return;
    }
    harness_deferred_fn[harness_deferred_count] = fn;
    harness_deferred_context[harness_deferred_count] = context;
    harness_deferred_count += 1;
}

/* Forgets the cleanup registered for `context` (the test released it itself). */
static inline void harness_cancel(void *context)
{
    for (int i = harness_deferred_count - 1; i >= 0; --i) {
        if (harness_deferred_context[i] == context) {
            for (int j = i; j + 1 < harness_deferred_count; ++j) {
                harness_deferred_fn[j] = harness_deferred_fn[j + 1];
                harness_deferred_context[j] = harness_deferred_context[j + 1];
            }
            harness_deferred_count -= 1;
            return;
        }
    }
}

/* Runs the registered cleanups, last registered first. */
static inline void harness_run_deferred(void)
{
    while (harness_deferred_count > 0) {
        harness_deferred_count -= 1;
        harness_deferred_fn[harness_deferred_count](harness_deferred_context[harness_deferred_count]);
    }
}

/* ---- reporting ---------------------------------------------------------------------------------------- */

/* This thread's last library error message, for failure reports (static buffer; never NULL). */
static inline const char *harness_last_error(void)
{
    static char buffer[512];
    buffer[0] = '\0';
    uint32_t length = 0;
    (void)kdw_last_error_message(buffer, (uint32_t)sizeof buffer, &length);
    return buffer;
}

#define RUN_TEST(fn)                                                                                       \
    do {                                                                                                   \
        int harness_result_ = fn();                                                                        \
        harness_run_deferred();                                                                            \
        if (harness_result_ == 0) {                                                                        \
            harness_passed += 1;                                                                           \
            printf("  ok    %s\n", #fn);                                                                   \
        } else {                                                                                           \
            harness_failed += 1;                                                                           \
            printf("  FAIL  %s\n", #fn);                                                                   \
        }                                                                                                  \
        fflush(stdout);                                                                                    \
    } while (0)

/* Prints the one summary line and evaluates to the process exit code. */
#define HARNESS_SUMMARY()                                                                                  \
    (printf("%d passed, %d failed\n", harness_passed, harness_failed), fflush(stdout),                     \
     harness_failed == 0 ? 0 : 1)

#define ENSURE(condition)                                                                                  \
    do {                                                                                                   \
        if (!(condition)) {                                                                                \
            printf("%s:%d: ENSURE failed: %s\n", __FILE__, __LINE__, #condition);                          \
            return 1;                                                                                      \
        }                                                                                                  \
    } while (0)

/* |value| <= tol; NaN fails. */
#define ENSURE_SMALL(value, tol)                                                                           \
    do {                                                                                                   \
        double harness_value_ = (double)(value);                                                           \
        double harness_tol_ = (double)(tol);                                                               \
        if (!(fabs(harness_value_) <= harness_tol_)) {                                                     \
            printf("%s:%d: ENSURE_SMALL failed: |%s| = %.9g > %.9g\n", __FILE__, __LINE__, #value,         \
                   fabs(harness_value_), harness_tol_);                                                    \
            return 1;                                                                                      \
        }                                                                                                  \
    } while (0)

/* `call` must return the kdw_status `expected`. */
#define ENSURE_STATUS(call, expected)                                                                      \
    do {                                                                                                   \
        kdw_status harness_got_ = (call);                                                                  \
        kdw_status harness_want_ = (expected);                                                             \
        if (harness_got_ != harness_want_) {                                                               \
            printf("%s:%d: ENSURE_STATUS failed: %s\n", __FILE__, __LINE__, #call);                        \
            printf("    got %d (%s), expected %d (%s)\n", (int)harness_got_, kdw_status_str(harness_got_),  \
                   (int)harness_want_, kdw_status_str(harness_want_));                                     \
            printf("    last error message: \"%s\"\n", harness_last_error());                              \
            return 1;                                                                                      \
        }                                                                                                  \
    } while (0)

#define ENSURE_OK(call) ENSURE_STATUS(call, KDW_STATUS_OK)

#endif /* KDW_TEST_HARNESS_H */
