/*
 * progressive.c -- the solver on a worker thread, its picture handed to the
 * window while it works (progressive refinement: Cohen, Chen, Wallace,
 * Greenberg 1988, "A progressive refinement approach to fast radiosity
 * image generation").
 *
 *   worker thread                           window thread (frame loop)
 *   rad_solution_solve                      every frame:
 *     on_step (after a shot / sweep)          rv_progress_take: lock, copy
 *       display values -> private arrays        the snapshot if newer, unlock
 *       lock, copy to the snapshot, unlock    upload (glBufferSubData), draw
 *       while paused: wait on the condition
 *       return stop
 *
 * The mutex is held only for the copies, never across a solver step, so
 * the frame loop never waits for the solver.  The worker has its own
 * rad_context (a context serves one thread at a time).  Stopping returns
 * RAD_STEP_FINISH from the next step: the iterate becomes the solution
 * (solved, not converged), which saves and exports; a solver that reports
 * no steps yet is cancelled instead (interrupted).
 *
 * The mesh may change during the solve (the hierarchical solver's leaves
 * after each refinement round, adaptive subdivision): the worker notices
 * it by the element and vertex counts (a refinement only adds elements),
 * copies the new mesh (rv_mesh: positions and element corners, whence the
 * triangles and the wireframe's edges) outside the lock and swaps it into
 * the snapshot with the values, counting a mesh generation.  The frame
 * loop then takes the mesh and rebuilds its buffers (rv_progress_take_mesh);
 * otherwise it uploads only colours.
 */
#include "viewer.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <time.h>

struct rv_progress {
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    rad_context *ctx;               /* the worker's */
    rad_solution *solution;
    rv_step_slot *slot;
    bool ambient;                   /* under the lock */
    double interval;                /* s between snapshots */
    size_t elements, vertices;      /* the worker's: of the mesh last published */
    /* the worker's own arrays */
    double *work_element, *work_vertex;
    double last_publish;            /* s, monotonic */
    double publish_cost;            /* s the last snapshot took */
    /* under the lock */
    double *snap_element, *snap_vertex;
    rv_mesh snap_mesh;              /* the mesh of generation status.mesh_generation > 0 */
    size_t snap_elements, snap_vertices;
    uint64_t taken_mesh;            /* the mesh generation the frame loop holds */
    rv_status status;
    bool pause, stop;
    bool steps_seen;                /* on_step has been called: it can end the solve */
    char message[512];
};

