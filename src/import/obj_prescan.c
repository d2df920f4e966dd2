/*
 * obj_prescan.c -- a light pre-scan of OBJ and MTL text, for the errors
 * assimp 5.2 omits or gets wrong: its OBJ parser reads "nan", garbage and
 * out-of-range numbers leniently, drops vertices of unexpected arity and
 * faces of fewer than 3 vertices, skips indented statements, stops at a
 * NUL byte, reads "f 012" or "f +1" as two indices, hides everything
 * between `cstype` and `end`, joins a line ending in '\\' (a comment
 * included) to the next, and reports no line numbers.
 *
 *    text --lines--> tokens --checks--> "scene.obj:12: face references vertex 40 of 32"
 *
 * Not a parser: it checks vertex coordinates, face/line/point indices,
 * Kd/Ke and material names, lists the `mtllib` statements and notes what
 * a material says beyond Kd and Ke (said after the load: unused.c); assimp
 * reads the text afterwards.  The statements are those of Wavefront's
 * "Object Files (.obj)" and "Material Library Files (.mtl)", Appendices B1
 * and B2 of the Advanced Visualizer manual.  Works on buffers (which need
 * not end in NUL), so the fuzzers drive it from memory.
 */
#include "import/import_internal.h"

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

enum { TOKEN_SIZE = 128 };

/* Control characters and bytes that are not UTF-8 become '?', so that a
 * message quoting a token of a binary file cannot drive the terminal it is
 * printed on (a lone 0x9b is a control sequence to some). */
static void make_printable(char *text)
{
    unsigned char *c = (unsigned char *)text;
    while (*c) {
        int length = *c < 0x80                  ? 1
                     : *c >= 0xc2 && *c <= 0xdf ? 2
                     : *c >= 0xe0 && *c <= 0xef ? 3
                     : *c >= 0xf0 && *c <= 0xf4 ? 4
                                                : 0;
        int k = 1;
        while (k < length && c[k] >= 0x80 && c[k] <= 0xbf)
            k++;
        if (length == 0 || k < length || *c < 0x20 || *c == 0x7f) {
            *c = '?';
            k = 1;
        }
        c += k;
    }
}

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

/* Copy the next blank-separated token of [*p, end) into `token` (cut to
 * TOKEN_SIZE - 1 characters, made printable) and return its full length;
 * 0 at the end.  Blanks are spaces and tabs only, as assimp has them: a
 * form feed or vertical tab is part of a token, so "v\v1 2 3" is no vertex
 * here either. */
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
    make_printable(token);
    *p = e;
    return length;
}

/* The rest of the line, blanks trimmed, whole, in a block of the context
 * (rad_free it); NULL when out of memory. */
static char *rest_of_line_copy(rad_context *ctx, const char *p, const char *end, const char *what)
{
    while (p < end && isspace((unsigned char)*p))
        p++;
    while (end > p && isspace((unsigned char)end[-1]))
        end--;
    char *copy = rad_alloc(ctx, RAD_MEM_SCENE, (size_t)(end - p) + 1, 1, what);
    if (copy)
        memcpy(copy, p, (size_t)(end - p));
    return copy;
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
 * B1 of the Advanced Visualizer manual) that assimp reads as what they
 * are; anything else means the text is not an OBJ file, or uses what
 * unsupported_statements lists. */
static const char *const obj_statements[] = {
    "v", "vt", "vn", "vp", "f", "fo", "l", "p", "g", "o", "s", "mg", "mtllib", "usemtl",
    "usemap", "maplib", "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "ctech",
    "stech", "csh",
};

/* Statements the engine cannot honour and assimp 5.2 would get silently
 * wrong: free-form geometry (`cstype` makes assimp skip every line up to
 * `end`, vertices and faces included; `parm` is read as a point, `lod` as
 * a line) and `call`, which would read another file. */
static const struct {
    const char *statement, *why;
} unsupported_statements[] = {
    {"cstype", "free-form geometry is not supported (polygons only)"},
    {"deg", "free-form geometry is not supported (polygons only)"},
    {"bmat", "free-form geometry is not supported (polygons only)"},
    {"step", "free-form geometry is not supported (polygons only)"},
    {"curv", "free-form geometry is not supported (polygons only)"},
    {"curv2", "free-form geometry is not supported (polygons only)"},
    {"surf", "free-form geometry is not supported (polygons only)"},
    {"parm", "free-form geometry is not supported (polygons only)"},
    {"trim", "free-form geometry is not supported (polygons only)"},
    {"hole", "free-form geometry is not supported (polygons only)"},
    {"scrv", "free-form geometry is not supported (polygons only)"},
    {"sp", "free-form geometry is not supported (polygons only)"},
    {"end", "free-form geometry is not supported (polygons only)"},
    {"con", "free-form geometry is not supported (polygons only)"},
    {"lod", "levels of detail are not supported"},
    {"call", "reading another file is not supported"},
};

static bool is_obj_statement(const char *token)
{
    for (size_t i = 0; i < sizeof obj_statements / sizeof obj_statements[0]; i++)
        if (strcmp(token, obj_statements[i]) == 0)
            return true;
    return false;
}

