/*
 * daylight_file.c -- the daylight file (docs/lighting.md "Daylight"), read with
 * cJSON against a loaded scene, and the openings it marks moved out of the
 * scene:
 *
 *     {"sky": {"type": 12, "diffuse_illuminance": 10000},   1..15 or "cie-overcast";
 *                                                            or "zenith_luminance": cd/m^2
 *      "sun": {"altitude": 40, "azimuth": 180,              deg, azimuth from north via east
 *              "normal_illuminance": 60000},                 lux; 0 or none: no direct sun
 *      "up": [0, 1, 0], "north": [0, 0, -1],                 the defaults
 *      "ground": {"reflectance": 0.2},                       none: nothing below the horizon
 *      "openings": {"surfaces": ["skylight"], "materials": ["glass_hole"]},
 *      "tolerance": 1e-4}
 *
 * or the sun from place and time: {"latitude": 51.5, "longitude": -0.12,
 * "date": "2024-06-21", "time": "13:00", "timezone": 1, ...}.  Polygons of
 * a material named "opening" are openings too.  Every error names the
 * file and the key ("sky.json: sun.altitude: ...").  The public calls
 * (rad_scene_daylight_load_file, _memory) read, scale the sky and attach.
 */
#include "light/sky.h"
#include "photometry/photometry.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* CIE S 011/E:2003 (ISO 15469:2004), Table 1: the 15 standard general
 * skies' gradation (a, b) and indicatrix (c, d, e) parameters.  Types 1-5
 * are overcast to uniform (1: the overcast of steep gradation; 5: uniform
 * luminance), 6-10 partly cloudy, 11-15 clear (12: the CIE standard clear
 * sky, low turbidity; 13: the clear polluted sky). */
static const double sky_types[15][5] = {
    {4.0, -0.70, 0.0, -1.0, 0.00},  {4.0, -0.70, 2.0, -1.5, 0.15},  {1.1, -0.8, 0.0, -1.0, 0.00},
    {1.1, -0.8, 2.0, -1.5, 0.15},   {0.0, -1.0, 0.0, -1.0, 0.00},   {0.0, -1.0, 2.0, -1.5, 0.15},
    {0.0, -1.0, 5.0, -2.5, 0.30},   {0.0, -1.0, 10.0, -3.0, 0.45},  {-1.0, -0.55, 2.0, -1.5, 0.15},
    {-1.0, -0.55, 5.0, -2.5, 0.30}, {-1.0, -0.55, 10.0, -3.0, 0.45}, {-1.0, -0.32, 10.0, -3.0, 0.45},
    {-1.0, -0.32, 16.0, -3.0, 0.30}, {-1.0, -0.15, 16.0, -3.0, 0.30}, {-1.0, -0.15, 24.0, -2.8, 0.15}};

bool rad_sky_type_parameters(int type, double p[5])
{
    if (type < 1 || type > 15)
        return false;
    memcpy(p, sky_types[type - 1], 5 * sizeof *p);
    return true;
}

/* NOAA Global Monitoring Laboratory, "General Solar Position Calculations"
 * (the fractional-year series of Spencer, Search 2(5), 1971): accurate to
 * about 0.05 deg in declination and 0.5 min in the equation of time. */
void rad_sun_position(double latitude, double longitude, int day_of_year, double hours, double timezone,
                      double *zenith, double *azimuth)
{
    double g = 2.0 * M_PI / 365.0 * (day_of_year - 1 + (hours - timezone - 12.0) / 24.0); /* UTC */
    double eot = 229.18 * (0.000075 + 0.001868 * cos(g) - 0.032077 * sin(g) - 0.014615 * cos(2 * g) -
                           0.040849 * sin(2 * g)); /* min */
    double decl = 0.006918 - 0.399912 * cos(g) + 0.070257 * sin(g) - 0.006758 * cos(2 * g) +
                  0.000907 * sin(2 * g) - 0.002697 * cos(3 * g) + 0.00148 * sin(3 * g); /* rad */
    double true_solar = hours * 60.0 + eot + 4.0 * longitude - 60.0 * timezone; /* min */
    double hour_angle = (true_solar / 4.0 - 180.0) * M_PI / 180.0;
    double lat = latitude * M_PI / 180.0;
    double cz = sin(lat) * sin(decl) + cos(lat) * cos(decl) * cos(hour_angle);
    *zenith = acos(fmin(1.0, fmax(-1.0, cz)));
    /* Azimuth from south toward west, turned to from north toward east. */
    double a = atan2(sin(hour_angle), cos(hour_angle) * sin(lat) - tan(decl) * cos(lat)) + M_PI;
    *azimuth = fmod(a + 2.0 * M_PI, 2.0 * M_PI);
}

