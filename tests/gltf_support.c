/*
 * gltf_support.c -- helpers of test_export and test_bake (gltf_support.h).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "gltf_support.h"
#include "test_support.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

uint32_t support_le_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

float support_le_f32(const unsigned char *p)
{
    uint32_t bits = support_le_u32(p);
    float v;
    memcpy(&v, &bits, 4);
    return v;
}

void support_validate_gltf(const char *source_dir, const char *modules, const char *const *paths,
                           size_t count, const char *allowed_warning, const char *report)
{
    char package[600];
    snprintf(package, sizeof package, "%s/gltf-validator/package.json", modules);
    if (system("command -v node >/dev/null 2>&1") != 0 || access(package, F_OK) != 0) {
        printf("# gltf-validator: skipped (needs node and %s: scripts/setup.sh installs it with npm)\n", package);
        skip();
    }
    char cmd[4096];
    int n = snprintf(cmd, sizeof cmd, "node '%s/validate_gltf.js' '%s'", source_dir, modules);
    for (size_t k = 0; k < count; k++)
        n += snprintf(cmd + n, sizeof cmd - (size_t)n, " '%s'", paths[k]);
    snprintf(cmd + n, sizeof cmd - (size_t)n, " >'%s' 2>&1", report);
    int status = system(cmd);
    size_t size;
    unsigned char *text = (unsigned char *)test_read_file(report, &size);
    printf("%s", (const char *)text); /* the counts, and every error and warning */
    fflush(stdout);
    for (size_t k = 0; k < count; k++) {
        const char *name = strrchr(paths[k], '/') ? strrchr(paths[k], '/') + 1 : paths[k];
        char expected[600];
        snprintf(expected, sizeof expected, "%s: 0 errors", name);
        if (!strstr((const char *)text, expected))
            fail_msg("the validator did not say '%s'", expected);
    }
    for (const char *line = (const char *)text; (line = strstr(line, "  warning ")); line++)
        if (!allowed_warning || strncmp(line + 10, allowed_warning, strlen(allowed_warning)) != 0)
            fail_msg("unexpected validator warning: %.120s", line);
    free(text);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}