/* Why `token` is refused, or NULL when it is not one of those statements. */
static const char *unsupported_statement(const char *token)
{
    for (size_t i = 0; i < sizeof unsupported_statements / sizeof unsupported_statements[0]; i++)
        if (strcmp(token, unsupported_statements[i].statement) == 0)
            return unsupported_statements[i].why;
    return NULL;
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
 * in 1..total, or relative (-1 = the latest seen so far), written without
 * a '+' or leading zeros (assimp reads "012" as 12 and then 2, "+1" as 1
 * twice).  Writes the vertex's absolute index (0-based). */
static rad_result check_face_vertex(rad_context *ctx, const char *path, int line,
                                    const char *token, const size_t total[3],
                                    const size_t seen[3], size_t *vertex)
{
    const char *part = token;
    for (int slot = 0; slot < 3; slot++) {
        const char *slash = strchr(part, '/');
        size_t length = slash ? (size_t)(slash - part) : strlen(part);
        if (length > 0 || slot == 0) {
            char *after;
            errno = 0;
            long index = strtol(part, &after, 10);
            if (length == 0 || !strchr("0123456789-", part[0]) || after != part + length)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face has a malformed vertex '%s'",
                                path, line, token);
            const char *digits = part[0] == '-' ? part + 1 : part;
            if (digits[0] == '0' && digits + 1 < part + length)
                return rad_fail(ctx, RAD_ERROR_PARSE,
                                "%s:%d: face vertex '%s' has an index with a leading zero", path,
                                line, token);
            size_t available = index < 0 ? seen[slot] : total[slot];
            bool in_range = errno == 0 && index != 0 &&
                            (index > 0 ? (unsigned long)index <= available
                                       : (unsigned long)(-(index + 1)) < available);
            if (!in_range)
                return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face references %s %ld of %zu",
                                path, line, face_slot_names[slot], index, available);
            if (slot == 0)
                *vertex = index > 0 ? (size_t)index - 1 : seen[0] - (size_t)(-index);
        }
        if (!slash)
            return RAD_OK;
        part = slash + 1;
    }
    return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: face has a malformed vertex '%s'", path, line,
                    token);
}

/* Note an `mtllib` statement: the rest of its line, whole (the loader
 * splits it into names). */
static rad_result add_mtllib(rad_context *ctx, const char *path, import_obj_scan *scan,
                             const char *p, const char *end, int line, size_t offset)
{
    if (scan->mtllib_count == scan->mtllib_capacity) {
        size_t grown = scan->mtllib_capacity ? 2 * scan->mtllib_capacity : 4;
        import_obj_mtllib *mtllibs = rad_realloc(ctx, RAD_MEM_SCENE, scan->mtllibs, grown,
                                                 sizeof *mtllibs, path);
        if (!mtllibs)
            return RAD_ERROR_OUT_OF_MEMORY;
        scan->mtllibs = mtllibs;
        scan->mtllib_capacity = grown;
    }
    char *names = rest_of_line_copy(ctx, p, end, path);
    if (!names)
        return RAD_ERROR_OUT_OF_MEMORY;
    if (!names[0]) {
        rad_free(names);
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: 'mtllib' names no material library", path,
                        line);
    }
    scan->mtllibs[scan->mtllib_count++] = (import_obj_mtllib){names, line, offset};
    return RAD_OK;
}

void import_obj_scan_free(import_obj_scan *scan)
{
    for (size_t i = 0; i < scan->mtllib_count; i++)
        rad_free(scan->mtllibs[i].names);
    rad_free(scan->mtllibs);
    memset(scan, 0, sizeof *scan);
}

/* Check an OBJ where assimp would silently misread it or fail without a
 * line number: text without NUL bytes, known statements, none indented,
 * no line continued with '\\', vertices of 3, 4 or 6 finite numbers
 * (assimp drops other vertices and divides by the 4th), face, line and
 * point indices in range, faces of 3 or more distinct vertices.  Lists
 * the `mtllib` statements in `scan`.  Not a parser: assimp reads the file
 * afterwards. */