int rv_step_forward(void *user, rad_solution *solution, const rad_solve_step *step)
{
    const rv_step_slot *slot = user;
    return slot && slot->fn ? slot->fn(slot->user, solution, step) : 0;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A new mesh for the worker: its copy and arrays of its size, made
 * outside the lock.  False when out of memory (nothing changed). */
typedef struct new_mesh {
    rv_mesh mesh;
    double *work_element, *work_vertex, *snap_element, *snap_vertex;
} new_mesh;

static void new_mesh_free(new_mesh *m)
{
    rv_mesh_free(&m->mesh);
    free(m->work_element);
    free(m->work_vertex);
    free(m->snap_element);
    free(m->snap_vertex);
}

static bool new_mesh_make(const rad_solution *solution, new_mesh *m)
{
    *m = (new_mesh){0};
    size_t ne = rad_solution_element_count(solution), nv = rad_solution_vertex_count(solution);
    ne = ne ? ne : 1;
    nv = nv ? nv : 1;
    m->work_element = malloc(3 * ne * sizeof *m->work_element);
    m->work_vertex = malloc(3 * nv * sizeof *m->work_vertex);
    m->snap_element = malloc(3 * ne * sizeof *m->snap_element);
    m->snap_vertex = malloc(3 * nv * sizeof *m->snap_vertex);
    if (!m->work_element || !m->work_vertex || !m->snap_element || !m->snap_vertex ||
        !rv_mesh_from_solution(solution, &m->mesh)) {
        new_mesh_free(m);
        return false;
    }
    return true;
}

/* Copy the worker's arrays into the snapshot, with the mesh when it
 * changed. */
static void publish(rv_progress *p, const rad_solve_step *step)
{
    double start = now();
    size_t links = rad_solution_link_count(p->solution);
    bool changed = rad_solution_element_count(p->solution) != p->elements ||
                   rad_solution_vertex_count(p->solution) != p->vertices;
    pthread_mutex_lock(&p->lock);
    bool ambient = p->ambient;
    pthread_mutex_unlock(&p->lock);
    new_mesh fresh = {0};
    bool computed;
    if (changed) {
        /* the new mesh's values into its own arrays; the worker's swapped
         * for them (they are its own: no lock) once they are complete */
        computed = new_mesh_make(p->solution, &fresh) &&
                   rad_solution_display_radiosity(p->ctx, p->solution, ambient, fresh.work_element,
                                                  fresh.work_vertex) == RAD_OK;
        if (computed) {
            double *we = p->work_element, *wv = p->work_vertex;
            p->work_element = fresh.work_element;
            p->work_vertex = fresh.work_vertex;
            fresh.work_element = we;
            fresh.work_vertex = wv;
            p->elements = fresh.mesh.elements;
            p->vertices = fresh.mesh.vertices;
        }
    } else {
        computed = rad_solution_display_radiosity(p->ctx, p->solution, ambient, p->work_element,
                                                  p->work_vertex) == RAD_OK;
    }
    pthread_mutex_lock(&p->lock);
    if (changed && computed) {
        /* the new mesh and arrays of its size into the snapshot; the old
         * ones go back in `fresh`, freed after the lock */
        rv_mesh old = p->snap_mesh;
        double *se = p->snap_element, *sv = p->snap_vertex;
        p->snap_mesh = fresh.mesh;
        p->snap_element = fresh.snap_element;
        p->snap_vertex = fresh.snap_vertex;
        p->snap_elements = p->elements;
        p->snap_vertices = p->vertices;
        fresh.mesh = old;
        fresh.snap_element = se;
        fresh.snap_vertex = sv;
        p->status.mesh_generation++;
        p->status.elements = p->elements;
    }
    if (computed) {
        memcpy(p->snap_element, p->work_element, 3 * p->elements * sizeof *p->snap_element);
        memcpy(p->snap_vertex, p->work_vertex, 3 * p->vertices * sizeof *p->snap_vertex);
        p->status.generation++;
    }
    p->status.links = links;
    if (step)
        p->status.step = *step;
    pthread_mutex_unlock(&p->lock);
    new_mesh_free(&fresh);
    p->last_publish = now();
    p->publish_cost = p->last_publish - start;
}

static int on_step(void *user, rad_solution *solution, const rad_solve_step *step)
{
    rv_progress *p = user;
    (void)solution;
    pthread_mutex_lock(&p->lock);
    bool pausing = p->pause, stopping = p->stop;
    pthread_mutex_unlock(&p->lock);
    /* A snapshot costs O(elements) (the vertex values: 0.5 s at 10^6
     * elements, docs/viewer.md): with an interval, at most a tenth of the
     * worker's time goes to them. */
    double wait = p->interval > 0.0 ? fmax(p->interval, 9.0 * p->publish_cost) : 0.0;
    if (pausing || stopping || now() - p->last_publish >= wait)
        publish(p, step);
    pthread_mutex_lock(&p->lock);
    p->status.step = *step;
    while (p->pause && !p->stop) {
        p->status.paused = true;
        pthread_cond_wait(&p->wake, &p->lock);
    }
    p->status.paused = false;
    p->steps_seen = true;
    bool stop = p->stop;
    pthread_mutex_unlock(&p->lock);
    return stop ? RAD_STEP_FINISH : 0; /* the iterate becomes the solution */
}

static void *worker(void *user)
{
    rv_progress *p = user;
    rad_result r = rad_solution_solve(p->ctx, p->solution);
    rad_context_cancel(p->ctx, false); /* the display values below must not be refused */
    if (r != RAD_OK && r != RAD_ERROR_INTERRUPTED) {
        pthread_mutex_lock(&p->lock);
        snprintf(p->message, sizeof p->message, "%s", rad_context_error(p->ctx));
        pthread_mutex_unlock(&p->lock);
    } else {
        size_t count = 0;
        const rad_solve_step *history = rad_solution_history(p->solution, &count);
        publish(p, count ? &history[count - 1] : NULL);
    }
    pthread_mutex_lock(&p->lock);
    p->status.done = true;
    p->status.result = r;
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

static void progress_free(rv_progress *p)
{
    rad_context_destroy(p->ctx);
    free(p->work_element);
    free(p->work_vertex);
    free(p->snap_element);
    free(p->snap_vertex);
    rv_mesh_free(&p->snap_mesh);
    free(p);
}

rv_progress *rv_progress_start(rad_solution *solution, rv_step_slot *slot, int threads, bool ambient,
                               double interval, bool paused)
{
    rv_progress *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->solution = solution;
    p->slot = slot;
    p->ambient = ambient;
    p->interval = interval;
    p->pause = paused;
    p->elements = rad_solution_element_count(solution);
    p->vertices = rad_solution_vertex_count(solution);
    p->snap_elements = p->elements;
    p->snap_vertices = p->vertices;
    size_t ne = p->elements ? p->elements : 1, nv = p->vertices ? p->vertices : 1;
    p->work_element = malloc(3 * ne * sizeof *p->work_element);
    p->work_vertex = malloc(3 * nv * sizeof *p->work_vertex);
    p->snap_element = malloc(3 * ne * sizeof *p->snap_element);
    p->snap_vertex = malloc(3 * nv * sizeof *p->snap_vertex);
    rad_context_options co = {.threads = threads};
    if (!p->work_element || !p->work_vertex || !p->snap_element || !p->snap_vertex ||
        rad_context_create(&co, &p->ctx) != RAD_OK) {
        progress_free(p);
        return NULL;
    }
    p->status.elements = p->elements;
    p->status.step.residual = NAN;
    p->status.step.unshot = NAN;
    /* Set before the thread starts (pthread_create orders it), cleared
     * after it is joined. */
    slot->fn = on_step;
    slot->user = p;
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    p->last_publish = now();
    if (pthread_create(&p->thread, NULL, worker, p) != 0) {
        *slot = (rv_step_slot){NULL, NULL};
        pthread_mutex_destroy(&p->lock);
        pthread_cond_destroy(&p->wake);
        progress_free(p);
        return NULL;
    }
    return p;
}

bool rv_progress_take(rv_progress *p, uint64_t *generation, double *element_rgb, double *vertex_rgb,
                      rv_status *status)
{
    pthread_mutex_lock(&p->lock);
    bool newer = p->status.generation > *generation && p->status.mesh_generation == p->taken_mesh;
    if (newer) {
        if (element_rgb)
            memcpy(element_rgb, p->snap_element, 3 * p->snap_elements * sizeof *element_rgb);
        if (vertex_rgb)
            memcpy(vertex_rgb, p->snap_vertex, 3 * p->snap_vertices * sizeof *vertex_rgb);
        *generation = p->status.generation;
    }
    if (status)
        *status = p->status;
    pthread_mutex_unlock(&p->lock);
    return newer;
}

/* A copy of `m`; false when out of memory. */
static bool mesh_copy(const rv_mesh *m, rv_mesh *out)
{
    size_t nv = m->vertices ? m->vertices : 1, ne = m->elements ? m->elements : 1;
    rv_mesh c = {m->vertices, m->elements, malloc(3 * nv * sizeof *c.position), malloc(4 * ne * sizeof *c.corner),
                 malloc(ne)};
    if (!c.position || !c.corner || !c.corners) {
        rv_mesh_free(&c);
        return false;
    }
    memcpy(c.position, m->position, 3 * nv * sizeof *c.position);
    memcpy(c.corner, m->corner, 4 * ne * sizeof *c.corner);
    memcpy(c.corners, m->corners, ne);
    *out = c;
    return true;
}

bool rv_progress_take_mesh(rv_progress *p, uint64_t *generation, rv_mesh *mesh, double **element_rgb,
                           double **vertex_rgb)
{
    pthread_mutex_lock(&p->lock);
    bool newer = p->status.mesh_generation != p->taken_mesh;
    size_t ne = p->snap_elements ? p->snap_elements : 1, nv = p->snap_vertices ? p->snap_vertices : 1;
    rv_mesh copy = {0};
    double *e = NULL, *v = NULL;
    /* Copied under the lock: it happens once per mesh (a refinement round). */
    if (newer) {
        e = malloc(3 * ne * sizeof *e);
        v = malloc(3 * nv * sizeof *v);
        newer = e && v && mesh_copy(&p->snap_mesh, &copy);
    }
    if (newer) {
        memcpy(e, p->snap_element, 3 * ne * sizeof *e);
        memcpy(v, p->snap_vertex, 3 * nv * sizeof *v);
        *generation = p->status.generation;
        p->taken_mesh = p->status.mesh_generation;
    }
    pthread_mutex_unlock(&p->lock);
    if (!newer) {
        free(e);
        free(v);
        return false;
    }
    rv_mesh_free(mesh);
    *mesh = copy;
    free(*element_rgb);
    free(*vertex_rgb);
    *element_rgb = e;
    *vertex_rgb = v;
    return true;
}

void rv_progress_pause(rv_progress *p, bool pause)
{
    pthread_mutex_lock(&p->lock);
    p->pause = pause;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
}

void rv_progress_ambient(rv_progress *p, bool ambient)
{
    pthread_mutex_lock(&p->lock);
    p->ambient = ambient;
    pthread_mutex_unlock(&p->lock);
}

void rv_progress_stop(rv_progress *p)
{
    pthread_mutex_lock(&p->lock);
    p->stop = true;
    bool steps = p->steps_seen;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    /* A solver that has not reached its first step (the hierarchical
     * solver's first refinement round, the dense solvers' form factors) is
     * cancelled instead: interrupted, its iterate kept for display
     * and export but not a solution to save.  Any thread may raise it. */
    if (!steps)
        rad_context_cancel(p->ctx, true);
}

rad_result rv_progress_finish(rv_progress *p, char *message, size_t message_size)
{
    pthread_join(p->thread, NULL);
    rad_result r = p->status.result;
    if (message)
        snprintf(message, message_size, "%s", p->message);
    *p->slot = (rv_step_slot){NULL, NULL};
    pthread_mutex_destroy(&p->lock);
    pthread_cond_destroy(&p->wake);
    progress_free(p);
    return r;
}