/* ---- reading ---- */

typedef struct reader {
    rad_context *ctx;
    const char *name;
    const rad_scene *scene;
} reader;

#define FAIL(rd, ...) rad_fail((rd)->ctx, RAD_ERROR_PARSE, __VA_ARGS__)

/* The members of object o, each of `keys` at most once, into slots (NULL
 * where absent); `where` prefixes the key path ("" at the root). */
static rad_result members(const reader *rd, const char *where, const cJSON *o, const char *const *keys,
                          size_t count, const cJSON **slots)
{
    for (size_t k = 0; k < count; k++)
        slots[k] = NULL;
    for (const cJSON *item = o->child; item; item = item->next) {
        size_t k = 0;
        while (k < count && strcmp(item->string, keys[k]) != 0)
            k++;
        if (k == count) {
            char known[256] = "";
            for (size_t j = 0; j < count; j++)
                snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", j ? ", " : "", keys[j]);
            return FAIL(rd, "%s: %s%.200s: unknown key (known: %s)", rd->name, where, item->string, known);
        }
        if (slots[k])
            return FAIL(rd, "%s: %s%s: given twice", rd->name, where, keys[k]);
        slots[k] = item;
    }
    return RAD_OK;
}

/* A finite number in [lo, hi] at key path `key`. */
static rad_result number(const reader *rd, const char *key, const cJSON *item, double lo, double hi, double *out)
{
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
        return FAIL(rd, "%s: %s: must be a number", rd->name, key);
    double v = item->valuedouble;
    if (!(v >= lo && v <= hi))
        return FAIL(rd, "%s: %s: must be in [%g, %g], got %.6g", rd->name, key, lo, hi, v);
    *out = v;
    return RAD_OK;
}

static rad_result direction(const reader *rd, const char *key, const cJSON *item, vec3 *out)
{
    double v[3];
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return FAIL(rd, "%s: %s: must be an array of three numbers, such as [0, 1, 0]", rd->name, key);
    int k = 0;
    for (const cJSON *x = item->child; x; x = x->next, k++) {
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble) || fabs(x->valuedouble) > 1e30)
            return FAIL(rd, "%s: %s[%d]: must be a finite number", rd->name, key, k);
        v[k] = x->valuedouble;
    }
    vec3 d = {v[0], v[1], v[2]};
    double len = v3_length(d);
    if (!(len > 1e-12))
        return FAIL(rd, "%s: %s: must not be the zero vector", rd->name, key);
    *out = v3_scale(d, 1.0 / len);
    return RAD_OK;
}