rad_result import_obj_prescan(rad_context *ctx, const char *path, const char *text, size_t size,
                              import_obj_scan *scan)
{
    char token[TOKEN_SIZE];
    const char *p, *end;
    size_t total[3] = {0, 0, 0}; /* v, vt, vn in the whole file */
    memset(scan, 0, sizeof *scan);
    text_lines lines = text_lines_of(text, size);
    rad_result r = RAD_OK;
    bool seen_statement = false;
    while (r == RAD_OK && next_line(&lines, &p, &end)) {
        const char *line = p;
        if (has_nul(p, end))
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: NUL byte in the text", path, lines.number);
        else if (end > p && end[-1] == '\\') /* assimp joins the next line to it, comments too */
            r = rad_fail(ctx, RAD_ERROR_PARSE,
                         "%s:%d: line ends in '\\' (a continuation line): not supported, join "
                         "the lines", path, lines.number);
        if (r != RAD_OK)
            break;
        bool indented = p < end && is_blank(*p);
        if (next_token(&p, end, token) == 0 || token[0] == '#')
            continue;
        bool first_statement = !seen_statement;
        seen_statement = true;
        if (indented) { /* assimp skips such a line without a word */
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: statement '%s' is indented", path,
                         lines.number, token);
            break;
        }
        int slot = face_slot_of(token);
        if (slot >= 0)
            total[slot]++;
        const char *unsupported = unsupported_statement(token);
        if (slot == 0) {
            size_t length;
            int coordinates = 0;
            double value = 1.0;
            while (r == RAD_OK && (length = next_token(&p, end, token)) > 0) {
                number_kind kind = parse_number(token, length, &value);
                if (token[0] == '.') /* assimp does not count ".5" as a coordinate */
                    kind = NUMBER_GARBAGE;
                if (kind != NUMBER_FINITE)
                    r = rad_fail(ctx,
                                 kind == NUMBER_GARBAGE ? RAD_ERROR_PARSE : RAD_ERROR_INVALID_SCENE,
                                 "%s:%d: vertex coordinate '%s' is not a finite number", path,
                                 lines.number, token);
                else if (coordinates < 3 && fabs(value) > RAD_MAX_COORDINATE)
                    r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                                 "%s:%d: vertex coordinate '%s' is beyond the %g m the engine "
                                 "works in (are the units right?)",
                                 path, lines.number, token, RAD_MAX_COORDINATE);
                coordinates++;
            }
            if (r != RAD_OK)
                break;
            if (coordinates != 3 && coordinates != 4 && coordinates != 6)
                r = rad_fail(ctx, RAD_ERROR_PARSE,
                             "%s:%d: vertex has %d numbers (3, 4 or 6 expected)", path,
                             lines.number, coordinates);
            else if (coordinates == 4 && value == 0.0) /* x y z w: assimp divides by w */
                r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s:%d: vertex has weight w = 0",
                             path, lines.number);
        } else if (strcmp(token, "mtllib") == 0) {
            r = add_mtllib(ctx, path, scan, p, end, lines.number, (size_t)(line - text));
        } else if (unsupported) {
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: '%s': %s", path, lines.number, token,
                         unsupported);
        } else if (!is_obj_statement(token)) {
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: unknown statement '%s'%s", path,
                         lines.number, token,
                         first_statement ? " (read as OBJ: by its content the file is not "
                                           "glTF JSON or binary glTF)"
                                         : "");
        }
    }

    /* Second pass: faces may name vertices defined later in the file;
     * relative (negative) indices count back from the latest one. */
    size_t seen[3] = {0, 0, 0}, faces = 0;
    lines = text_lines_of(text, size);
    while (r == RAD_OK && next_line(&lines, &p, &end)) {
        next_token(&p, end, token);
        int slot = face_slot_of(token);
        if (slot >= 0)
            seen[slot]++;
        /* assimp reads points and lines with the face code: check them
         * too; they have no area, and the loader ignores them */
        bool face = strcmp(token, "f") == 0 || strcmp(token, "fo") == 0;
        if (!face && strcmp(token, "l") != 0 && strcmp(token, "p") != 0)
            continue;
        faces += face;
        size_t count = 0, distinct[3], vertex = 0;
        int kinds = 0; /* distinct vertices up to 3 */
        while (r == RAD_OK && next_token(&p, end, token) > 0) {
            r = check_face_vertex(ctx, path, lines.number, token, total, seen, &vertex);
            count++;
            bool repeat = false;
            for (int k = 0; k < kinds; k++)
                repeat = repeat || distinct[k] == vertex;
            if (!repeat && kinds < 3)
                distinct[kinds++] = vertex;
        }
        if (r == RAD_OK && face && count < 3)
            r = rad_fail(ctx, RAD_ERROR_PARSE,
                         "%s:%d: face needs 3 or more vertices, has %zu ('l' is for lines)",
                         path, lines.number, count);
        else if (r == RAD_OK && face && kinds < 3)
            r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                         "%s:%d: face needs 3 or more distinct vertices, has %d", path,
                         lines.number, kinds);
    }
    /* Said here, as for any scene without polygons: assimp 5.2 would say
     * "OBJ-file is too small" below 16 bytes. */
    if (r == RAD_OK && faces == 0)
        r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s: scene is empty (no polygons)", path);
    if (r != RAD_OK)
        import_obj_scan_free(scan);
    return r;
}

/* Note library `path` (when it is not the latest already). */
static rad_result add_library(rad_context *ctx, import_material_names *names, const char *path)
{
    if (names->library_count == 0 ||
        strcmp(names->libraries[names->library_count - 1], path) != 0) {
        if (names->library_count == names->library_capacity) {
            size_t grown = names->library_capacity ? 2 * names->library_capacity : 4;
            char **libraries = rad_realloc(ctx, RAD_MEM_SCENE, names->libraries, grown,
                                           sizeof *libraries, path);
            if (!libraries)
                return RAD_ERROR_OUT_OF_MEMORY;
            names->libraries = libraries;
            names->library_capacity = grown;
        }
        char *copy = rad_strdup(ctx, RAD_MEM_SCENE, path, path);
        if (!copy)
            return RAD_ERROR_OUT_OF_MEMORY;
        names->libraries[names->library_count++] = copy;
    }
    return RAD_OK;
}

