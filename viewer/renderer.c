/*
 * renderer.c -- the viewer's OpenGL 3.3 core renderer, shared by the
 * window and the off-screen frames.
 *
 *   vertex buffer   welded vertices: position (float, relative to the
 *                   scene's centre) and radiance L = B / pi (smooth shading)
 *   index buffers   triangles (a quad as 0-1-2, 0-2-3) and element edges
 *   texture buffers per element radiance (flat shading) and, per triangle,
 *                   its element: the fragment shader fetches
 *                   element_radiance[triangle_element[gl_PrimitiveID]]
 *
 * A colour update rewrites the two radiance buffers (glBufferSubData), the
 * geometry stays.  The fragment shader draws the back of a surface black,
 * as the ray caster does (surfaces are one-sided), and outputs either the
 * radiance itself (read back as float: the same numbers as
 * rad_solution_render's image) or a display colour: radiance times the
 * exposure through the sRGB curve (src/output/image.c's rule), or false
 * colour.  Smooth shading interpolates the vertex values linearly over
 * each triangle; the ray caster interpolates a quad bilinearly, which
 * differs inside quads that are not parallelograms (docs/viewer.md).
 */
#include "viewer.h"

#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct rv_renderer {
    GLuint program, vao, vertex_buffer, radiance_buffer, triangle_buffer, edge_buffer;
    GLuint element_buffer, element_texture, triangle_element_buffer, triangle_element_texture;
    GLint u_matrix, u_shading, u_output, u_exposure, u_false_range, u_wire;
    size_t vertices, elements, triangles, edges;
    double centre[3], radius;   /* bounding sphere, m */
    float *scratch;             /* 4 floats per element or vertex, whichever more */
};

static const char *VERTEX_SHADER =
    "#version 330 core\n"
    "layout(location = 0) in vec3 position;\n"
    "layout(location = 1) in vec3 radiance;\n"
    "uniform mat4 view_projection;\n"
    "out vec3 v_radiance;\n"
    "void main() {\n"
    "    v_radiance = radiance;\n"
    "    gl_Position = view_projection * vec4(position, 1.0);\n"
    "}\n";

/* False colour: log10 of the luminance (Rec. 709 Y of L, cd/m^2 for
 * W/(m^2 sr) read photometrically as the renderer's exposure does) over
 * [lo, hi] on a blue - cyan - green - yellow - red ramp; black is 0. */
static const char *FRAGMENT_SHADER =
    "#version 330 core\n"
    "in vec3 v_radiance;\n"
    "uniform int shading;\n"
    "uniform int output_kind;\n"
    "uniform float exposure;\n"
    "uniform vec2 false_range;\n"
    "uniform int wire;\n"
    "uniform samplerBuffer element_radiance;\n"
    "uniform usamplerBuffer triangle_element;\n"
    "out vec4 colour;\n"
    "float srgb(float x) {\n"
    "    x = clamp(x, 0.0, 1.0);\n"
    "    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;\n"
    "}\n"
    "vec3 ramp(float t) {\n"
    "    t = clamp(t, 0.0, 1.0) * 4.0;\n"
    "    if (t < 1.0) return vec3(0.0, t, 1.0);\n"
    "    if (t < 2.0) return vec3(0.0, 1.0, 2.0 - t);\n"
    "    if (t < 3.0) return vec3(t - 2.0, 1.0, 0.0);\n"
    "    return vec3(1.0, 4.0 - t, 0.0);\n"
    "}\n"
    "void main() {\n"
    "    if (wire != 0) { colour = vec4(1.0, 0.55, 0.0, 1.0); return; }\n"
    "    vec3 L = vec3(0.0);\n"
    "    if (gl_FrontFacing) {\n"
    "        if (shading == 1)\n"
    "            L = texelFetch(element_radiance, int(texelFetch(triangle_element, gl_PrimitiveID).r)).rgb;\n"
    "        else\n"
    "            L = v_radiance;\n"
    "    }\n"
    "    if (output_kind == 0) { colour = vec4(L, 1.0); return; }\n"
    "    if (output_kind == 2) {\n"
    "        float Y = dot(L, vec3(0.2126, 0.7152, 0.0722));\n"
    "        colour = Y > 0.0 ? vec4(ramp((log(Y) / log(10.0) - false_range.x) /\n"
    "                                     (false_range.y - false_range.x)), 1.0) : vec4(0.0, 0.0, 0.0, 1.0);\n"
    "        return;\n"
    "    }\n"
    "    colour = vec4(srgb(exposure * L.r), srgb(exposure * L.g), srgb(exposure * L.b), 1.0);\n"
    "}\n";

