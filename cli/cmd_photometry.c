/*
 * cmd_photometry.c -- `radiosity photometry FILE...`: each luminaire
 * photometric file's summary (IES LM-63, EULUMDAT; radiosity.h,
 * "Photometric files"): format, type, symmetry, angles, the maximum and
 * its direction, flux, rated lumens and light output ratio, opening, tilt.
 * A file that cannot be read is named on stderr and the rest are still
 * read; the status is 1 if any failed.
 */
#include "cli.h"

#include <stdio.h>
#include <string.h>

int cmd_photometry(cli_job *job)
{
    const cli_settings *s = &job->s;
    int status = 0;
    for (size_t k = 0; k < s->photometry_file_count; k++) {
        const char *path = s->photometry_files[k];
        rad_photometry_info in;
        rad_result r = rad_photometry_info_read(job->ctx, path, &in);
        if (r != RAD_OK) {
            status = cli_fail(job->ctx, r);
            continue;
        }
        static const char *const types[] = {"?", "C", "B", "A"};
        printf("%s: %s%s%s, type %s%s%s%s\n", path, in.format, strcmp(in.format, in.version) ? " " : "",
               strcmp(in.format, in.version) ? in.version : "", types[in.type >= 1 && in.type <= 3 ? in.type : 0],
               in.label[0] ? ", \"" : "", in.label, in.label[0] ? "\"" : "");
        printf("  symmetry      %s\n", in.symmetry);
        printf("  angles        %zu %s from %g to %g, %zu %s from %g to %g (degrees)\n", in.vertical_count,
               in.format[0] == 'E' ? "gamma" : "vertical", in.vertical_min, in.vertical_max, in.horizontal_count,
               in.format[0] == 'E' ? "C" : "horizontal", in.horizontal_min, in.horizontal_max);
        printf("  maximum       %.6g cd at C %g, gamma %g\n", in.max_candela, in.max_c, in.max_gamma);
        printf("  flux          %.6g lm\n", in.flux);
        if (in.rated_lumens > 0.0)
            printf("  rated lumens  %.6g lm, light output ratio %.4f\n", in.rated_lumens, in.lor);
        else
            printf("  rated lumens  none (absolute photometry)\n");
        if (in.stated_lor >= 0.0)
            printf("  stated LOR    %.4f\n", in.stated_lor);
        printf("  opening       %s, %g x %g x %g m (length x width x height)\n", in.shape, in.length, in.width,
               in.height);
        if (in.tilt_count)
            printf("  tilt          %s, %zu angles\n", in.tilt, in.tilt_count);
        else
            printf("  tilt          none\n");
        if (in.input_watts > 0.0)
            printf("  input         %.6g W\n", in.input_watts);
    }
    return cli_status(status);
}