/* Note that `line` of the latest library defines material `name`. */
static rad_result add_material_name(rad_context *ctx, import_material_names *names,
                                    const char *path, int line, char *name)
{
    if (names->count == names->capacity) {
        size_t grown = names->capacity ? 2 * names->capacity : 16;
        import_material_name *entries = rad_realloc(ctx, RAD_MEM_SCENE, names->entries, grown,
                                                    sizeof *entries, path);
        if (!entries)
            return RAD_ERROR_OUT_OF_MEMORY;
        names->entries = entries;
        names->capacity = grown;
    }
    names->entries[names->count] = (import_material_name){
        .name = name, .library = names->library_count - 1, .line = line, .order = names->count,
        .ks = {NAN, NAN, NAN}, .ns = NAN, .ni = NAN, .d = NAN, .tr = NAN, .illum = NAN, .ks_line = line,
        .ni_line = line};
    names->count++;
    names->sorted = false;
    return RAD_OK;
}

/* ---- what an MTL material says beyond Kd and Ke ---- */

/* The statements of Wavefront's MTL (and the PBR extension exporters
 * write: Pr, Pm, Ps, Pc, Pcr, aniso, anisor) that describe what a diffuse
 * engine does not draw.  Ka is not among them: ambient light is what
 * radiosity computes. */
enum {
    MTL_KS, MTL_NS, MTL_NI, MTL_D, MTL_TR, MTL_TF, MTL_ILLUM, MTL_PR, MTL_PM, MTL_PS, MTL_PC,
    MTL_PCR, MTL_ANISO, MTL_ANISOR, MTL_PROPERTIES
};
static const char *const mtl_property_names[MTL_PROPERTIES] = {
    "Ks", "Ns", "Ni", "d", "Tr", "Tf", "illum", "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor",
};

enum { MTL_MAPS = 8, MTL_ITEM = TOKEN_SIZE + 40 };

/* What one material says beyond Kd and Ke, judged at its end (whether Ns
 * shows depends on Ks, wherever each is). */
typedef struct mtl_extras {
    bool seen[MTL_PROPERTIES];
    bool numeric[MTL_PROPERTIES]; /* its values all numbers (not "spectral", "-halo") */
    double low[MTL_PROPERTIES], high[MTL_PROPERTIES];
    char illum[16];               /* illum's value as written */
    bool has_kd, has_ke, map_kd, map_ke;
    double kd[3], ke[3];
    char map_statements[MTL_MAPS][32];
    char maps[MTL_MAPS][MTL_ITEM]; /* "map_Kd 'wood.png'", in the file's order, each once */
    size_t map_count, maps_more;
} mtl_extras;

static int mtl_property_of(const char *statement)
{
    for (int k = 0; k < MTL_PROPERTIES; k++)
        if (strcasecmp(statement, mtl_property_names[k]) == 0)
            return k;
    return -1;
}

/* Keep the values of the specular statements the engine reads (Ks, Ns,
 * Ni, d, Tr, illum) on the material's entry, the rest of the line [p,
 * end); a statement whose values are not all numbers is kept as absent
 * (NAN), as is a Ks of other than one or three numbers. */
static void note_specular(import_material_name *entry, int k, int line, const char *p, const char *end)
{
    char token[TOKEN_SIZE];
    size_t length;
    double values[3];
    int count = 0;
    while ((length = next_token(&p, end, token)) > 0) {
        double value;
        if (parse_number(token, length, &value) != NUMBER_FINITE || count == 3) {
            count = -1;
            break;
        }
        values[count++] = value;
    }
    double first = count > 0 ? values[0] : NAN;
    switch (k) {
    case MTL_KS:
        for (int c = 0; c < 3; c++)
            entry->ks[c] = count == 3 ? values[c] : count == 1 ? first : NAN;
        entry->ks_line = line;
        break;
    case MTL_NS: entry->ns = count == 1 ? first : NAN; break;
    case MTL_NI:
        entry->ni = count == 1 ? first : NAN;
        entry->ni_line = line;
        break;
    case MTL_D: entry->d = count == 1 ? first : NAN; break;
    case MTL_TR: entry->tr = count == 1 ? first : NAN; break;
    case MTL_ILLUM: entry->illum = count == 1 ? first : NAN; break;
    default: break;
    }
}

/* Texture statements: every map_*, and bump, disp, decal, refl, norm. */
static bool is_mtl_map(const char *statement)
{
    static const char *const others[] = {"bump", "disp", "decal", "refl", "norm"};
    if (strncasecmp(statement, "map_", 4) == 0)
        return true;
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++)
        if (strcasecmp(statement, others[i]) == 0)
            return true;
    return false;
}

/* Note property `k`'s values, the rest of its line [p, end); a statement
 * without values says nothing (assimp reads zeros). */
static void note_property(mtl_extras *x, int k, const char *p, const char *end)
{
    char token[TOKEN_SIZE];
    size_t length;
    int count = 0;
    bool numeric = true;
    double value, low = 0.0, high = 0.0;
    while ((length = next_token(&p, end, token)) > 0) {
        if (parse_number(token, length, &value) != NUMBER_FINITE) {
            numeric = false;
        } else {
            low = count == 0 || value < low ? value : low;
            high = count == 0 || value > high ? value : high;
        }
        if (k == MTL_ILLUM && count == 0)
            snprintf(x->illum, sizeof x->illum, "%.15s", token);
        count++;
    }
    if (count == 0)
        return;
    x->seen[k] = true;
    x->numeric[k] = numeric;
    x->low[k] = low;
    x->high[k] = high;
}

/* Note texture statement `statement`, its file the last word of its line
 * (options such as "-bm 0.5" come first). */
