/*
 * camera.c -- cameras for scenes that bring none: automatic framing of the
 * bounding box, and the CLI's --camera text.
 *
 * Framing looks along -z from +z at the box centre.  The front face of the
 * box (z = max) is the widest part of the box in the image, so the
 * distance is chosen to fit that face in both field-of-view angles, with
 * a margin:
 *
 *        y ^    +-------+ front face
 *          |    |       |
 *   eye <--|----|   +   |   half height h: d = h / tan(vfov / 2)
 *   (+z)   |    |       |
 *               +-------+
 */
#include "output/output.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#define RAD_FRAME_VFOV_DEGREES 40.0
#define RAD_FRAME_MARGIN 1.1   /* 10% border around the front face */

rad_camera rad_camera_frame(vec3 bounds_min, vec3 bounds_max, double aspect)
{
    if (!(aspect > 0.0) || !isfinite(aspect))
        aspect = 1.0;
    vec3 centre = v3_scale(v3_add(bounds_min, bounds_max), 0.5);
    vec3 half = v3_scale(v3_sub(bounds_max, bounds_min), 0.5);
    double tan_v = tan(0.5 * RAD_FRAME_VFOV_DEGREES * M_PI / 180.0);
    double tan_h = tan_v * aspect;
    double distance = RAD_FRAME_MARGIN * fmax(half.y / tan_v, half.x / tan_h);
    /* A flat or point-like box still needs the eye off its surface. */
    double size = v3_length(half);
    if (!(distance > 1e-3 * size))
        distance = size > 0.0 ? size : 1.0;
    rad_camera camera;
    camera.position[0] = centre.x;
    camera.position[1] = centre.y;
    camera.position[2] = bounds_max.z + distance;
    camera.look_at[0] = centre.x;
    camera.look_at[1] = centre.y;
    camera.look_at[2] = centre.z;
    camera.up[0] = 0.0;
    camera.up[1] = 1.0;
    camera.up[2] = 0.0;
    camera.vfov_degrees = RAD_FRAME_VFOV_DEGREES;
    return camera;
}

rad_result rad_camera_parse(rad_context *ctx, const char *text, rad_camera *camera)
{
    double value[10];
    int count = 0;
    const char *p = text ? text : "";
    for (;;) {
        if (count == 10)
            goto bad_count;
        char *end;
        errno = 0;
        value[count] = strtod(p, &end);
        if (end == p)
            goto bad_count;
        while (*end == ' ' || *end == '\t')
            end++;
        count++;
        if (*end == '\0')
            break;
        if (*end != ',')
            goto bad_count;
        p = end + 1;
    }
    if (count != 6 && count != 9 && count != 10)
        goto bad_count;
    for (int i = 0; i < count; i++)
        if (!isfinite(value[i]))
            return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                            "camera: number %d is not finite in '%s'", i + 1, text);

    rad_camera c;
    memcpy(c.position, value, sizeof c.position);
    memcpy(c.look_at, value + 3, sizeof c.look_at);
    c.up[0] = 0.0;
    c.up[1] = 1.0;
    c.up[2] = 0.0;
    c.vfov_degrees = RAD_FRAME_VFOV_DEGREES;
    if (count >= 9)
        memcpy(c.up, value + 6, sizeof c.up);
    if (count == 10)
        c.vfov_degrees = value[9];

    vec3 forward = v3_sub(v3(c.look_at[0], c.look_at[1], c.look_at[2]),
                          v3(c.position[0], c.position[1], c.position[2]));
    vec3 up = v3(c.up[0], c.up[1], c.up[2]);
    if (v3_length(forward) == 0.0)
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "camera: position and look-at point coincide in '%s'", text);
    /* Finite numbers can still be too far apart for a finite view
     * direction (1e308 and -1e308), or too large for the cross product
     * below: the renderer would get infinities. */
    if (!isfinite(v3_length(forward)) || !isfinite(v3_length(v3_cross(forward, up))))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "camera: position, look-at point or up vector too large in '%s'", text);
    /* Up must leave a sideways direction: |f x u| against |f||u|, with
     * room for round-off in a nearly parallel pair. */
    if (v3_length(v3_cross(forward, up)) <= 1e-9 * v3_length(forward) * v3_length(up))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "camera: up vector is zero or parallel to the view direction in '%s'",
                        text);
    if (!(c.vfov_degrees > 0.0 && c.vfov_degrees < 180.0))
        return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                        "camera: vertical field of view must be in (0, 180) degrees, got %g",
                        c.vfov_degrees);
    *camera = c;
    return RAD_OK;

bad_count:
    return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                    "camera: expected 6, 9 or 10 comma-separated numbers, got '%s'",
                    text ? text : "");
}

/* Pixel directions are exact to double rounding (1e-16), so a camera at
 * distance D misplaces its rays by about 1e-16 D where they meet the
 * scene.  Within RAD_CAMERA_MAX_DISTANCE scene diagonals that is 1e-10 of
 * the scene, far below the float rounding of the ray queries (1e-7; the
 * rays themselves are advanced to the scene in double, vis_embree.c): the
 * image is what a nearer camera with a narrower field would see.  Farther,
 * the rays would land wherever rounding puts them, so the camera is
 * refused. */
rad_result rad_camera_check_distance(rad_context *ctx, const rad_camera *camera, vec3 lo, vec3 hi)
{
    double diagonal = v3_length(v3_sub(hi, lo));
    if (!(diagonal > 0.0) || !isfinite(diagonal))
        return RAD_OK; /* nothing to place the camera against */
    vec3 position = v3(camera->position[0], camera->position[1], camera->position[2]);
    double distance = v3_length(v3_sub(position, v3_scale(v3_add(lo, hi), 0.5)));
    if (distance <= RAD_CAMERA_MAX_DISTANCE * diagonal)
        return RAD_OK;
    return rad_fail(ctx, RAD_ERROR_INVALID_ARGUMENT,
                    "camera: the position is %.3g m from the scene's centre, %.3g times the "
                    "scene's size of %.3g m; at most %g times is drawn (farther, rounding "
                    "misplaces the rays)",
                    distance, distance / diagonal, diagonal, RAD_CAMERA_MAX_DISTANCE);
}