static bool leap(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

static rad_result read_sky(const reader *rd, const cJSON *o, rad_daylight *d)
{
    if (!cJSON_IsObject(o))
        return FAIL(rd, "%s: sky: must be an object such as {\"type\": 12, \"diffuse_illuminance\": 10000}",
                    rd->name);
    static const char *const keys[] = {"type", "zenith_luminance", "diffuse_illuminance"};
    const cJSON *s[3];
    rad_result r = members(rd, "sky.", o, keys, 3, s);
    if (r != RAD_OK)
        return r;
    if (!s[0])
        return FAIL(rd, "%s: sky.type: missing (1 to 15, the CIE general skies, or \"cie-overcast\")", rd->name);
    if (cJSON_IsString(s[0]) && strcmp(s[0]->valuestring, "cie-overcast") == 0) {
        d->sky.model = RAD_SKY_CIE_OVERCAST;
    } else {
        double t = cJSON_IsNumber(s[0]) ? s[0]->valuedouble : 0.0;
        if (!(t >= 1 && t <= 15) || t != floor(t))
            return FAIL(rd, "%s: sky.type: must be an integer 1 to 15 (the CIE general skies) or "
                        "\"cie-overcast\"", rd->name);
        d->sky.model = RAD_SKY_CIE_GENERAL;
        d->sky.type = (int)t;
        double p[5] = {0, 0, 0, 0, 0};
        rad_sky_type_parameters(d->sky.type, p);
        d->sky.a = p[0], d->sky.b = p[1], d->sky.c = p[2], d->sky.d = p[3], d->sky.e = p[4];
    }
    if (s[1] && s[2])
        return FAIL(rd, "%s: sky: give zenith_luminance or diffuse_illuminance, not both", rd->name);
    d->diffuse_illuminance = 10000.0;
    if (s[1] && (r = number(rd, "sky.zenith_luminance", s[1], 1e-9, 1e12, &d->zenith_luminance)) != RAD_OK)
        return r;
    if (s[2] && (r = number(rd, "sky.diffuse_illuminance", s[2], 1e-9, 1e12, &d->diffuse_illuminance)) != RAD_OK)
        return r;
    return RAD_OK;
}

/* "YYYY-MM-DD" -> day of the year; "HH:MM[:SS]" -> hours. */
static bool parse_date(const char *text, int *day_of_year)
{
    int y, m, dd, n = 0;
    static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (sscanf(text, "%4d-%2d-%2d%n", &y, &m, &dd, &n) != 3 || text[n] != '\0' || m < 1 || m > 12 || dd < 1 ||
        y < 1 || dd > days[m - 1] + (m == 2 && leap(y)))
        return false;
    int doy = dd;
    for (int k = 0; k < m - 1; k++)
        doy += days[k] + (k == 1 && leap(y));
    *day_of_year = doy;
    return true;
}

static bool parse_time(const char *text, double *hours)
{
    int h, m, s = 0, n = 0;
    if (sscanf(text, "%2d:%2d%n", &h, &m, &n) != 2)
        return false;
    if (text[n] == ':') {
        int n2 = 0;
        if (sscanf(text + n + 1, "%2d%n", &s, &n2) != 1)
            return false;
        n += 1 + n2;
    }
    if (text[n] != '\0' || h < 0 || h > 24 || m < 0 || m > 59 || s < 0 || s > 59 || (h == 24 && (m || s)))
        return false;
    *hours = h + m / 60.0 + s / 3600.0;
    return true;
}

static rad_result read_sun(const reader *rd, const cJSON *o, rad_daylight *d, bool *positioned)
{
    if (!cJSON_IsObject(o))
        return FAIL(rd, "%s: sun: must be an object such as {\"altitude\": 40, \"azimuth\": 180}", rd->name);
    static const char *const keys[] = {"altitude", "azimuth", "latitude", "longitude", "date", "time",
                                       "timezone", "normal_illuminance"};
    const cJSON *s[8];
    rad_result r = members(rd, "sun.", o, keys, 8, s);
    if (r != RAD_OK)
        return r;
    bool angles = s[0] || s[1], place = s[2] || s[3] || s[4] || s[5] || s[6];
    if (angles && place)
        return FAIL(rd, "%s: sun: give altitude and azimuth, or latitude, longitude, date, time and timezone, "
                    "not both", rd->name);
    if (s[7] && (r = number(rd, "sun.normal_illuminance", s[7], 0.0, 1e12, &d->sun_normal)) != RAD_OK)
        return r;
    d->sun_normal /= RAD_LUMINOUS_EFFICACY; /* lux -> W/m^2 per channel */
    double zenith, azimuth;
    if (angles) {
        double alt = 0.0, az = 0.0;
        if (!s[0] || !s[1])
            return FAIL(rd, "%s: sun.%s: missing (altitude and azimuth go together)", rd->name,
                        s[0] ? "azimuth" : "altitude");
        if ((r = number(rd, "sun.altitude", s[0], -90.0, 90.0, &alt)) != RAD_OK ||
            (r = number(rd, "sun.azimuth", s[1], -360.0, 360.0, &az)) != RAD_OK)
            return r;
        zenith = (90.0 - alt) * M_PI / 180.0;
        azimuth = az * M_PI / 180.0;
    } else if (place) {
        for (int k = 2; k <= 6; k++)
            if (!s[k])
                return FAIL(rd, "%s: sun.%s: missing (the sun from place and time needs latitude, longitude, "
                            "date, time and timezone)", rd->name, keys[k]);
        double lat = 0.0, lon = 0.0, tz = 0.0, hours = 0.0;
        int doy = 1;
        if ((r = number(rd, "sun.latitude", s[2], -90.0, 90.0, &lat)) != RAD_OK ||
            (r = number(rd, "sun.longitude", s[3], -180.0, 180.0, &lon)) != RAD_OK ||
            (r = number(rd, "sun.timezone", s[6], -14.0, 14.0, &tz)) != RAD_OK)
            return r;
        if (!cJSON_IsString(s[4]) || !parse_date(s[4]->valuestring, &doy))
            return FAIL(rd, "%s: sun.date: must be a date \"YYYY-MM-DD\"", rd->name);
        if (!cJSON_IsString(s[5]) || !parse_time(s[5]->valuestring, &hours))
            return FAIL(rd, "%s: sun.time: must be a local clock time \"HH:MM\" or \"HH:MM:SS\"", rd->name);
        rad_sun_position(lat, lon, doy, hours, tz, &zenith, &azimuth);
    } else {
        return FAIL(rd, "%s: sun: give its position: altitude and azimuth, or latitude, longitude, date, time "
                    "and timezone", rd->name);
    }
    d->sky.sun_zenith = zenith;
    d->sky.sun_azimuth = azimuth;
    *positioned = true;
    return RAD_OK;
}

static rad_result read_ground(const reader *rd, const cJSON *o, rad_daylight *d)
{
    if (!cJSON_IsObject(o))
        return FAIL(rd, "%s: ground: must be an object such as {\"reflectance\": 0.2}", rd->name);
    static const char *const keys[] = {"reflectance"};
    const cJSON *s[1];
    rad_result r = members(rd, "ground.", o, keys, 1, s);
    if (r != RAD_OK)
        return r;
    if (!s[0])
        return FAIL(rd, "%s: ground.reflectance: missing", rd->name);
    d->ground = true;
    return number(rd, "ground.reflectance", s[0], 0.0, 1.0, &d->ground_reflectance);
}

/* Mark the polygons of the surfaces and materials "openings" names. */
static rad_result read_openings(const reader *rd, const cJSON *o, rad_daylight *d)
{
    if (!cJSON_IsObject(o))
        return FAIL(rd, "%s: openings: must be an object such as {\"surfaces\": [\"window\"]}", rd->name);
    static const char *const keys[] = {"surfaces", "materials"};
    const cJSON *s[2];
    rad_result r = members(rd, "openings.", o, keys, 2, s);
    if (r != RAD_OK)
        return r;
    const rad_scene *scene = rd->scene;
    for (int k = 0; k < 2; k++) {
        if (!s[k])
            continue;
        if (!cJSON_IsArray(s[k]))
            return FAIL(rd, "%s: openings.%s: must be an array of names", rd->name, keys[k]);
        int i = 0;
        for (const cJSON *x = s[k]->child; x; x = x->next, i++) {
            if (!cJSON_IsString(x))
                return FAIL(rd, "%s: openings.%s[%d]: must be a name (a string)", rd->name, keys[k], i);
            size_t count = k == 0 ? scene->surface_count : scene->material_count, j = 0;
            while (j < count && strcmp(k == 0 ? scene->surfaces[j].name : scene->materials[j].name,
                                       x->valuestring) != 0)
                j++;
            if (j == count)
                return FAIL(rd, "%s: openings.%s[%d]: the scene %s has no %s '%.200s'", rd->name, keys[k], i,
                            scene->source ? scene->source : "", k == 0 ? "surface" : "material", x->valuestring);
            for (size_t p = 0; p < scene->polygon_count; p++)
                if ((k == 0 ? scene->polygons[p].surface : scene->polygons[p].material) == j)
                    d->marked[p] = 1;
        }
    }
    return RAD_OK;
}

static rad_result parse_tree(const reader *rd, const cJSON *root, rad_daylight *d)
{
    if (!cJSON_IsObject(root))
        return FAIL(rd, "%s: must be a JSON object with \"sky\"", rd->name);
    static const char *const keys[] = {"sky", "sun", "up", "north", "ground", "openings", "tolerance"};
    const cJSON *s[7];
    rad_result r = members(rd, "", root, keys, 7, s);
    if (r != RAD_OK)
        return r;
    if (!s[0])
        return FAIL(rd, "%s: sky: missing (such as {\"type\": \"cie-overcast\"})", rd->name);
    d->sky.up = (vec3){0.0, 1.0, 0.0};
    d->sky.north = (vec3){0.0, 0.0, -1.0};
    if (s[2] && (r = direction(rd, "up", s[2], &d->sky.up)) != RAD_OK)
        return r;
    if (s[3] && (r = direction(rd, "north", s[3], &d->sky.north)) != RAD_OK)
        return r;
    vec3 north = v3_sub(d->sky.north, v3_scale(d->sky.up, v3_dot(d->sky.north, d->sky.up)));
    if (!(v3_length(north) > 1e-6))
        return FAIL(rd, "%s: north: must not be parallel to up", rd->name);
    d->sky.north = v3_normalize(north);
    d->sky.east = v3_cross(d->sky.north, d->sky.up);
    if ((r = read_sky(rd, s[0], d)) != RAD_OK)
        return r;
    bool positioned = false;
    if (s[1] && (r = read_sun(rd, s[1], d, &positioned)) != RAD_OK)
        return r;
    bool needs_sun = d->sky.model == RAD_SKY_CIE_GENERAL && (d->sky.c != 0.0 || d->sky.e != 0.0);
    if (needs_sun && !positioned)
        return FAIL(rd, "%s: sun: missing: sky type %d depends on the sun's position", rd->name, d->sky.type);
    if ((needs_sun || d->sun_normal > 0.0) && !(d->sky.sun_zenith < 0.5 * M_PI))
        return FAIL(rd, "%s: sun: the sun is %.2f deg below the horizon: sky type %d and direct sun need it "
                    "above", rd->name, (d->sky.sun_zenith - 0.5 * M_PI) * 180.0 / M_PI, d->sky.type);
    if (!positioned || !(d->sky.sun_zenith < 0.5 * M_PI))
        d->sky.sun_zenith = 0.0, d->sky.sun_azimuth = 0.0, d->sun_normal = 0.0;
    double sz = sin(d->sky.sun_zenith);
    d->sky.sun = v3_add(v3_scale(d->sky.up, cos(d->sky.sun_zenith)),
                        v3_scale(v3_add(v3_scale(d->sky.north, cos(d->sky.sun_azimuth)),
                                        v3_scale(d->sky.east, sin(d->sky.sun_azimuth))), sz));
    if (s[4] && (r = read_ground(rd, s[4], d)) != RAD_OK)
        return r;
    if (s[5] && (r = read_openings(rd, s[5], d)) != RAD_OK)
        return r;
    d->tolerance = 1e-4;
    if (s[6] && (r = number(rd, "tolerance", s[6], 1e-6, 0.1, &d->tolerance)) != RAD_OK)
        return r;
    /* The material convention: polygons of a material named "opening". */
    for (size_t p = 0; p < rd->scene->polygon_count; p++)
        if (strcmp(rd->scene->materials[rd->scene->polygons[p].material].name, "opening") == 0)
            d->marked[p] = 1;
    return RAD_OK;
}

rad_result rad_daylight_parse(rad_context *ctx, const rad_scene *scene, const char *name, const char *text,
                              size_t size, rad_daylight **out)
{
    *out = NULL;
    rad_daylight *d = rad_alloc(ctx, RAD_MEM_SCENE, 1, sizeof *d, "daylight");
    if (!d)
        return RAD_ERROR_OUT_OF_MEMORY;
    d->source = rad_strdup(ctx, RAD_MEM_SCENE, name, "daylight: name");
    d->marked = rad_alloc(ctx, RAD_MEM_SCENE, scene->polygon_count + 1, 1, "daylight: openings' polygons");
    d->marked_count = scene->polygon_count;
    if (!d->source || !d->marked) {
        rad_daylight_free(d);
        return RAD_ERROR_OUT_OF_MEMORY;
    }
    reader rd = {ctx, name, scene};
    rad_result r;
    cJSON *root = NULL;
    r = rad_json_parse(ctx, name, text, size, &root);
    if (r == RAD_OK)
        r = parse_tree(&rd, root, d);
    cJSON_Delete(root);
    if (r != RAD_OK) {
        rad_daylight_free(d);
        return r;
    }
    *out = d;
    return RAD_OK;
}

/* ---- the openings leave the scene ---- */

static bool convex_quad(const vec3 *q, vec3 normal)
{
    for (int k = 0; k < 4; k++) {
        vec3 e0 = v3_sub(q[(k + 1) % 4], q[k]), e1 = v3_sub(q[(k + 2) % 4], q[(k + 1) % 4]);
        if (!(v3_dot(v3_cross(e0, e1), normal) > 0.0))
            return false;
    }
    return true;
}

/* The pieces of the marked polygons into d->openings (triangles and
 * convex quads), their surfaces' names into d->opening_names. */
static rad_result collect_openings(rad_context *ctx, const rad_scene *scene, rad_daylight *d)
{
    size_t pieces = 0, biggest = 3;
    for (size_t p = 0; p < scene->polygon_count; p++)
        if (d->marked[p]) {
            pieces += scene->polygons[p].vertex_count - 2;
            if (scene->polygons[p].vertex_count > biggest)
                biggest = scene->polygons[p].vertex_count;
        }
    /* A daylight the scene had already: its openings stay openings. */
    const rad_daylight *before = scene->daylight;
    size_t before_pieces = before ? before->opening_count : 0, before_names = before ? before->opening_name_count : 0;
    d->openings = rad_alloc(ctx, RAD_MEM_SCENE, before_pieces + pieces + 1, sizeof *d->openings,
                            "daylight: openings");
    d->opening_names = rad_alloc(ctx, RAD_MEM_SCENE, before_names + scene->surface_count + 1,
                                 sizeof *d->opening_names, "daylight: openings' names");
    uint32_t *name_of = rad_alloc(ctx, RAD_MEM_SCENE, scene->surface_count + 1, sizeof *name_of, "daylight");
    vec3 *v = rad_alloc(ctx, RAD_MEM_SCENE, biggest, sizeof *v, "daylight: polygon");
    uint32_t *tri = rad_alloc(ctx, RAD_MEM_SCENE, 3 * biggest, sizeof *tri, "daylight: triangles");
    void *scratch = rad_alloc(ctx, RAD_MEM_SCENE, 1, RAD_TRIANGULATE_SCRATCH(biggest), "daylight: scratch");
    rad_result r = RAD_OK;
    if (!d->openings || !d->opening_names || !name_of || !v || !tri || !scratch)
        r = RAD_ERROR_OUT_OF_MEMORY;
    for (size_t s = 0; r == RAD_OK && s < scene->surface_count; s++)
        name_of[s] = UINT32_MAX;
    for (size_t k = 0; r == RAD_OK && k < before_names; k++) {
        d->opening_names[k] = rad_strdup(ctx, RAD_MEM_SCENE, before->opening_names[k], "daylight: opening name");
        if (!d->opening_names[k])
            r = RAD_ERROR_OUT_OF_MEMORY;
        else
            d->opening_name_count++;
    }
    if (r == RAD_OK && before_pieces > 0) {
        memcpy(d->openings, before->openings, before_pieces * sizeof *d->openings);
        d->opening_count = before_pieces;
    }
    for (size_t p = 0; r == RAD_OK && p < scene->polygon_count; p++) {
        if (!d->marked[p])
            continue;
        const rad_polygon *poly = &scene->polygons[p];
        uint32_t surface = poly->surface;
        if (name_of[surface] == UINT32_MAX) {
            char *copy = rad_strdup(ctx, RAD_MEM_SCENE, scene->surfaces[surface].name, "daylight: opening name");
            if (!copy) {
                r = RAD_ERROR_OUT_OF_MEMORY;
                break;
            }
            name_of[surface] = (uint32_t)d->opening_name_count;
            d->opening_names[d->opening_name_count++] = copy;
        }
        size_t n = poly->vertex_count;
        for (size_t k = 0; k < n; k++)
            v[k] = scene->positions[scene->indices[poly->first_index + k]];
        rad_opening o = {.normal = poly->normal, .surface = name_of[surface]};
        if (n == 3 || (n == 4 && convex_quad(v, poly->normal))) {
            memcpy(o.corner, v, n * sizeof *v);
            o.corner_count = (uint32_t)n;
            o.area = poly->area;
            d->openings[d->opening_count++] = o;
            continue;
        }
        size_t t = rad_triangulate_polygon(NULL, v, n, poly->normal, scratch, tri);
        if (t == 0 || t == RAD_TRIANGULATE_INTERRUPTED) {
            r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s: the opening '%s' has a polygon that is not simple",
                         d->source, scene->surfaces[surface].name);
            break;
        }
        for (size_t k = 0; k < t; k++) {
            for (int c = 0; c < 3; c++)
                o.corner[c] = v[tri[3 * k + (size_t)c]];
            o.corner_count = 3;
            o.area = 0.5 * v3_length(v3_cross(v3_sub(o.corner[1], o.corner[0]), v3_sub(o.corner[2], o.corner[0])));
            d->openings[d->opening_count++] = o;
        }
    }
    rad_free(name_of);
    rad_free(v);
    rad_free(tri);
    rad_free(scratch);
    return r;
}