static void note_map(mtl_extras *x, const char *statement, const char *p, const char *end)
{
    char token[TOKEN_SIZE], file[TOKEN_SIZE] = "";
    while (next_token(&p, end, token) > 0)
        memcpy(file, token, sizeof file);
    if (strcasecmp(statement, "map_Kd") == 0)
        x->map_kd = true;
    if (strcasecmp(statement, "map_Ke") == 0)
        x->map_ke = true;
    for (size_t i = 0; i < x->map_count; i++)
        if (strcasecmp(x->map_statements[i], statement) == 0)
            return;
    if (x->map_count == MTL_MAPS) {
        x->maps_more++;
        return;
    }
    snprintf(x->map_statements[x->map_count], sizeof x->map_statements[0], "%.31s", statement);
    if (file[0])
        snprintf(x->maps[x->map_count], MTL_ITEM, "%.31s '%s'", statement, file);
    else
        snprintf(x->maps[x->map_count], MTL_ITEM, "%.31s", statement);
    x->map_count++;
}

/* Whether property `k` was given with a value above 0 (or words). */
static bool above_zero(const mtl_extras *x, int k)
{
    return x->seen[k] && (!x->numeric[k] || x->high[k] > 0.0);
}

/* Note, in `notes`, what material `material` (its full `name`, for
 * matching assimp's; `label` printable) of library `path` says that would
 * change its look.  Not said: Ks 0 0 0; Ns without a highlight; d 1 and
 * Tr 0 (opaque); Ni and Tf on an opaque material without refraction
 * (illum 6 or 7), and Tf 1 1 1; illum 0 and 1 (diffuse), and 2
 * (highlights) without Ks; Pr without a highlight or metal; Pcr without
 * Pc, anisor without aniso. */
static rad_result note_mtl_material(rad_context *ctx, const char *path, const char *name,
                                    const char *label, const mtl_extras *x, import_notes *notes)
{
    bool specular = above_zero(x, MTL_KS);
    bool transparent = (x->seen[MTL_D] && (!x->numeric[MTL_D] || x->low[MTL_D] < 1.0)) ||
                       above_zero(x, MTL_TR);
    int illum = -1;
    if (x->seen[MTL_ILLUM] && x->numeric[MTL_ILLUM] && x->low[MTL_ILLUM] == x->high[MTL_ILLUM] &&
        x->high[MTL_ILLUM] >= 0.0 && x->high[MTL_ILLUM] <= 10.0 &&
        x->high[MTL_ILLUM] == floor(x->high[MTL_ILLUM]))
        illum = (int)x->high[MTL_ILLUM];
    bool refractive = illum == 6 || illum == 7;
    /* What the engine reads (import_assimp.c mtl_specular): a reflector's
     * Ks, Ns and illum; glass's illum, Ni, d and Tr. */
    bool reflector = (illum == 3 || illum == 5) && specular, glass = illum == 4 || refractive;
    bool listed[MTL_PROPERTIES] = {false};
    listed[MTL_KS] = specular;
    listed[MTL_NS] = x->seen[MTL_NS] && specular;
    listed[MTL_NI] = x->seen[MTL_NI] && (transparent || refractive);
    listed[MTL_D] = x->seen[MTL_D] && (!x->numeric[MTL_D] || x->low[MTL_D] < 1.0);
    listed[MTL_TR] = above_zero(x, MTL_TR);
    listed[MTL_TF] = x->seen[MTL_TF] && (transparent || refractive) &&
                     (!x->numeric[MTL_TF] || x->low[MTL_TF] < 1.0);
    listed[MTL_ILLUM] =
        x->seen[MTL_ILLUM] && !(illum == 0 || illum == 1 || (illum == 2 && !specular));
    listed[MTL_PM] = above_zero(x, MTL_PM);
    listed[MTL_PR] = x->seen[MTL_PR] && (listed[MTL_PM] || specular);
    listed[MTL_PS] = above_zero(x, MTL_PS);
    listed[MTL_PC] = above_zero(x, MTL_PC);
    listed[MTL_PCR] = x->seen[MTL_PCR] && listed[MTL_PC];
    listed[MTL_ANISO] = above_zero(x, MTL_ANISO);
    listed[MTL_ANISOR] = x->seen[MTL_ANISOR] && listed[MTL_ANISO];
    if (reflector)
        listed[MTL_KS] = listed[MTL_NS] = listed[MTL_ILLUM] = false;
    if (glass)
        listed[MTL_ILLUM] = listed[MTL_NI] = listed[MTL_D] = listed[MTL_TR] = false;

    const char *items[MTL_PROPERTIES + MTL_MAPS + 1];
    size_t count = 0;
    char illum_item[32], more[32];
    for (int k = 0; k < MTL_PROPERTIES; k++) {
        if (!listed[k])
            continue;
        if (k == MTL_ILLUM) {
            snprintf(illum_item, sizeof illum_item, "illum %s", x->illum);
            items[count++] = illum_item;
        } else {
            items[count++] = mtl_property_names[k];
        }
    }
    for (size_t i = 0; i < x->map_count; i++)
        items[count++] = x->maps[i];
    if (x->maps_more > 0) {
        snprintf(more, sizeof more, "%zu more", x->maps_more);
        items[count++] = more;
    }
    if (count == 0)
        return RAD_OK;

    char what[1024];
    import_join_items(what, sizeof what, items, count);
    size_t used = strlen(what);
    used += (size_t)snprintf(what + used, sizeof what - used, " %s not used",
                             count == 1 ? "is" : "are");
    char colour[96];
    if (x->map_kd && used < sizeof what) {
        if (x->has_kd)
            snprintf(colour, sizeof colour, "Kd (%g %g %g)", x->kd[0], x->kd[1], x->kd[2]);
        else
            snprintf(colour, sizeof colour, "0.6 0.6 0.6 (no Kd)"); /* assimp's default */
        used += (size_t)snprintf(what + used, sizeof what - used, ": its reflectance is %s",
                                 colour);
    }
    if (x->map_ke && used < sizeof what) {
        if (x->has_ke)
            snprintf(colour, sizeof colour, "Ke (%g %g %g)", x->ke[0], x->ke[1], x->ke[2]);
        else
            snprintf(colour, sizeof colour, "0 (no Ke)");
        used += (size_t)snprintf(what + used, sizeof what - used, "%s its emission is %s",
                                 x->map_kd ? "," : ":", colour);
    }
    if (!x->map_kd && !x->map_ke && used < sizeof what)
        snprintf(what + used, sizeof what - used, " (the engine reads Kd and Ke, and the specular keys with illum 3 to 7)");
    char subject[512];
    snprintf(subject, sizeof subject, "%s: material '%s'", path, label);
    return import_notes_add(ctx, notes, subject, name, SIZE_MAX, what);
}

