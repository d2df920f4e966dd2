/*
 * obj_prescan.c -- a light pre-scan of OBJ and MTL text, for the errors
 * assimp 5.2 omits or gets wrong: its OBJ parser reads "nan", garbage and
 * out-of-range numbers leniently, drops vertices of unexpected arity, skips
 * indented statements, stops at a NUL byte, and reports no line numbers.
 *
 *    text --lines--> tokens --checks--> "scene.obj:12: face references vertex 40 of 32"
 *
 * Not a parser: it checks vertex coordinates, face/line/point indices and
 * Kd/Ke, and finds the first `mtllib`; assimp reads the text afterwards.
 * The statements are those of Wavefront's "Object Files (.obj)", Appendix
 * B1 of the Advanced Visualizer manual.  Works on buffers (which need not
 * end in NUL), so the fuzzers drive it from memory.
 */
#include "scene/import_internal.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---- reading text line by line (buffers need not end in NUL) ---- */

typedef struct text_lines {
    const char *next, *end;
    int number; /* 1-based number of the line last returned */
} text_lines;

static text_lines text_lines_of(const char *text, size_t size)
{
    text_lines t = {text, text + size, 0};
    return t;
}

/* The next line, without its end of line, in [*line, *line_end). */
static bool next_line(text_lines *t, const char **line, const char **line_end)
{
    if (t->next >= t->end)
        return false;
    const char *start = t->next;
    const char *newline = memchr(start, '\n', (size_t)(t->end - start));
    const char *stop = newline ? newline : t->end;
    t->next = newline ? newline + 1 : t->end;
    if (stop > start && stop[-1] == '\r')
        stop--;
    t->number++;
    *line = start;
    *line_end = stop;
    return true;
}

/* Copy the next blank-separated token of [*p, end) into `token` (cut to
 * TOKEN_SIZE - 1 characters) and return its full length; 0 at the end.
 * Blanks are spaces and tabs only, as assimp has them: a form feed or
 * vertical tab is part of a token, so "v\v1 2 3" is no vertex here either. */
enum { TOKEN_SIZE = 128 };

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

static size_t next_token(const char **p, const char *end, char *token)
{
    const char *s = *p;
    while (s < end && is_blank(*s))
        s++;
    const char *e = s;
    while (e < end && !is_blank(*e))
        e++;
    size_t length = (size_t)(e - s);
    size_t copied = length < TOKEN_SIZE - 1 ? length : TOKEN_SIZE - 1;
    memcpy(token, s, copied);
    token[copied] = '\0';
    *p = e;
    return length;
}

/* The rest of the line, blanks trimmed, cut to `size` - 1 characters. */
static void rest_of_line(const char *p, const char *end, char *out, size_t size)
{
    while (p < end && isspace((unsigned char)*p))
        p++;
    while (end > p && isspace((unsigned char)end[-1]))
        end--;
    size_t length = (size_t)(end - p) < size - 1 ? (size_t)(end - p) : size - 1;
    memcpy(out, p, length);
    out[length] = '\0';
}

typedef enum number_kind { NUMBER_FINITE, NUMBER_NOT_FINITE, NUMBER_GARBAGE } number_kind;

/* A number as OBJ and MTL files write it: digits, sign, '.' and an
 * exponent ("1", "-0.5", ".5", "2e-3"); assimp misreads "0x1p3", so that
 * is garbage here.  "nan", "inf" and "1e999" are numbers that are not
 * finite. */
static number_kind parse_number(const char *token, size_t length, double *value)
{
    if (length == 0 || length >= TOKEN_SIZE)
        return NUMBER_GARBAGE;
    char *end;
    *value = strtod(token, &end);
    if (end != token + length)
        return NUMBER_GARBAGE;
    if (!isfinite(*value))
        return NUMBER_NOT_FINITE;
    return strspn(token, "0123456789+-.eE") == length ? NUMBER_FINITE : NUMBER_GARBAGE;
}

/* ---- pre-scan of OBJ and MTL text: line-numbered errors assimp omits ---- */

/* Statements of the OBJ format (Wavefront, "Object Files (.obj)", Appendix
 * B1 of the Advanced Visualizer manual); anything else means the text is
 * not an OBJ file. */