/* A compiled shader, or 0 with the driver's log on stderr (a driver that
 * refuses GLSL 3.30 core: no context of ours reaches here without it). */
static GLuint compile(GLenum kind, const char *source)
{
    GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, NULL);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        glGetShaderInfoLog(shader, sizeof log, NULL, log);
        fprintf(stderr, "radiosity: view: %s shader: %s\n", kind == GL_VERTEX_SHADER ? "vertex" : "fragment",
                log);
        glDeleteShader(shader);
        return 0;
    }
    return shader;
}

static GLuint link_program(void)
{
    GLuint vs = compile(GL_VERTEX_SHADER, VERTEX_SHADER);
    GLuint fs = vs ? compile(GL_FRAGMENT_SHADER, FRAGMENT_SHADER) : 0;
    if (!fs) {
        glDeleteShader(vs);
        return 0;
    }
    GLuint program = glCreateProgram();
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        glGetProgramInfoLog(program, sizeof log, NULL, log);
        fprintf(stderr, "radiosity: view: shader program: %s\n", log);
        glDeleteProgram(program);
        return 0;
    }
    return program;
}

/* Radiance L = B / pi as float, 4 per item (RGBA for the texture buffer,
 * the vertex attribute reads the first 3 of each 4). */
static void to_radiance(const double *rgb, size_t count, float *out)
{
    for (size_t i = 0; i < count; i++) {
        for (int c = 0; c < 3; c++)
            out[4 * i + (size_t)c] = (float)(rgb[3 * i + (size_t)c] / M_PI);
        out[4 * i + 3] = 1.0f;
    }
}

void rv_mesh_free(rv_mesh *m)
{
    free(m->position);
    free(m->corner);
    free(m->corners);
    *m = (rv_mesh){0};
}

bool rv_mesh_from_solution(const rad_solution *solution, rv_mesh *out)
{
    size_t nv = rad_solution_vertex_count(solution), ne = rad_solution_element_count(solution);
    rv_mesh m = {nv, ne, malloc((nv ? nv : 1) * 3 * sizeof *m.position),
                 malloc((ne ? ne : 1) * 4 * sizeof *m.corner), malloc(ne ? ne : 1)};
    if (!m.position || !m.corner || !m.corners) {
        rv_mesh_free(&m);
        *out = m;
        return false;
    }
    for (size_t v = 0; v < nv; v++)
        rad_solution_vertex_position(solution, v, &m.position[3 * v]);
    for (size_t i = 0; i < ne; i++) {
        size_t corner[4] = {0, 0, 0, 0};
        int count = rad_solution_element_vertices(solution, i, corner);
        m.corners[i] = (uint8_t)count;
        for (int k = 0; k < 4; k++)
            m.corner[4 * i + (size_t)k] = (uint32_t)corner[k];
    }
    *out = m;
    return true;
}

/* Positions, triangles, edges and triangle -> element from the mesh;
 * false when out of memory. */