/* Check an MTL: nothing before the first newmtl, which names its
 * material; Kd (reflectance) and Ke (emitted radiance) are 3 finite
 * numbers, Kd in [0, 1) and Ke >= 0.  Every material is noted in `names`
 * (import_material_names_check then finds names defined twice), and what
 * it says beyond Kd and Ke in `notes` (note_mtl_material). */
rad_result import_mtl_prescan(rad_context *ctx, const char *path, const char *text, size_t size,
                              import_material_names *names, import_notes *notes)
{
    char token[TOKEN_SIZE], material[64] = "";
    const char *p, *end, *name = NULL; /* the current material's full name */
    bool seen_newmtl = false;
    rad_result added = add_library(ctx, names, path);
    if (added != RAD_OK)
        return added;
    mtl_extras *extras = notes ? rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *extras, path) : NULL;
    if (notes && !extras)
        return RAD_ERROR_OUT_OF_MEMORY;
    rad_result r = RAD_OK;
    text_lines lines = text_lines_of(text, size);
    while (r == RAD_OK && next_line(&lines, &p, &end)) {
        if (has_nul(p, end)) {
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: NUL byte in the text", path,
                         lines.number);
            break;
        }
        if (next_token(&p, end, token) == 0 || token[0] == '#')
            continue;
        if (strcmp(token, "newmtl") == 0) {
            /* The name is the rest of the line, as assimp reads it and
             * `usemtl` names it: it may hold blanks. */
            char *copy = rest_of_line_copy(ctx, p, end, path);
            if (!copy) {
                r = RAD_ERROR_OUT_OF_MEMORY;
                break;
            }
            if (!copy[0]) {
                rad_free(copy);
                r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: 'newmtl' names no material", path,
                             lines.number);
                break;
            }
            if (extras && seen_newmtl) /* the material before is complete */
                r = note_mtl_material(ctx, path, name, material, extras, notes);
            if (r != RAD_OK) {
                rad_free(copy);
                break;
            }
            snprintf(material, sizeof material, "%s", copy);
            make_printable(material);
            r = add_material_name(ctx, names, path, lines.number, copy);
            if (r != RAD_OK) {
                rad_free(copy);
                break;
            }
            name = copy; /* the names own it now */
            if (extras)
                memset(extras, 0, sizeof *extras);
            seen_newmtl = true;
            continue;
        }
        /* Every statement belongs to a material; assimp 5.2 dereferences a
         * null material for a texture map (map_Kd ...) before the first
         * newmtl (found by fuzz_mtl). */
        if (!seen_newmtl) {
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: '%s' before any 'newmtl'", path,
                         lines.number, token);
            break;
        }
        bool is_kd = strcasecmp(token, "Kd") == 0, is_ke = strcasecmp(token, "Ke") == 0;
        if (strcasecmp(token, "map_Kd") == 0) { /* its line for the importer's messages */
            names->entries[names->count - 1].map_kd_line = lines.number;
            if (names->textures_read)
                continue; /* read (import/texture.c), so not noted as unused */
        }
        if (!is_kd && !is_ke) {
            int property = mtl_property_of(token);
            if (property >= 0)
                note_specular(&names->entries[names->count - 1], property, lines.number, p, end);
            if (extras && property >= 0)
                note_property(extras, property, p, end);
            else if (extras && is_mtl_map(token))
                note_map(extras, token, p, end);
            continue;
        }
        const char *key = is_kd ? "Kd" : "Ke";
        double values[3];
        int count = 0;
        size_t length;
        while (r == RAD_OK && (length = next_token(&p, end, token)) > 0) {
            if (count == 3 || parse_number(token, length, &values[count]) != NUMBER_FINITE)
                r = rad_fail(ctx, RAD_ERROR_PARSE,
                             "%s:%d: material '%s': %s value '%s' is not a finite number",
                             path, lines.number, material, key, token);
            count++;
        }
        if (r != RAD_OK)
            break;
        if (count != 3) { /* assimp reads "Kd 0.5" as (0.5, 0, 0) */
            r = rad_fail(ctx, RAD_ERROR_PARSE, "%s:%d: material '%s': %s needs 3 numbers",
                         path, lines.number, material, key);
            break;
        }
        for (int c = 0; c < count && r == RAD_OK; c++) {
            if (is_kd && !(values[c] >= 0.0 && values[c] < 1.0))
                r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                             "%s:%d: material '%s': reflectance (Kd) %g is outside [0, 1)",
                             path, lines.number, material, values[c]);
            if (is_ke && values[c] < 0.0)
                r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE,
                             "%s:%d: material '%s': emission (Ke) %g is negative", path,
                             lines.number, material, values[c]);
        }
        if (extras) {
            memcpy(is_kd ? extras->kd : extras->ke, values, sizeof values);
            *(is_kd ? &extras->has_kd : &extras->has_ke) = true;
        }
        import_material_name *entry = &names->entries[names->count - 1]; /* this material */
        memcpy(is_kd ? entry->kd : entry->ke, values, sizeof values);
        *(is_kd ? &entry->has_kd : &entry->has_ke) = true;
    }
    if (r == RAD_OK && extras && seen_newmtl)
        r = note_mtl_material(ctx, path, name, material, extras, notes);
    rad_free(extras);
    return r;
}

