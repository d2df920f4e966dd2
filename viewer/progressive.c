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
 * no steps (hierarchical) is cancelled instead (interrupted).  Only the display values of the
 * mesh the solve began on are published: when the mesh changes during the
 * solve (adaptive subdivision, the hierarchical solver's leaves), the
 * window shows the last values of the old mesh and rebuilds its buffers
 * when the solve ends.
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
    size_t elements, vertices;      /* of the mesh the solve began on */
    /* the worker's own arrays */
    double *work_element, *work_vertex;
    double last_publish;            /* s, monotonic */
    double publish_cost;            /* s the last snapshot took */
    /* under the lock */
    double *snap_element, *snap_vertex;
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

/* Copy the worker's arrays into the snapshot (the mesh unchanged). */
static void publish(rv_progress *p, const rad_solve_step *step)
{
    double start = now();
    bool same_mesh = rad_solution_element_count(p->solution) == p->elements &&
                     rad_solution_vertex_count(p->solution) == p->vertices;
    pthread_mutex_lock(&p->lock);
    bool ambient = p->ambient;
    pthread_mutex_unlock(&p->lock);
    bool computed = same_mesh && rad_solution_display_radiosity(p->ctx, p->solution, ambient, p->work_element,
                                                                p->work_vertex) == RAD_OK;
    pthread_mutex_lock(&p->lock);
    if (computed) {
        memcpy(p->snap_element, p->work_element, 3 * p->elements * sizeof *p->snap_element);
        memcpy(p->snap_vertex, p->work_vertex, 3 * p->vertices * sizeof *p->snap_vertex);
        p->status.generation++;
    }
    if (step)
        p->status.step = *step;
    pthread_mutex_unlock(&p->lock);
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
    p->status.elements = rad_solution_element_count(p->solution);
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
    bool newer = p->status.generation > *generation;
    if (newer) {
        if (element_rgb)
            memcpy(element_rgb, p->snap_element, 3 * p->elements * sizeof *element_rgb);
        if (vertex_rgb)
            memcpy(vertex_rgb, p->snap_vertex, 3 * p->vertices * sizeof *vertex_rgb);
        *generation = p->status.generation;
    }
    if (status)
        *status = p->status;
    pthread_mutex_unlock(&p->lock);
    return newer;
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
    /* A solver that reports no steps (hierarchical) or has not reached its
     * first is cancelled instead: interrupted, its iterate kept for display
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
