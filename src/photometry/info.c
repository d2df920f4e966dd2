/*
 * info.c -- the public summary of a photometric file (radiosity.h,
 * "Photometric files"): photometry.c reads it, this copies what a program
 * or the `radiosity photometry` command shows.
 */
#include "photometry/photometry.h"

#include <stdio.h>
#include <string.h>

static const char *shape_name(rad_luminous_shape shape)
{
    static const char *const names[] = {"point", "rectangle", "box", "ellipse", "vertical cylinder", "ellipsoid",
                                        "cylinder along x", "cylinder along y", "vertical ellipse facing x",
                                        "vertical ellipse facing y"};
    return (size_t)shape < sizeof names / sizeof names[0] ? names[shape] : "?";
}

rad_result rad_photometry_info_read(rad_context *ctx, const char *path, rad_photometry_info *out)
{
    rad_api_enter(ctx);
    if (out)
        memset(out, 0, sizeof *out);
    if (!ctx || !path || !out)
        return rad_null_argument(ctx, __func__);
    rad_photometry *p = NULL;
    rad_result r = rad_photometry_load(ctx, path, &p);
    if (r != RAD_OK)
        return r;
    snprintf(out->format, sizeof out->format, "%s", p->format == RAD_PHOTOMETRY_LDT ? "EULUMDAT" : "IES");
    snprintf(out->version, sizeof out->version, "%s", p->version);
    snprintf(out->label, sizeof out->label, "%s", p->label);
    out->type = (int)p->type;
    snprintf(out->symmetry, sizeof out->symmetry, "%s", p->symmetry);
    out->horizontal_count = p->file_horizontal_count;
    out->vertical_count = p->file_vertical_count;
    out->horizontal_min = p->file_horizontal_min, out->horizontal_max = p->file_horizontal_max;
    out->vertical_min = p->file_vertical_min, out->vertical_max = p->file_vertical_max;
    out->max_candela = rad_photometry_max(p, &out->max_c, &out->max_gamma);
    out->flux = p->flux;
    out->rated_lumens = p->rated_lumens;
    out->lor = rad_photometry_lor(p);
    out->stated_lor = p->stated_lor;
    out->width = p->width, out->length = p->length, out->height = p->height;
    snprintf(out->shape, sizeof out->shape, "%s", shape_name(p->shape));
    snprintf(out->tilt, sizeof out->tilt, "%s", p->tilt_source);
    out->tilt_count = p->tilt_count;
    out->input_watts = p->input_watts;
    rad_photometry_free(p);
    return RAD_OK;
}