rad_result rad_scene_attach_daylight(rad_context *ctx, rad_scene *scene, rad_daylight *d, const char *path)
{
    rad_result r = collect_openings(ctx, scene, d);
    size_t kept = 0;
    for (size_t p = 0; p < scene->polygon_count; p++)
        kept += !d->marked[p];
    if (r == RAD_OK && kept == 0)
        r = rad_fail(ctx, RAD_ERROR_INVALID_SCENE, "%s: openings: every polygon of the scene %s is an opening: "
                     "nothing would be left", d->source, scene->source ? scene->source : "");
    rad_polygon *polygons = NULL;
    rad_surface *surfaces = NULL;
    uint32_t *renumber = NULL, *material_renumber = NULL;
    char **inputs = NULL;
    if (r == RAD_OK) {
        polygons = rad_alloc(ctx, RAD_MEM_SCENE, kept, sizeof *polygons, "scene: polygons");
        surfaces = rad_alloc(ctx, RAD_MEM_SCENE, scene->surface_count, sizeof *surfaces, "scene: surfaces");
        renumber = rad_alloc(ctx, RAD_MEM_SCENE, scene->surface_count, sizeof *renumber, "scene: surfaces");
        inputs = rad_alloc(ctx, RAD_MEM_SCENE, scene->input_count + 1, sizeof *inputs, "scene: inputs");
        material_renumber = rad_alloc(ctx, RAD_MEM_SCENE, scene->material_count + 1, sizeof *material_renumber,
                                      "scene: materials");
        if (!polygons || !surfaces || !renumber || !inputs || !material_renumber)
            r = RAD_ERROR_OUT_OF_MEMORY;
    }
    char *input = NULL;
    if (r == RAD_OK && path && !(input = rad_strdup(ctx, RAD_MEM_SCENE, path, "scene: input")))
        r = RAD_ERROR_OUT_OF_MEMORY;
    if (r != RAD_OK) {
        rad_free(polygons);
        rad_free(surfaces);
        rad_free(renumber);
        rad_free(material_renumber);
        rad_free(inputs);
        rad_daylight_free(d);
        return r;
    }
    /* Nothing fails from here on. */
    for (size_t s = 0; s < scene->surface_count; s++)
        renumber[s] = 0;
    for (size_t p = 0; p < scene->polygon_count; p++)
        if (!d->marked[p])
            renumber[scene->polygons[p].surface] = 1;
    size_t surface_count = 0;
    for (size_t s = 0; s < scene->surface_count; s++) {
        if (!renumber[s]) {
            rad_free(scene->surfaces[s].name);
            renumber[s] = UINT32_MAX;
            continue;
        }
        surfaces[surface_count] = scene->surfaces[s];
        surfaces[surface_count].area = 0.0;
        renumber[s] = (uint32_t)surface_count++;
    }
    for (size_t s = 0; s < surface_count; s++)
        if (surfaces[s].mask) {
            uint32_t base = renumber[surfaces[s].mask_base];
            surfaces[s].mask = base != UINT32_MAX;
            surfaces[s].mask_base = base != UINT32_MAX ? base : 0;
        }
    size_t m = 0;
    vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t p = 0; p < scene->polygon_count; p++) {
        if (d->marked[p])
            continue;
        rad_polygon poly = scene->polygons[p];
        poly.surface = renumber[poly.surface];
        surfaces[poly.surface].area += poly.area;
        for (uint32_t k = 0; k < poly.vertex_count; k++) {
            vec3 x = scene->positions[scene->indices[poly.first_index + k]];
            lo = v3_min(lo, x);
            hi = v3_max(hi, x);
        }
        polygons[m++] = poly;
    }
    /* Materials only the openings used go too, as the scene builder drops
     * unused ones: the scene is the one its file without the openings would
     * make (a solution file rebuilds it so, and checks its checksum). */
    for (size_t k = 0; k < scene->material_count; k++)
        material_renumber[k] = 0;
    for (size_t p = 0; p < m; p++)
        material_renumber[polygons[p].material] = 1;
    size_t material_count = 0;
    for (size_t k = 0; k < scene->material_count; k++) {
        if (!material_renumber[k]) {
            rad_free(scene->materials[k].name);
            continue;
        }
        scene->materials[material_count] = scene->materials[k];
        material_renumber[k] = (uint32_t)material_count++;
    }
    for (size_t p = 0; p < m; p++)
        polygons[p].material = material_renumber[polygons[p].material];
    scene->material_count = material_count;
    rad_free(material_renumber);
    rad_free(scene->polygons);
    rad_free(scene->surfaces);
    scene->polygons = polygons;
    scene->polygon_count = m;
    scene->surfaces = surfaces;
    scene->surface_count = surface_count;
    scene->bounds_min = lo;
    scene->bounds_max = hi;
    for (size_t k = 0; k < scene->input_count; k++)
        inputs[k] = scene->inputs[k];
    size_t input_count = scene->input_count;
    if (input)
        inputs[input_count++] = input;
    rad_free(scene->inputs);
    scene->inputs = inputs;
    scene->input_count = input_count;
    rad_free(renumber);
    rad_free(d->marked);
    d->marked = NULL;
    d->marked_count = 0;
    rad_daylight_free(scene->daylight);
    scene->daylight = d;
    return RAD_OK;
}