static const char *const obj_statements[] = {
    "v", "vt", "vn", "vp", "f", "fo", "l", "p", "g", "o", "s", "mg", "mtllib", "usemtl",
    "usemap", "maplib", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm",
    "trim", "hole", "scrv", "sp", "end", "con", "bevel", "c_interp", "d_interp", "lod",
    "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh",
};

static bool is_obj_statement(const char *token)
{
    for (size_t i = 0; i < sizeof obj_statements / sizeof obj_statements[0]; i++)
        if (strcmp(token, obj_statements[i]) == 0)
            return true;
    return false;
}

/* A line holding a NUL byte: assimp stops reading there, so the rest of
 * the file would be silently lost. */
static bool has_nul(const char *line, const char *end)
{
    /* A loop, not memchr: GCC 12 at -O3 misjudges memchr's bound here. */
    for (const char *c = line; c < end; c++)
        if (*c == '\0')
            return true;
    return false;
}

/* What the slots of a face vertex "v/vt/vn" index, and their statements. */
static const char *const face_slot_names[3] = {"vertex", "texture coordinate", "normal"};
static const char *const face_slot_statements[3] = {"v", "vt", "vn"};

static int face_slot_of(const char *statement)
{
    for (int k = 0; k < 3; k++)
        if (strcmp(statement, face_slot_statements[k]) == 0)
            return k;
    return -1;
}

/* Check one face vertex, "v", "v/vt", "v//vn" or "v/vt/vn": each index
 * in 1..total, or relative (-1 = the latest seen so far). */
static rad_result check_face_vertex(rad_context *ctx, const char *path, int line,
                                    const char *token, const size_t total[3],
                                    const size_t seen[3])
{
    const char *part = token;
    for (int slot = 0; slot < 3; slot++) {
        const char *slash = strchr(part, '/');
        size_t length = slash ? (size_t)(slash - part) : strlen(part);
        if (length > 0 || slot == 0) {
            char *after;
            errno = 0;
            long index = strtol(part, &after, 10);
            if (length == 0 || !strchr("0123456789+-", part[0]) || after != part + length)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face has a malformed vertex '%s'",
                                path, line, token);
            size_t available = index < 0 ? seen[slot] : total[slot];
            bool in_range = errno == 0 && index != 0 &&
                            (index > 0 ? (unsigned long)index <= available
                                       : (unsigned long)(-(index + 1)) < available);
            if (!in_range)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face references %s %ld of %zu",
                                path, line, face_slot_names[slot], index, available);
        }
        if (!slash)
            return RAD_OK;
        part = slash + 1;
    }
    return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face has a malformed vertex '%s'", path, line,
                    token);
}

/* Check an OBJ where assimp would silently misread it or fail without a
 * line number: text without NUL bytes, known statements, none indented,
 * vertices of 3, 4 or 6 finite numbers (assimp drops other vertices and
 * divides by the 4th), face, line and point indices in range.  Writes
 * the first `mtllib` name (or "") and its line.  Not a parser: assimp
 * reads the file afterwards. */
