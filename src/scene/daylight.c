/*
 * daylight.c -- the scene's daylight as a model: what rad_scene_destroy
 * frees.  The file that makes it is read by light/daylight_file.c.
 */
#include "scene/daylight.h"

void rad_daylight_free(rad_daylight *d)
{
    if (!d)
        return;
    rad_free(d->source);
    rad_free(d->openings);
    for (size_t k = 0; k < d->opening_name_count; k++)
        rad_free(d->opening_names[k]);
    rad_free(d->opening_names);
    rad_free(d->marked);
    rad_free(d);
}
