/*
 * test_support.c -- helpers every suite may use; see test_support.h.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "test_support.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

static char workdir[256];

rad_context *test_context(int threads)
{
    rad_context_options o = {0};
    o.threads = threads;
    rad_context *ctx = NULL;
    assert_int_equal(rad_context_create(&o, &ctx), RAD_OK);
    return ctx;
}

int test_workdir_make(const char *tag)
{
    snprintf(workdir, sizeof workdir, "/tmp/radiosity-%s-XXXXXX", tag);
    return mkdtemp(workdir) ? 0 : -1;
}

int test_workdir_remove(void)
{
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", workdir);
    return system(cmd) == 0 ? 0 : -1;
}

const char *test_workdir(void) { return workdir; }

const char *test_path(const char *name)
{
    static char paths[4][1024];
    static int next;
    char *p = paths[next++ % 4];
    snprintf(p, sizeof paths[0], "%s/%s", workdir, name);
    return p;
}

char *test_read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot read %s", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    assert_true(n >= 0);
    char *bytes = malloc((size_t)n + 1);
    assert_non_null(bytes);
    assert_int_equal(fread(bytes, 1, (size_t)n, f), (size_t)n);
    bytes[n] = '\0';
    fclose(f);
    if (size)
        *size = (size_t)n;
    return bytes;
}

void test_read_into(const char *path, char *buf, size_t size)
{
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    size_t n = fread(buf, 1, size - 1, f);
    buf[n] = '\0';
    fclose(f);
}

void test_write_file(const char *name, const char *text)
{
    FILE *f = fopen(test_path(name), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

bool test_file_exists(const char *path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

void test_put(test_text *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    assert_true(n >= 0);
    if (t->length + (size_t)n + 1 > t->capacity) {
        t->capacity = 2 * (t->length + (size_t)n + 1);
        t->data = realloc(t->data, t->capacity);
        assert_non_null(t->data);
    }
    va_start(ap, fmt);
    vsnprintf(t->data + t->length, (size_t)n + 1, fmt, ap);
    va_end(ap);
    t->length += (size_t)n;
}
