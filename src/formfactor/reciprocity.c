/*
 * reciprocity.c -- the default step after a sampled method: reciprocity
 * and closure restored, so that the radiosity solution conserves energy.
 *
 * Why.  With B = E + rho F B, the absorbed power is
 *
 *     sum_i A_i (1 - rho_i) H_i  =  sum_i A_i E_i  +  sum_j A_j B_j (c_j - 1)
 *
 * where c_j = sum_i A_i F_ij / A_j is a column's weight: when F is
 * reciprocal (A_i F_ij = A_j F_ji) it is row j's sum, so absorbed +
 * escaped = emitted holds exactly when rows sum to their closure (1 in a
 * closed scene) and escaped >= 0 when they sum to at most 1.  Sampled
 * factors break both: a hemicube or a ray count estimates A_i F_ij and
 * A_j F_ji separately, and Monte Carlo's rows carry the noise of every
 * pair in them; energy then drifts by rho / (1 - rho) times the row
 * error, with rows noisiest where B is highest.
 *
 * Step 1, reciprocity (row methods: hemicube, hemisphere).  The two
 * estimates of the power coupling G_ij = A_i F_ij ~= A_j F_ji are
 * combined, each weighted by its element's samples per unit area
 * (rad_ff_method.density):
 *
 *     G_ij = (w_i A_i F_ij + w_j A_j F_ji) / (w_i + w_j)
 *
 * For ray counts var(A_i F_ij) ~= A_i G_ij / N_i, so w_i = N_i / A_i is
 * the inverse-variance weight, and it depends on no estimate (weights
 * that did would bias the mean).  Variances combine as
 * (w_i^2 A_i^2 var_ij + w_j^2 A_j^2 var_ji) / (w_i + w_j)^2.
 *
 * Step 2, closure.  Each row is rescaled toward its closure t_i, the
 * fraction of the light leaving element i that meets the front of some
 * element, keeping reciprocity: x > 0 with x_i sum_j G_ij x_j = A_i t_i
 * (symmetric Sinkhorn scaling, Knight 2008, as rad_ff_close), then
 * F_ij <- x_i x_j F_ij.  Row methods measure t_i themselves (their raw
 * row sums: pixels or rays that met a front).  Monte Carlo is measured
 * here by cosine-distributed rays from each element (CLOSURE_RAYS),
 * combined with its own row sum s_i by their variances
 *
 *     t_i = (r_i / var r_i + s_i / var s_i) / (1 / var r_i + 1 / var s_i),
 *     var r_i = r_i (1 - r_i) / K,   var s_i = sum_j var F_ij
 *
 * so a closed element (every ray meets a front: r_i = 1, var 0) is held
 * to exactly 1, and an open one keeps mostly its own, usually better, sum.
 * In an open scene the t_i need not be consistent with one reciprocal G
 * (two facing squares: A_1 t_1 = A_2 t_2 only up to noise); the scaling
 * then settles between them, within the noise.  Last, every row above 1
 * (rounding, or that compromise) is scaled down to 1.
 *
 * rad_options.raw_form_factors turns the step off.
 */
#include "formfactor/formfactor.h"

#include <string.h>

enum { CLOSURE_RAYS = 256, BLOCK = 64 };

/* Per element: the fraction of CLOSURE_RAYS cosine-distributed rays from
 * stratified points of it that first meet the front of an element, into
 * closure[].  Keyed on (seed, element): thread-count independent. */
static rad_result closure_rays(rad_context *ctx, const rad_ff_request *req, double *closure)
{
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    const int side = 16; /* CLOSURE_RAYS = side^2 strata of the disk */
    double eps = rad_vis_epsilon(mesh);
    volatile int stop = 0;
#pragma omp parallel for schedule(dynamic, 16) num_threads(ctx->threads > 0 ? ctx->threads : 1)
    for (size_t i = 0; i < n; i++) {
        closure[i] = 0.0;
        if (stop)
            continue;
        const rad_element *e = &mesh->elements[i];
        double lift = eps + rad_element_bend(mesh, e);
        rad_rng rng = rad_rng_keyed(req->seed ^ 0x436c6f73757265ULL, i, 1); /* "Closure" */
        rad_ray ray[BLOCK];
        rad_hit hit[BLOCK];
        int met = 0;
        for (int first = 0; first < CLOSURE_RAYS; first += BLOCK) {
            rad_element_cosine_rays(mesh, e, lift, side, first, BLOCK, &rng, ray);
            req->vis->backend->intersect(req->vis->state, ray, BLOCK, hit);
            for (int k = 0; k < BLOCK; k++)
                met += isfinite(hit[k].t) && v3_dot(ray[k].direction, mesh->patches[hit[k].patch].normal) < 0.0;
        }
        closure[i] = (double)met / CLOSURE_RAYS;
        if (rad_cancelled(ctx))
            stop = 1;
    }
    if (stop)
        return rad_fail(ctx, RAD_ERROR_INTERRUPTED, "form factors: interrupted");
    return RAD_OK;
}

