/*
 * fuzz_ies.c -- an IES LM-63 photometric file (photometry/ies.c) from
 * memory, through the reader itself (not the by-content dispatch, so
 * every input reaches it).  A failure must leave a one-line message and no
 * distribution; a success a table as photometry.h describes it: C from 0
 * to 360 (or one plane), gamma from 0 to 180 with at most two equal in a
 * row, candela finite and >= 0, a finite flux, finite intensities.
 */
#include "fuzz.h"
#include "photometry/photometry_internal.h"

#include <math.h>
#include <string.h>

static void check_warning(void *user, const char *message)
{
    (void)user;
    FUZZ_CHECK(message[0] != '\0' && strchr(message, '\n') == NULL && strlen(message) < 1024);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rad_context_options co = {.threads = 1, .on_warning = check_warning};
    rad_context *ctx = NULL;
    if (rad_context_create(&co, &ctx) != RAD_OK)
        return 0;
    rad_photometry *p = (rad_photometry *)1;
    rad_result r = ph_parse_ies(ctx, "x.ies", NULL, (const char *)data, size, &p);
    if (r != RAD_OK) {
        const char *msg = rad_context_error(ctx);
        FUZZ_CHECK(p == NULL);
        FUZZ_CHECK(msg[0] != '\0' && strchr(msg, '\n') == NULL);
    } else {
        FUZZ_CHECK(p != NULL && p->c_count >= 1 && p->gamma_count >= 2);
        FUZZ_CHECK(p->c_count == 1 || (p->c_angles[0] == 0.0 && p->c_angles[p->c_count - 1] == 360.0));
        for (size_t i = 1; i < p->c_count; i++)
            FUZZ_CHECK(p->c_angles[i] > p->c_angles[i - 1]);
        FUZZ_CHECK(p->gamma_angles[0] == 0.0 && p->gamma_angles[p->gamma_count - 1] == 180.0);
        for (size_t i = 1; i < p->gamma_count; i++)
            FUZZ_CHECK(p->gamma_angles[i] >= p->gamma_angles[i - 1] &&
                       (i < 2 || p->gamma_angles[i] > p->gamma_angles[i - 2]));
        for (size_t i = 0; i < p->c_count * p->gamma_count; i++)
            FUZZ_CHECK(isfinite(p->candela[i]) && p->candela[i] >= 0.0);
        FUZZ_CHECK(isfinite(p->flux) && p->flux >= 0.0);
        FUZZ_CHECK(p->width >= 0.0 && p->length >= 0.0 && p->height >= 0.0);
        for (int k = 0; k < 16; k++) {
            double z = 1.0 - (k + 0.5) / 8.0, s = sqrt(1.0 - z * z);
            double i = rad_photometry_intensity(p, v3(s * cos(k * 2.4), s * sin(k * 2.4), z));
            FUZZ_CHECK(isfinite(i) && i >= 0.0);
        }
        rad_photometry_free(p);
    }
    rad_context_destroy(ctx);
    return 0;
}