rad_result import_obj_prescan(rad_context *ctx, const char *path, const char *text, size_t size,
                              char *mtllib, size_t mtllib_size, int *mtllib_line)
{
    char token[TOKEN_SIZE];
    const char *p, *end;
    size_t total[3] = {0, 0, 0}; /* v, vt, vn in the whole file */
    mtllib[0] = '\0';
    *mtllib_line = 0;
    text_lines lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        if (has_nul(p, end))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: NUL byte in the text", path,
                            lines.number);
        bool indented = p < end && is_blank(*p);
        if (next_token(&p, end, token) == 0 || token[0] == '#')
            continue;
        if (indented) /* assimp skips such a line without a word */
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: statement '%s' is indented", path,
                            lines.number, token);
        int slot = face_slot_of(token);
        if (slot >= 0)
            total[slot]++;
        if (slot == 0) {
            size_t length;
            int coordinates = 0;
            double value = 1.0;
            while ((length = next_token(&p, end, token)) > 0) {
                number_kind kind = parse_number(token, length, &value);
                if (token[0] == '.') /* assimp does not count ".5" as a coordinate */
                    kind = NUMBER_GARBAGE;
                if (kind != NUMBER_FINITE)
                    return rad_fail(ctx,
                                    kind == NUMBER_GARBAGE ? RAD_ERROR_PARSE
                                                           : RAD_ERROR_INVALID_SCENE,
                                    "%s:%d: vertex coordinate '%s' is not a finite number", path,
                                    lines.number, token);
                coordinates++;
            }
            if (coordinates != 3 && coordinates != 4 && coordinates != 6)
                return rad_fail(ctx, RAD_ERROR_PARSE,
                                "%s:%d: vertex has %d numbers (3, 4 or 6 expected)", path,
                                lines.number, coordinates);
            if (coordinates == 4 && value == 0.0) /* x y z w: assimp divides by w */
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s:%d: vertex has weight w = 0",
                                path, lines.number);
        } else if (strcmp(token, "mtllib") == 0) {
            if (!mtllib[0]) {
                rest_of_line(p, end, mtllib, mtllib_size);
                *mtllib_line = lines.number;
            }
        } else if (!is_obj_statement(token)) {
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: unknown statement '%s'", path,
                            lines.number, token);
        }
    }

    /* Second pass: faces may name vertices defined later in the file;
     * relative (negative) indices count back from the latest one. */
    size_t seen[3] = {0, 0, 0};
    lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        next_token(&p, end, token);
        int slot = face_slot_of(token);
        if (slot >= 0)
            seen[slot]++;
        /* assimp reads points and lines with the face code: check them too */
        if (strcmp(token, "f") != 0 && strcmp(token, "fo") != 0 && strcmp(token, "l") != 0 &&
            strcmp(token, "p") != 0)
            continue;
        while (next_token(&p, end, token) > 0) {
            rad_result r = check_face_vertex(ctx, path, lines.number, token, total, seen);
            if (r != RAD_OK)
                return r;
        }
    }
    return RAD_OK;
}

/* Check an MTL: nothing before the first newmtl; Kd (reflectance) and Ke
 * (emitted radiance) are 3 finite numbers, Kd in [0, 1) and Ke >= 0. */
rad_result import_mtl_prescan(rad_context *ctx, const char *path, const char *text, size_t size)
{
    char token[TOKEN_SIZE], material[64] = "";
    const char *p, *end;
    bool seen_newmtl = false;
    text_lines lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        if (has_nul(p, end))
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: NUL byte in the text", path,
                            lines.number);
        if (next_token(&p, end, token) == 0 || token[0] == '#')
            continue;
        if (strcmp(token, "newmtl") == 0) {
            rest_of_line(p, end, material, sizeof material);
            seen_newmtl = true;
            continue;
        }
        /* Every statement belongs to a material; assimp 5.2 dereferences a
         * null material for a texture map (map_Kd ...) before the first
         * newmtl (found by fuzz_mtl). */
        if (!seen_newmtl)
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: '%s' before any 'newmtl'", path,
                            lines.number, token);
        bool is_kd = strcasecmp(token, "Kd") == 0, is_ke = strcasecmp(token, "Ke") == 0;
        if (!is_kd && !is_ke)
            continue;
        const char *key = is_kd ? "Kd" : "Ke";
        double values[3];
        int count = 0;
        size_t length;
        while ((length = next_token(&p, end, token)) > 0) {
            if (count == 3 || parse_number(token, length, &values[count]) != NUMBER_FINITE)
                return rad_fail(ctx, RAD_ERROR_PARSE,
                                "%s:%d: material '%s': %s value '%s' is not a finite number",
                                path, lines.number, material, key, token);
            count++;
        }
        if (count != 3) /* assimp reads "Kd 0.5" as (0.5, 0, 0) */
            return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: material '%s': %s needs 3 numbers",
                            path, lines.number, material, key);
        for (int c = 0; c < count; c++) {
            if (is_kd && !(values[c] >= 0.0 && values[c] < 1.0))
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                                "%s:%d: material '%s': reflectance (Kd) %g is outside [0, 1)",
                                path, lines.number, material, values[c]);
            if (is_ke && values[c] < 0.0)
                return rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                                "%s:%d: material '%s': emission (Ke) %g is negative", path,
                                lines.number, material, values[c]);
        }
    }
    return RAD_OK;
}