static int compare_material_names(const void *a, const void *b)
{
    const import_material_name *x = a, *y = b;
    int order = strcmp(x->name, y->name);
    return order ? order : (x->order > y->order) - (x->order < y->order);
}

rad_result import_material_names_check(rad_context *ctx, import_material_names *names)
{
    if (!names->sorted && names->count > 1)
        qsort(names->entries, names->count, sizeof *names->entries, compare_material_names);
    names->sorted = true;
    for (size_t i = 1; i < names->count; i++) {
        const import_material_name *first = &names->entries[i - 1], *again = &names->entries[i];
        if (strcmp(first->name, again->name) == 0) {
            char name[64];
            snprintf(name, sizeof name, "%s", again->name);
            make_printable(name);
            return rad_fail(ctx, RAD_ERROR_PARSE,
                            "%s:%d: material '%s' is defined again (first at %s:%d)",
                            names->libraries[again->library], again->line, name,
                            names->libraries[first->library], first->line);
        }
    }
    return RAD_OK;
}

static int compare_name_to_entry(const void *key, const void *entry)
{
    return strcmp((const char *)key, ((const import_material_name *)entry)->name);
}

rad_result import_obj_check_usemtl(rad_context *ctx, const char *path, const char *text,
                                   size_t size, const import_material_names *names)
{
    char token[TOKEN_SIZE];
    const char *p, *end;
    text_lines lines = text_lines_of(text, size);
    while (next_line(&lines, &p, &end)) {
        next_token(&p, end, token);
        if (strcmp(token, "usemtl") != 0)
            continue;
        char *name = rest_of_line_copy(ctx, p, end, path);
        if (!name)
            return RAD_ERROR_OUT_OF_MEMORY;
        bool known = !name[0] || /* assimp ignores a usemtl without a name */
                     (names->count > 0 &&
                      bsearch(name, names->entries, names->count, sizeof *names->entries,
                              compare_name_to_entry) != NULL);
        if (!known) {
            char quoted[64];
            snprintf(quoted, sizeof quoted, "%s", name);
            make_printable(quoted);
            rad_free(name);
            size_t more = names->library_count > 0 ? names->library_count - 1 : 0;
            char others[48] = "";
            if (more > 0)
                snprintf(others, sizeof others, " and %zu more", more);
            return rad_fail(ctx, RAD_ERROR_PARSE,
                            "%s:%d: usemtl '%s': no material of that name in %s%s", path,
                            lines.number, quoted,
                            names->library_count ? names->libraries[0] : "its material library",
                            others);
        }
        rad_free(name);
    }
    return RAD_OK;
}

const import_material_name *import_material_find(const import_material_names *names,
                                                 const char *name)
{
    if (!names || names->count == 0)
        return NULL;
    if (names->sorted)
        return bsearch(name, names->entries, names->count, sizeof *names->entries,
                       compare_name_to_entry);
    for (size_t i = 0; i < names->count; i++)
        if (strcmp(names->entries[i].name, name) == 0)
            return &names->entries[i];
    return NULL;
}

void import_material_names_free(import_material_names *names)
{
    for (size_t i = 0; i < names->count; i++)
        rad_free(names->entries[i].name);
    for (size_t i = 0; i < names->library_count; i++)
        rad_free(names->libraries[i]);
    rad_free(names->entries);
    rad_free(names->libraries);
    memset(names, 0, sizeof *names);
}

/* ---- the exact positions (assimp reads them as float) ---- */

/* Read a `v` statement's numbers, the rest of its line [p, end), which
 * the pre-scan has checked: 3, 4 or 6 finite numbers. */
