/*
 * cornell_box.c -- the built-in scene: the measured Cornell box.
 *
 * Source: Cornell University Program of Computer Graphics, "Cornell Box
 * Data", http://www.graphics.cornell.edu/online/box/data.html -- vertices as
 * published, converted from millimetres to metres; reflectances and the
 * light from the measured spectra (see the MTL's own header).  The text is
 * a verbatim copy of tests/data/cornell_box.obj and cornell_box.mtl and is
 * loaded through the ordinary importer (from memory), so the built-in box
 * and the files on disk cannot disagree about what is in it.
 *
 * The camera is the published one: at (278, 273, -800) mm looking along +z
 * with +y up, focal length 35 mm on a 25 mm square film, so the full
 * vertical field of view is 2 atan(12.5 / 35) = 39.3076 degrees.
 *
 * Seen from the camera (x grows to the left):
 *
 *     x = 0.556 +---------[ light ]---------+ x = 0      y = 0.5488
 *               |                           |
 *     left_wall |         back_wall         | right_wall
 *     (red)     |  tall_block               | (green)
 *               |              short_block  |
 *               +---------------------------+            y = 0
 */
#include "import/import.h"

#include <stdlib.h>

/* Each text stays below the 4095 characters C11 guarantees for one string
 * literal (-Woverlength-strings under -Wpedantic). */
static const char cornell_box_obj[] =
    "# Cornell box (Cornell University Program of Computer Graphics, 'Cornell Box Data',\n"
    "#   http://www.graphics.cornell.edu/online/box/data.html), vertices as published but\n"
    "#   converted from millimetres to METRES (x 0.001).  y is up; the open side is z = 0;\n"
    "#   camera: position (0.278, 0.273, -0.800), direction (0,0,1), up (0,1,0),\n"
    "#   focal length 0.035 m, film 0.025 x 0.025 m (also as published).\n"
    "# Transcribed from github.com/oddurs/cornell include/render/cornell.hpp @3b9f682.\n"
    "# Face winding: counter-clockwise seen from the lit side, so the right-hand-rule\n"
    "#   normal points INTO the room for walls/floor/ceiling/light and OUT of the blocks.\n"
    "# Ceiling is split into 4 quads around a hole that the light exactly fills (no\n"
    "#   coplanar overlap).  The red (left) wall is non-planar by 3.2 mm -> 2 triangles.\n"
    "mtllib cornell_box.mtl\n"
    "\n"
    "o floor\n"
    "usemtl white\n"
    "v 0.5528 0 0\n"
    "v 0 0 0\n"
    "v 0 0 0.5592\n"
    "v 0.5496 0 0.5592\n"
    "f 1 2 3 4\n"
    "\n"
    "o ceiling\n"
    "usemtl white\n"
    "v 0.556 0.5488 0\n"
    "v 0.556 0.5488 0.227\n"
    "v 0 0.5488 0.227\n"
    "v 0 0.5488 0\n"
    "f 5 6 7 8\n"
    "v 0.556 0.5488 0.332\n"
    "v 0.556 0.5488 0.5592\n"
    "v 0 0.5488 0.5592\n"
    "v 0 0.5488 0.332\n"
    "f 9 10 11 12\n"
    "v 0.213 0.5488 0.227\n"
    "v 0.213 0.5488 0.332\n"
    "v 0 0.5488 0.332\n"
    "v 0 0.5488 0.227\n"
    "f 13 14 15 16\n"
    "v 0.556 0.5488 0.227\n"
    "v 0.556 0.5488 0.332\n"
    "v 0.343 0.5488 0.332\n"
    "v 0.343 0.5488 0.227\n"
    "f 17 18 19 20\n"
    "\n"
    "o light\n"
    "usemtl light\n"
    "v 0.343 0.5488 0.227\n"
    "v 0.343 0.5488 0.332\n"
    "v 0.213 0.5488 0.332\n"
    "v 0.213 0.5488 0.227\n"
    "f 21 22 23 24\n"
    "\n"
    "o back_wall\n"
    "usemtl white\n"
    "v 0.5496 0 0.5592\n"
    "v 0 0 0.5592\n"
    "v 0 0.5488 0.5592\n"
    "v 0.556 0.5488 0.5592\n"
    "f 25 26 27 28\n"
    "\n"
    "o right_wall\n"
    "usemtl green\n"
    "v 0 0 0.5592\n"
    "v 0 0 0\n"
    "v 0 0.5488 0\n"
    "v 0 0.5488 0.5592\n"
    "f 29 30 31 32\n"
    "\n"
    "o left_wall\n"
    "usemtl red\n"
    "v 0.5528 0 0\n"
    "v 0.5496 0 0.5592\n"
    "v 0.556 0.5488 0.5592\n"
    "f 33 34 35\n"
    "v 0.5528 0 0\n"
    "v 0.556 0.5488 0.5592\n"
    "v 0.556 0.5488 0\n"
    "f 36 37 38\n"
    "\n"
    "o short_block\n"
    "usemtl white\n"
    "v 0.13 0.165 0.065\n"
    "v 0.082 0.165 0.225\n"
    "v 0.24 0.165 0.272\n"
    "v 0.29 0.165 0.114\n"
    "f 39 40 41 42\n"
    "v 0.29 0 0.114\n"
    "v 0.29 0.165 0.114\n"
    "v 0.24 0.165 0.272\n"
    "v 0.24 0 0.272\n"
    "f 43 44 45 46\n"
    "v 0.13 0 0.065\n"
    "v 0.13 0.165 0.065\n"
    "v 0.29 0.165 0.114\n"
    "v 0.29 0 0.114\n"
    "f 47 48 49 50\n"
    "v 0.082 0 0.225\n"
    "v 0.082 0.165 0.225\n"
    "v 0.13 0.165 0.065\n"
    "v 0.13 0 0.065\n"
    "f 51 52 53 54\n"
    "v 0.24 0 0.272\n"
    "v 0.24 0.165 0.272\n"
    "v 0.082 0.165 0.225\n"
    "v 0.082 0 0.225\n"
    "f 55 56 57 58\n"
    "\n"
    "o tall_block\n"
    "usemtl white\n"
    "v 0.423 0.33 0.247\n"
    "v 0.265 0.33 0.296\n"
    "v 0.314 0.33 0.456\n"
    "v 0.472 0.33 0.406\n"
    "f 59 60 61 62\n"
    "v 0.423 0 0.247\n"
    "v 0.423 0.33 0.247\n"
    "v 0.472 0.33 0.406\n"
    "v 0.472 0 0.406\n"
    "f 63 64 65 66\n"
    "v 0.472 0 0.406\n"
    "v 0.472 0.33 0.406\n"
    "v 0.314 0.33 0.456\n"
    "v 0.314 0 0.456\n"
    "f 67 68 69 70\n"
    "v 0.314 0 0.456\n"
    "v 0.314 0.33 0.456\n"
    "v 0.265 0.33 0.296\n"
    "v 0.265 0 0.296\n"
    "f 71 72 73 74\n"
    "v 0.265 0 0.296\n"
    "v 0.265 0.33 0.296\n"
    "v 0.423 0.33 0.247\n"
    "v 0.423 0 0.247\n"
    "f 75 76 77 78\n";

