/*
 * orbit.c -- the viewer's cameras: orbit about a target, fly through the
 * scene, frame all, and the matrices OpenGL draws with.
 *
 * The projection is the renderer's pinhole (src/output/render.c): the same
 * forward f = normalize(look_at - position), right r = normalize(f x up),
 * true up u = r x f and vertical field of view, so a frame drawn here and
 * an image ray-cast from the same rad_camera put every point on the same
 * pixel.  Positions are taken relative to the scene's centre in double
 * before they become float, so a scene far from the origin keeps its
 * precision on the GPU.
 */
#include "viewer.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void sub(const double a[3], const double b[3], double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = a[k] - b[k];
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross(const double a[3], const double b[3], double out[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    memcpy(out, c, sizeof c);
}

static bool normalize(double v[3])
{
    double length = sqrt(dot(v, v));
    if (!(length > 0.0) || !isfinite(length))
        return false;
    for (int k = 0; k < 3; k++)
        v[k] /= length;
    return true;
}

/* v rotated by `angle` about the unit axis (Rodrigues' formula). */
static void rotate(double v[3], const double axis[3], double angle)
{
    double c = cos(angle), s = sin(angle), k_cross_v[3];
    cross(axis, v, k_cross_v);
    double k_dot_v = dot(axis, v);
    for (int k = 0; k < 3; k++)
        v[k] = v[k] * c + k_cross_v[k] * s + axis[k] * k_dot_v * (1.0 - c);
}

/* The camera's orthonormal frame; false when degenerate. */
static bool frame(const rv_camera *c, double forward[3], double right[3], double up[3])
{
    sub(c->target, c->position, forward);
    if (!normalize(forward))
        return false;
    cross(forward, c->up, right);
    if (!normalize(right))
        return false;
    cross(right, forward, up);
    return true;
}

rv_camera rv_camera_from(const rad_camera *camera)
{
    rv_camera c;
    memcpy(c.position, camera->position, sizeof c.position);
    memcpy(c.target, camera->look_at, sizeof c.target);
    memcpy(c.up, camera->up, sizeof c.up);
    c.vfov_degrees = camera->vfov_degrees;
    return c;
}

rad_camera rv_camera_to(const rv_camera *c)
{
    rad_camera camera;
    memcpy(camera.position, c->position, sizeof camera.position);
    memcpy(camera.look_at, c->target, sizeof camera.look_at);
    memcpy(camera.up, c->up, sizeof camera.up);
    camera.vfov_degrees = c->vfov_degrees;
    return camera;
}

/* Pitch is held short of the up axis (0.01 rad, about half a degree), where
 * the right axis f x up would vanish. */
#define RV_PITCH_MARGIN 0.01

static double clamp_pitch(const double forward[3], const double up_axis[3], double pitch)
{
    double up_axis_unit[3] = {up_axis[0], up_axis[1], up_axis[2]};
    if (!normalize(up_axis_unit))
        return 0.0;
    double elevation = asin(fmax(-1.0, fmin(1.0, dot(forward, up_axis_unit))));
    double limit = 0.5 * M_PI - RV_PITCH_MARGIN;
    return fmax(-limit - elevation, fmin(limit - elevation, pitch));
}

void rv_camera_orbit(rv_camera *c, double yaw, double pitch)
{
    double forward[3], right[3], up[3], axis[3] = {c->up[0], c->up[1], c->up[2]};
    if (!frame(c, forward, right, up) || !normalize(axis))
        return;
    double offset[3];
    sub(c->position, c->target, offset);
    /* The eye rises by `pitch` as the view direction tips down by it. */
    pitch = clamp_pitch(forward, axis, -pitch);
    rotate(offset, right, pitch);
    rotate(offset, axis, yaw);
    for (int k = 0; k < 3; k++)
        c->position[k] = c->target[k] + offset[k];
}

void rv_camera_look(rv_camera *c, double yaw, double pitch)
{
    double forward[3], right[3], up[3], axis[3] = {c->up[0], c->up[1], c->up[2]};
    if (!frame(c, forward, right, up) || !normalize(axis))
        return;
    double distance[3];
    sub(c->target, c->position, distance);
    double d = sqrt(dot(distance, distance));
    pitch = clamp_pitch(forward, axis, pitch);
    rotate(forward, right, pitch);
    rotate(forward, axis, yaw);
    for (int k = 0; k < 3; k++)
        c->target[k] = c->position[k] + d * forward[k];
}

void rv_camera_move(rv_camera *c, double forward_m, double right_m, double up_m)
{
    double forward[3], right[3], up[3];
    if (!frame(c, forward, right, up))
        return;
    for (int k = 0; k < 3; k++) {
        double step = forward_m * forward[k] + right_m * right[k] + up_m * up[k];
        c->position[k] += step;
        c->target[k] += step;
    }
}

void rv_camera_dolly(rv_camera *c, double factor)
{
    double offset[3];
    sub(c->position, c->target, offset);
    if (!(factor > 0.0) || !(sqrt(dot(offset, offset)) * factor > 1e-9))
        return;
    for (int k = 0; k < 3; k++)
        c->position[k] = c->target[k] + factor * offset[k];
}

void rv_camera_frame(rv_camera *c, const double centre[3], double radius, double aspect)
{
    double forward[3], right[3], up[3];
    if (!frame(c, forward, right, up))
        return;
    double half = 0.5 * c->vfov_degrees * M_PI / 180.0;
    double half_h = atan(tan(half) * (aspect > 0.0 ? fmin(aspect, 1.0) : 1.0));
    double distance = radius / sin(fmin(half, half_h));
    for (int k = 0; k < 3; k++) {
        c->target[k] = centre[k];
        c->position[k] = centre[k] - distance * forward[k];
    }
}

void rv_camera_text(const rv_camera *c, char *text, size_t size)
{
    snprintf(text, size, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", c->position[0],
             c->position[1], c->position[2], c->target[0], c->target[1], c->target[2], c->up[0], c->up[1],
             c->up[2], c->vfov_degrees);
}

/* Near plane: where the eye is outside the bounding sphere, its near side
 * (less 1%); inside it, 1e-4 of the far plane, which a 24-bit depth buffer
 * still resolves to 1e-3 of the scene near the far plane. */
void rv_camera_matrix(const rv_camera *c, const double origin[3], double radius, double aspect, float m[16])
{
    double f[3], r[3], u[3], eye[3];
    memset(m, 0, 16 * sizeof *m);
    if (!frame(c, f, r, u))
        return;
    sub(c->position, origin, eye);
    double distance = sqrt(dot(eye, eye));
    double far_plane = 1.01 * (distance + radius);
    double near_plane = fmax(0.99 * (distance - radius), 1e-4 * far_plane);
    double t = tan(0.5 * c->vfov_degrees * M_PI / 180.0);
    double sx = 1.0 / (t * aspect), sy = 1.0 / t;
    double a = -(far_plane + near_plane) / (far_plane - near_plane);
    double b = -2.0 * far_plane * near_plane / (far_plane - near_plane);
    /* P * V with V rows (r, -eye.r), (u, -eye.u), (-f, eye.f). */
    double view[3][4] = {{r[0], r[1], r[2], -dot(r, eye)},
                         {u[0], u[1], u[2], -dot(u, eye)},
                         {-f[0], -f[1], -f[2], dot(f, eye)}};
    for (int col = 0; col < 4; col++) {
        m[4 * col + 0] = (float)(sx * view[0][col]);
        m[4 * col + 1] = (float)(sy * view[1][col]);
        m[4 * col + 2] = (float)(a * view[2][col] + (col == 3 ? b : 0.0));
        m[4 * col + 3] = (float)(-view[2][col]);
    }
}