static bool upload_geometry(rv_renderer *r, const rv_mesh *mesh)
{
    size_t nv = r->vertices, ne = r->elements;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < nv; v++) {
        const double *p = &mesh->position[3 * v];
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], p[k]);
            hi[k] = fmax(hi[k], p[k]);
        }
    }
    r->radius = 0.0;
    for (int k = 0; k < 3; k++) {
        r->centre[k] = nv ? 0.5 * (lo[k] + hi[k]) : 0.0;
        r->radius += nv ? 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]) : 0.0;
    }
    r->radius = sqrt(r->radius);
    if (!(r->radius > 0.0))
        r->radius = 1.0;

    float *positions = malloc((nv ? nv : 1) * 3 * sizeof *positions);
    uint32_t *triangles = malloc((ne ? ne : 1) * 6 * sizeof *triangles);
    uint32_t *edges = malloc((ne ? ne : 1) * 8 * sizeof *edges);
    uint32_t *triangle_element = malloc((ne ? ne : 1) * 2 * sizeof *triangle_element);
    bool ok = positions && triangles && edges && triangle_element;
    if (ok) {
        for (size_t v = 0; v < nv; v++)
            for (int k = 0; k < 3; k++)
                positions[3 * v + (size_t)k] = (float)(mesh->position[3 * v + (size_t)k] - r->centre[k]);
        size_t t = 0, e = 0;
        for (size_t i = 0; i < ne; i++) {
            const uint32_t *corner = &mesh->corner[4 * i];
            int count = mesh->corners[i];
            for (int k = 1; k + 1 < count; k++) {
                triangles[3 * t + 0] = (uint32_t)corner[0];
                triangles[3 * t + 1] = (uint32_t)corner[k];
                triangles[3 * t + 2] = (uint32_t)corner[k + 1];
                triangle_element[t++] = (uint32_t)i;
            }
            for (int k = 0; k < count; k++) {
                edges[e++] = (uint32_t)corner[k];
                edges[e++] = (uint32_t)corner[(k + 1) % count];
            }
        }
        r->triangles = t;
        r->edges = e / 2;
        glBindVertexArray(r->vao);
        glBindBuffer(GL_ARRAY_BUFFER, r->vertex_buffer);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof *positions), positions, GL_STATIC_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), NULL);
        glEnableVertexAttribArray(0);
        glBindBuffer(GL_ARRAY_BUFFER, r->radiance_buffer);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 4 * sizeof(float)), NULL, GL_DYNAMIC_DRAW);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 4 * sizeof(float), NULL);
        glEnableVertexAttribArray(1);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->triangle_buffer);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(t * 3 * sizeof *triangles), triangles, GL_STATIC_DRAW);
        glBindVertexArray(0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->edge_buffer);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(e * sizeof *edges), edges, GL_STATIC_DRAW);
        glBindBuffer(GL_TEXTURE_BUFFER, r->triangle_element_buffer);
        glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)(t * sizeof *triangle_element), triangle_element,
                     GL_STATIC_DRAW);
        glBindTexture(GL_TEXTURE_BUFFER, r->triangle_element_texture);
        glTexBuffer(GL_TEXTURE_BUFFER, GL_R32UI, r->triangle_element_buffer);
        glBindBuffer(GL_TEXTURE_BUFFER, r->element_buffer);
        glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)(ne * 4 * sizeof(float)), NULL, GL_DYNAMIC_DRAW);
        glBindTexture(GL_TEXTURE_BUFFER, r->element_texture);
        glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, r->element_buffer);
        glBindTexture(GL_TEXTURE_BUFFER, 0);
        glBindBuffer(GL_TEXTURE_BUFFER, 0);
    }
    free(positions);
    free(triangles);
    free(edges);
    free(triangle_element);
    return ok;
}

rv_renderer *rv_renderer_create(const rad_solution *solution, const double *element_rgb, const double *vertex_rgb)
{
    rv_mesh mesh;
    if (!rv_mesh_from_solution(solution, &mesh))
        return NULL;
    rv_renderer *r = rv_renderer_create_mesh(&mesh, element_rgb, vertex_rgb);
    rv_mesh_free(&mesh);
    return r;
}

rv_renderer *rv_renderer_create_mesh(const rv_mesh *mesh, const double *element_rgb, const double *vertex_rgb)
{
    rv_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->vertices = mesh->vertices;
    r->elements = mesh->elements;
    size_t most = r->vertices > r->elements ? r->vertices : r->elements;
    r->scratch = malloc((most ? most : 1) * 4 * sizeof *r->scratch);
    r->program = link_program();
    if (!r->scratch || !r->program) {
        rv_renderer_destroy(r);
        return NULL;
    }
    glGenVertexArrays(1, &r->vao);
    GLuint buffers[6];
    glGenBuffers(6, buffers);
    r->vertex_buffer = buffers[0];
    r->radiance_buffer = buffers[1];
    r->triangle_buffer = buffers[2];
    r->edge_buffer = buffers[3];
    r->element_buffer = buffers[4];
    r->triangle_element_buffer = buffers[5];
    GLuint textures[2];
    glGenTextures(2, textures);
    r->element_texture = textures[0];
    r->triangle_element_texture = textures[1];
    r->u_matrix = glGetUniformLocation(r->program, "view_projection");
    r->u_shading = glGetUniformLocation(r->program, "shading");
    r->u_output = glGetUniformLocation(r->program, "output_kind");
    r->u_exposure = glGetUniformLocation(r->program, "exposure");
    r->u_false_range = glGetUniformLocation(r->program, "false_range");
    r->u_wire = glGetUniformLocation(r->program, "wire");
    glUseProgram(r->program);
    glUniform1i(glGetUniformLocation(r->program, "element_radiance"), 0);
    glUniform1i(glGetUniformLocation(r->program, "triangle_element"), 1);
    glUseProgram(0);
    if (!upload_geometry(r, mesh)) {
        rv_renderer_destroy(r);
        return NULL;
    }
    rv_renderer_update(r, element_rgb, vertex_rgb);
    return r;
}

