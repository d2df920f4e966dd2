/*
 * test_support.h -- helpers every suite may use (the rad_test_support
 * library): a context, a work folder under /tmp and the paths in it, whole
 * files read and written, text that grows as it is printed into, and the
 * comparison of two numbers to a tolerance.
 *
 * Failures go through cmocka (fail_msg and the assert_* macros), so these
 * are for use inside a running test, or a group's setup and teardown.
 * cli_support.h adds what the suites that drive the `radiosity` program
 * share.
 */
#ifndef RAD_TESTS_TEST_SUPPORT_H
#define RAD_TESTS_TEST_SUPPORT_H

#include <radiosity.h>

#include <stdbool.h>
#include <stddef.h>

#if defined(__GNUC__)
#define TEST_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define TEST_PRINTF(fmt, args)
#endif

/* ---- numbers ---- */

/* Fails the test unless |a - b| <= tol, naming both expressions. */
#define assert_near(a, b, tol)                                                              \
    do {                                                                                    \
        double a_ = (a), b_ = (b), tol_ = (tol);                                            \
        if (!(fabs(a_ - b_) <= tol_))                                                       \
            fail_msg("%s = %.17g, %s = %.17g, differ by more than %g", #a, a_, #b, b_, tol_); \
    } while (0)

/* ---- the context ---- */

/* A context with `threads` threads, the other options their defaults;
 * fails the test if it cannot be made.  The caller destroys it. */
rad_context *test_context(int threads);

/* ---- the work folder ---- */

/* Makes /tmp/radiosity-TAG-XXXXXX the work folder; 0, or -1 on failure. */
int test_workdir_make(const char *tag);
/* Removes the work folder with everything in it; 0, or -1 on failure. */
int test_workdir_remove(void);
/* The folder made by test_workdir_make. */
const char *test_workdir(void);
/* The path of `name` in the work folder, in one of four static buffers
 * used in turn: four paths can be held at once. */
const char *test_path(const char *name);

/* ---- files ---- */

/* The whole file with a NUL after its bytes (free it); *size (size may be
 * NULL) its bytes.  Fails the test when the file cannot be read. */
char *test_read_file(const char *path, size_t *size);
/* At most size - 1 bytes of the file into buf, NUL-terminated; "" when
 * the file cannot be read. */
void test_read_into(const char *path, char *buf, size_t size);
/* Writes `text` as the file `name` of the work folder; fails the test if
 * it cannot. */
void test_write_file(const char *name, const char *text);
/* Is there anything at `path`: a file, a folder, a link (dangling too)? */
bool test_file_exists(const char *path);

/* ---- text that grows ---- */

/* Printed into by test_put; zero-initialise, free(data) when done. */
typedef struct test_text {
    char *data;               /* NUL-terminated once anything is put */
    size_t length, capacity;  /* bytes, the NUL not counted in length */
} test_text;

/* Appends printf-formatted text to t. */
void test_put(test_text *t, const char *fmt, ...) TEST_PRINTF(2, 3);

#endif
