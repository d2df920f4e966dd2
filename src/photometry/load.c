/*
 * load.c -- a photometric file read and told apart by content (IES LM-63 by
 * its first line or its TILT line, EULUMDAT otherwise), then parsed by its
 * reader (ies.c, eulumdat.c) into the intensity table (photometry.c).
 */
#include "photometry/photometry_internal.h"

#include <string.h>

/* Photometric files are small (a dense 1-degree web is 65,000 numbers,
 * under 1 MiB); 64 MiB bounds a file before its counts are read. */
#define PH_MAX_FILE_BYTES (64u << 20)

/* IES by content: its first line names LM-63 ("IESNA", "IES:"), or a line
 * starts with "TILT=" (LM-63-1986 has no first line).  EULUMDAT otherwise:
 * its layout is fixed, with no keyword to recognise. */
static bool looks_like_ies(const char *data, size_t size)
{
    size_t i = 0;
    while (i < size && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n'))
        i++;
    if (size - i >= 5 && (strncmp(data + i, "IESNA", 5) == 0 || strncmp(data + i, "IES:", 4) == 0))
        return true;
    for (size_t at = 0; at < size;) {
        while (at < size && (data[at] == ' ' || data[at] == '\t'))
            at++;
        if (size - at >= 5 && strncmp(data + at, "TILT=", 5) == 0)
            return true;
        const char *nl = memchr(data + at, '\n', size - at);
        if (!nl)
            break;
        at = (size_t)(nl - data) + 1;
    }
    return false;
}

rad_result rad_photometry_parse(rad_context *ctx, const char *name, const char *folder,
                                const char *data, size_t size, rad_photometry **out)
{
    if (!out)
        return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!name)
        name = "(memory)";
    if (!data && size)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT, "%s: no data", name);
    if (size == 0)
        return rad_fail(ctx, RAD_ERROR_PARSE, "%s:1: empty file", name);
    if (looks_like_ies(data, size))
        return ph_parse_ies(ctx, name, folder, data, size, out);
    return ph_parse_ldt(ctx, name, data, size, out);
}

rad_result rad_photometry_load(rad_context *ctx, const char *path, rad_photometry **out)
{
    if (!out || !path)
        return RAD_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    unsigned char *bytes;
    size_t size;
    rad_result r = rad_read_file(ctx, path, NULL, PH_MAX_FILE_BYTES, "photometric file", &bytes, &size);
    if (r != RAD_OK)
        return r;
    const char *data = (const char *)bytes;
    const char *slash = strrchr(path, '/');
    char *folder = slash ? rad_strdup(ctx, RAD_MEM_SCENE, path, "photometry: folder")
                         : rad_strdup(ctx, RAD_MEM_SCENE, ".", "photometry: folder");
    if (!folder) {
        rad_free(bytes);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    if (slash)
        folder[slash == path ? 1 : slash - path] = '\0';
    r = rad_photometry_parse(ctx, path, folder, data, size, out);
    rad_free(folder);
    rad_free(bytes);
    return r;
}