/* ---- the public calls (radiosity.h "Daylight"): read, scale the sky
 * (sky.c), move the openings out of the scene ---- */

rad_result rad_scene_daylight_load_memory(rad_context *ctx, rad_scene *scene, const char *name, const void *data,
                                          size_t size)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !name || (!data && size > 0))
        return rad_null_argument(ctx, __func__);
    rad_daylight *d = NULL;
    rad_result r = rad_daylight_parse(ctx, scene, name, data ? (const char *)data : "", size, &d);
    if (r != RAD_OK)
        return r;
    rad_sky_prepare(d);
    return rad_scene_attach_daylight(ctx, scene, d, NULL);
}

rad_result rad_scene_daylight_load_file(rad_context *ctx, rad_scene *scene, const char *path)
{
    rad_api_enter(ctx);
    if (!ctx || !scene || !path)
        return rad_null_argument(ctx, __func__);
    unsigned char *data = NULL;
    size_t size = 0;
    rad_result r = rad_read_whole_file(ctx, path, &data, &size);
    rad_daylight *d = NULL;
    if (r == RAD_OK)
        r = rad_daylight_parse(ctx, scene, path, (const char *)data, size, &d);
    rad_free(data);
    if (r != RAD_OK)
        return r;
    rad_sky_prepare(d);
    return rad_scene_attach_daylight(ctx, scene, d, path);
}

double rad_scene_daylight_sky_illuminance(const rad_scene *scene)
{
    return scene && scene->daylight ? RAD_LUMINOUS_EFFICACY * scene->daylight->sky.horizontal : 0.0;
}

size_t rad_scene_daylight_opening_count(const rad_scene *scene)
{
    return scene && scene->daylight ? scene->daylight->opening_name_count : 0;
}