void rv_renderer_destroy(rv_renderer *r)
{
    if (!r)
        return;
    if (r->program) {
        GLuint buffers[6] = {r->vertex_buffer, r->radiance_buffer, r->triangle_buffer,
                             r->edge_buffer, r->element_buffer, r->triangle_element_buffer};
        GLuint textures[2] = {r->element_texture, r->triangle_element_texture};
        glDeleteBuffers(6, buffers);
        glDeleteTextures(2, textures);
        glDeleteVertexArrays(1, &r->vao);
        glDeleteProgram(r->program);
    }
    free(r->scratch);
    free(r);
}

void rv_renderer_update(rv_renderer *r, const double *element_rgb, const double *vertex_rgb)
{
    if (vertex_rgb && r->vertices) {
        to_radiance(vertex_rgb, r->vertices, r->scratch);
        glBindBuffer(GL_ARRAY_BUFFER, r->radiance_buffer);
        glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(r->vertices * 4 * sizeof(float)), r->scratch);
        glBindBuffer(GL_ARRAY_BUFFER, 0);
    }
    if (element_rgb && r->elements) {
        to_radiance(element_rgb, r->elements, r->scratch);
        glBindBuffer(GL_TEXTURE_BUFFER, r->element_buffer);
        glBufferSubData(GL_TEXTURE_BUFFER, 0, (GLsizeiptr)(r->elements * 4 * sizeof(float)), r->scratch);
        glBindBuffer(GL_TEXTURE_BUFFER, 0);
    }
}

void rv_renderer_draw(const rv_renderer *r, const rv_draw *d)
{
    float m[16];
    double aspect = d->height > 0 ? (double)d->width / (double)d->height : 1.0;
    rv_camera_matrix(d->camera, r->centre, r->radius, aspect, m);
    glViewport(0, 0, d->width, d->height);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_CULL_FACE);
    glUseProgram(r->program);
    glUniformMatrix4fv(r->u_matrix, 1, GL_FALSE, m);
    glUniform1i(r->u_shading, d->shading == RAD_SHADING_FLAT ? 1 : 0);
    glUniform1i(r->u_output, (GLint)d->output);
    glUniform1f(r->u_exposure, (float)d->exposure);
    glUniform2f(r->u_false_range, (float)d->false_min, (float)d->false_max);
    glUniform1i(r->u_wire, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_BUFFER, r->element_texture);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_BUFFER, r->triangle_element_texture);
    glBindVertexArray(r->vao);
    /* The surfaces pushed back a little so the edges drawn over them win
     * the depth test. */
    if (d->wireframe) {
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(1.0f, 1.0f);
    }
    glDrawElements(GL_TRIANGLES, (GLsizei)(3 * r->triangles), GL_UNSIGNED_INT, NULL);
    if (d->wireframe) {
        glDisable(GL_POLYGON_OFFSET_FILL);
        glUniform1i(r->u_wire, 1);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->edge_buffer);
        glDrawElements(GL_LINES, (GLsizei)(2 * r->edges), GL_UNSIGNED_INT, NULL);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->triangle_buffer); /* the VAO's again */
    }
    glBindVertexArray(0);
    glUseProgram(0);
}

void rv_renderer_bounds(const rv_renderer *r, double centre[3], double *radius)
{
    memcpy(centre, r->centre, sizeof r->centre);
    *radius = r->radius;
}

size_t rv_renderer_elements(const rv_renderer *r) { return r->elements; }
size_t rv_renderer_vertices(const rv_renderer *r) { return r->vertices; }