/* Step 1: A_i F_ij and A_j F_ji combined with weights density[i], [j]. */
static void symmetrize(const rad_mesh *mesh, const double *density, double *F, double *var)
{
    size_t n = mesh->element_count;
    for (size_t i = 0; i < n; i++) {
        double ai = mesh->elements[i].area, wi = density[i];
        for (size_t j = i + 1; j < n; j++) {
            double aj = mesh->elements[j].area, wj = density[j], w = wi + wj;
            if (!(w > 0.0))
                continue;
            double g = (wi * ai * F[i * n + j] + wj * aj * F[j * n + i]) / w;
            F[i * n + j] = (g / ai);
            F[j * n + i] = (g / aj);
            if (var) {
                double v = (wi * wi * ai * ai * var[i * n + j] + wj * wj * aj * aj * var[j * n + i]) / (w * w);
                var[i * n + j] = (v / (ai * ai));
                var[j * n + i] = (v / (aj * aj));
            }
        }
    }
}

rad_result rad_ff_balance(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                          const void *shared, double *F_rows, double *var_rows, rad_ff_stats *stats)
{
    double *F = F_rows, *var = var_rows;
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    double *work = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 4 * n, sizeof *work, "form factors: reciprocity");
    if (!work)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *target = work, *x = work + n, *row = work + 2 * n, *density = work + 3 * n;
    /* The raw rows: their sums (a row method's measured closure), and
     * their variance (sum of the pairs'). */
    double raw_max = 0.0;
    for (size_t i = 0; i < n; i++) {
        double s = 0.0, v = 0.0;
        for (size_t j = 0; j < n; j++) {
            s += F[i * n + j];
            v += var ? var[i * n + j] : 0.0;
        }
        target[i] = s;
        row[i] = v;
        raw_max = fmax(raw_max, s);
    }
    stats->raw_row_sum_max = raw_max;
    if (method->density) {
        for (size_t i = 0; i < n; i++)
            density[i] = method->density(req, shared, (uint32_t)i);
        symmetrize(mesh, density, F, var);
    } else if (req->vis) {
        /* Measured closure r_i, combined with the row's own sum s_i. */
        rad_result r = closure_rays(ctx, req, density);
        if (r != RAD_OK) {
            rad_free(work);
            return r;
        }
        for (size_t i = 0; i < n; i++) {
            double r_i = density[i], var_r = r_i * (1.0 - r_i) / CLOSURE_RAYS, s_i = target[i], var_s = row[i];
            if (!(var_r > 0.0))
                target[i] = r_i;
            else if (var && var_s > 0.0)
                target[i] = (r_i / var_r + s_i / var_s) / (1.0 / var_r + 1.0 / var_s);
        }
    }
    /* Step 2: x_i sum_j G_ij x_j = A_i t_i, by the symmetric Sinkhorn
     * iteration x_i <- sqrt(x_i A_i t_i / sum_j G_ij x_j).  Until the worst
     * row is right to 1e-7 (far below the sampling noise), or while it still
     * improves (inconsistent targets of an open scene stall it). */
    for (size_t i = 0; i < n; i++) {
        target[i] = fmin(target[i], 1.0);
        x[i] = 1.0;
    }
    double previous = INFINITY;
    for (int it = 0; it < 200; it++) {
        double worst = 0.0;
        for (size_t i = 0; i < n; i++) {
            double s = 0.0;
            for (size_t j = 0; j < n; j++)
                s += (double)F[i * n + j] * x[j];
            row[i] = s;
        }
        for (size_t i = 0; i < n; i++) {
            if (!(row[i] > 0.0 && target[i] > 0.0))
                continue; /* sees nothing: stays as it is */
            worst = fmax(worst, fabs(row[i] * x[i] / target[i] - 1.0));
            x[i] = sqrt(x[i] * target[i] / row[i]);
        }
        if (worst < 1e-7 || (it >= 20 && worst > 0.99 * previous))
            break;
        previous = worst;
    }
    /* No row above 1: each row over it scaled down by its excess, all
     * at once (scaling x_i down only lowers the other rows). */
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (size_t j = 0; j < n; j++)
            s += (double)F[i * n + j] * x[i] * x[j];
        row[i] = s;
    }
    stats->closure_scale_min = INFINITY;
    stats->closure_scale_max = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (row[i] > 1.0)
            x[i] /= row[i];
        stats->closure_scale_min = fmin(stats->closure_scale_min, x[i]);
        stats->closure_scale_max = fmax(stats->closure_scale_max, x[i]);
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            double scale = x[i] * x[j];
            F[i * n + j] = (F[i * n + j] * scale);
            if (var)
                var[i * n + j] = (var[i * n + j] * scale * scale);
        }
    if (n == 0)
        stats->closure_scale_min = stats->closure_scale_max = 1.0;
    stats->balanced = true;
    rad_free(work);
    return RAD_OK;
}
