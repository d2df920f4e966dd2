/*
 * json.c -- the project's JSON input files (thermal conditions, luminaire
 * layouts, calculation grids, daylight) read one way: cJSON, strict (the
 * object and blanks, nothing after it), errors naming the file and line.
 */
#include "core/core.h"

#include <cjson/cJSON.h>

/* 1-based line of byte `at` of text. */
static int line_of(const char *text, size_t at)
{
    int line = 1;
    for (size_t k = 0; k < at; k++)
        line += text[k] == '\n';
    return line;
}

rad_result rad_json_parse(rad_context *ctx, const char *name, const char *text, size_t size, struct cJSON **out)
{
    const char *end = NULL;
    cJSON *root = size > 0 ? cJSON_ParseWithLengthOpts(text, size, &end, false) : NULL;
    *out = NULL;
    if (!root) {
        size_t at = end && end >= text && end <= text + size ? (size_t)(end - text) : 0;
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: not valid JSON", name, line_of(text, at));
    }
    /* Nothing but blanks after the object (a final NUL allowed). */
    size_t at = (size_t)(end - text);
    while (at < size && (text[at] == ' ' || text[at] == '\t' || text[at] == '\n' || text[at] == '\r'))
        at++;
    if (at < size && !(at + 1 == size && text[at] == '\0')) {
        cJSON_Delete(root);
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: text after the JSON object", name, line_of(text, at));
    }
    *out = root;
    return RAD_OK;
}