static void read_position(const char *p, const char *end, double xyz[3])
{
    char token[TOKEN_SIZE];
    double value[6] = {0, 0, 0, 1, 0, 0};
    int count = 0;
    while (count < 6 && next_token(&p, end, token) > 0)
        value[count++] = strtod(token, NULL);
    double w = count == 4 ? value[3] : 1.0; /* x y z w: homogeneous, as assimp reads it */
    for (int k = 0; k < 3; k++)
        xyz[k] = w == 1.0 ? value[k] : value[k] / w;
}

/* A camera comment (RAD_OBJ_CAMERA_COMMENT and ten numbers) on the line
 * [line, end): kept when every number reads and the camera is usable (a
 * finite position apart from its look-at point, a field of view in (0,
 * 180) degrees); anything else stays a comment. */
static void read_camera_comment(const char *line, const char *end, import_obj_positions *out)
{
    size_t prefix = strlen(RAD_OBJ_CAMERA_COMMENT);
    if ((size_t)(end - line) <= prefix || memcmp(line, RAD_OBJ_CAMERA_COMMENT, prefix) != 0)
        return;
    char buffer[512];
    size_t n = (size_t)(end - line) - prefix;
    if (n >= sizeof buffer)
        return;
    memcpy(buffer, line + prefix, n);
    buffer[n] = '\0';
    double v[10];
    char *at = buffer;
    for (int k = 0; k < 10; k++) {
        char *next;
        v[k] = strtod(at, &next);
        if (next == at || !isfinite(v[k]))
            return;
        at = next;
    }
    while (*at == ' ' || *at == '\t' || *at == '\r')
        at++;
    vec3 position = v3(v[0], v[1], v[2]), look = v3(v[3], v[4], v[5]), up = v3(v[6], v[7], v[8]);
    if (*at != '\0' || !(v3_length(v3_sub(look, position)) > 0.0) || !(v3_length(up) > 0.0) ||
        !(v[9] > 0.0 && v[9] < 180.0))
        return;
    rad_camera c = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}, v[9]};
    out->camera = c;
    out->has_camera = true;
}

rad_result import_obj_exact_positions(rad_context *ctx, const char *path, const char *text,
                                      size_t size, import_obj_positions *out)
{
    memset(out, 0, sizeof *out);
    char token[TOKEN_SIZE];
    const char *p, *end;
    /* First pass: how many positions, and the rewritten text's size.  A
     * `mtllib` after the first `usemtl` is moved to the top: assimp makes a
     * material of every name it does not know yet and then numbers the
     * library's own ones after them, so a face could get another
     * material's values. */
    size_t count = 0, bytes = 0;
    bool used = false;
    const char *lib = NULL, *lib_end = NULL;
    text_lines lines = text_lines_of(text, size);
    const char *start = lines.next;
    while (next_line(&lines, &p, &end)) {
        next_token(&p, end, token);
        if (strcmp(token, "usemtl") == 0)
            used = true;
        else if (strcmp(token, "mtllib") == 0 && !lib && used) {
            lib = start;
            lib_end = lines.next;
            bytes += (size_t)(lib_end - lib) + 1;
        }
        if (strcmp(token, "mtllib") == 0)
            used = true; /* only the first library statement counts */
        if (strcmp(token, "v") == 0) {
            bytes += (size_t)snprintf(NULL, 0, "v %zu %zu 0\n", count & ((1u << IMPORT_OBJ_INDEX_BITS) - 1),
                                      count >> IMPORT_OBJ_INDEX_BITS);
            count++;
        } else {
            bytes += (size_t)(lines.next - start);
        }
        start = lines.next;
    }
    out->xyz = rad_alloc(ctx, RAD_MEM_SCENE, count ? 3 * count : 1, sizeof *out->xyz, path);
    out->text = out->xyz ? rad_alloc(ctx, RAD_MEM_SCENE, bytes + 1, 1, path) : NULL;
    if (!out->text) {
        import_obj_positions_free(out);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    /* Second pass: read them, write the text. */
    lines = text_lines_of(text, size);
    start = lines.next;
    char *at = out->text;
    if (lib) {
        memcpy(at, lib, (size_t)(lib_end - lib));
        at += lib_end - lib;
        if (at[-1] != '\n')
            *at++ = '\n';
    }
    while (next_line(&lines, &p, &end)) {
        const char *line = p;
        if (start == lib) { /* moved to the top: a comment here */
            memcpy(at, start, (size_t)(lines.next - start));
            at[p - start] = '#';
            at += lines.next - start;
            start = lines.next;
            continue;
        }
        next_token(&p, end, token);
        if (token[0] == '#' && !out->has_camera)
            read_camera_comment(line, end, out);
        if (strcmp(token, "v") == 0) {
            size_t k = out->count++;
            read_position(p, end, &out->xyz[3 * k]);
            at += snprintf(at, bytes + 1 - (size_t)(at - out->text), "v %zu %zu 0\n",
                           k & ((1u << IMPORT_OBJ_INDEX_BITS) - 1), k >> IMPORT_OBJ_INDEX_BITS);
        } else {
            memcpy(at, start, (size_t)(lines.next - start));
            at += lines.next - start;
        }
        start = lines.next;
    }
    out->size = (size_t)(at - out->text);
    return RAD_OK;
}

void import_obj_positions_free(import_obj_positions *positions)
{
    rad_free(positions->xyz);
    rad_free(positions->text);
    memset(positions, 0, sizeof *positions);
}