static const char cornell_box_mtl[] =
    "# Cornell box materials.  Kd = approximate linear-sRGB reflectance computed by this\n"
    "#   project's refcases.py from the MEASURED 400-700 nm spectra (4 nm): spectrum x\n"
    "#   CIE 1931 CMFs (Wyman-Sloan-Shirley 2013 fit) -> XYZ -> linear sRGB, divided by\n"
    "#   the same for an equal-energy white (so a flat spectrum 0.75 gives Kd 0.75).\n"
    "# Ke = light spectrum (relative; published scale is ARBITRARY) treated the same way;\n"
    "#   interpret Ke as RADIANCE in arbitrary units (exitance = pi x radiance) and\n"
    "#   rescale to taste.  Commonly used renderer values for comparison (Tungsten/\n"
    "#   Bitterli): white 0.725 0.71 0.68, red 0.63 0.065 0.05, green 0.14 0.45 0.091,\n"
    "#   light 17 12 4.\n"
    "# light Kd 0.78: the lamp's constant reflectance as listed with the published data (per the oddurs/cornell transcription notes).\n"
    "\n"
    "newmtl white\n"
    "Kd 0.7378 0.7361 0.7374\n"
    "Ke 0 0 0\n"
    "illum 1\n"
    "\n"
    "newmtl red\n"
    "Kd 0.4718 0.0469 0.0489\n"
    "Ke 0 0 0\n"
    "illum 1\n"
    "\n"
    "newmtl green\n"
    "Kd 0.0879 0.3984 0.0844\n"
    "Ke 0 0 0\n"
    "illum 1\n"
    "\n"
    "newmtl light\n"
    "Kd 0.78 0.78 0.78\n"
    "Ke 17.1972 11.4744 3.0619\n"
    "illum 1\n";

rad_result rad_scene_create_cornell_box(rad_context *ctx, rad_scene **out)
{
    rad_api_enter(ctx);
    if (out)
        *out = NULL;
    if (!ctx || !out)
        return rad_null_argument(ctx, __func__);
    double start = rad_seconds();
    rad_scene *scene;
    rad_result r = rad_import_assimp_memory(ctx, "cornell_box.obj", cornell_box_obj,
                                            sizeof cornell_box_obj - 1, cornell_box_mtl,
                                            sizeof cornell_box_mtl - 1, &scene);
    if (r != RAD_OK)
        return r;
    char *source = rad_strdup(ctx, RAD_MEM_SCENE, "cornell-box", "cornell-box");
    if (!source) {
        rad_scene_destroy(scene);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    rad_free(scene->source);
    scene->source = source;
    rad_camera camera = {
        .position = {0.278, 0.273, -0.800},
        .look_at = {0.278, 0.273, 0.0},
        .up = {0.0, 1.0, 0.0},
        .vfov_degrees = 2.0 * atan(0.5 * 0.025 / 0.035) * 180.0 / M_PI, /* film, focal length */
    };
    scene->has_camera = true;
    scene->camera = camera;
    scene->load_seconds = rad_seconds() - start;
    *out = scene;
    return RAD_OK;
}
