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
 * Step 2, closure.  Each row is brought to its closure t_i, the
 * fraction of the light leaving element i that meets the front of some
 * element, keeping reciprocity.  Row methods measure t_i themselves (their
 * raw row sums: pixels or rays that met a front), and their rows are
 * rescaled: x > 0 with x_i sum_j G_ij x_j = A_i t_i (symmetric Sinkhorn
 * scaling, Knight 2008, as rad_ff_close), then F_ij <- x_i x_j F_ij.
 *
 * Monte Carlo's closure is measured here by cosine-distributed rays from
 * each element (CLOSURE_RAYS; r_i, var r_i = r_i (1 - r_i) / K), and its
 * rows are adjusted by generalised least squares instead: the pairs are
 * independent estimates with known variances W_ij = var(G_ij), so the
 * least change that meets the measured closures,
 *
 *     min sum_{i<j} (G'_ij - G_ij)^2 / W_ij + sum_i A_i^2 (t_i - r_i)^2 / var r_i
 *     subject to  sum_j G'_ij = A_i t_i
 *
 * is G'_ij = G_ij - W_ij (l_i + l_j), with (diag(d) + W) l = sum_j G_ij - A_i r_i,
 * d_i = sum_j W_ij + A_i^2 var r_i (Lagrange multipliers; the
 * best linear unbiased estimate under the constraints; Deming 1943 "Statistical
 * adjustment of data"), solved by conjugate gradients.  Each factor moves by
 * its share of its rows' variance: a precise factor (far, unoccluded)
 * hardly at all.  The rescaling spread a row's noise over its factors in
 * proportion to F instead, so precise factors moved by 10-20 times their
 * reported error.  A closed element (r_i = 1, var 0) is held to exactly 1;
 * an open one (or one whose rays met nothing) mostly keeps its own, usually
 * better, sum.  The adjusted factor's variance combines its own with the
 * two others that its rows' constraints give, A_i t_i less the rest of
 * the row (variance d_i - W_ij), as independent estimates:
 *
 *     1 / var G'_ij = 1 / W_ij + 1 / (d_i - W_ij) + 1 / (d_j - W_ij)
 *
 * (exact for a lone pair; to first order in W_ij / d the diagonal of
 * W - W A^T (A W A^T)^-1 A W).  A factor driven below 0 is held at 0 with
 * its raw variance, and the rest adjusted again.
 *
 * Last, every row above 1 (rounding, or an open scene's compromise) is
 * scaled down to 1.
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

/* Step 2 for row methods: x with x_i sum_j F_ij x_j = target_i, by the
 * symmetric Sinkhorn iteration x_i <- sqrt(x_i target_i / sum_j F_ij x_j),
 * until the worst row is right to 1e-7 (far below the sampling noise), or
 * while it still improves (inconsistent targets of an open scene stall
 * it).  `row`: n doubles of scratch. */
static void rescale(size_t n, const double *F, const double *target, double *x, double *row)
{
    double previous = INFINITY;
    for (int it = 0; it < 200; it++) {
        double worst = 0.0;
        for (size_t i = 0; i < n; i++) {
            double s = 0.0;
            for (size_t j = 0; j < n; j++)
                s += F[i * n + j] * x[j];
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
}

/* (M v)_i = d_i v_i + sum_j W_ij v_j over the constrained rows (d_i > 0),
 * W_ij = A_i^2 var_ij (held pairs carry -var: left out). */
static void adjust_product(const rad_mesh *mesh, const double *var, const double *d, const double *v, double *out)
{
    size_t n = mesh->element_count;
    for (size_t i = 0; i < n; i++) {
        out[i] = 0.0;
        if (!(d[i] > 0.0))
            continue;
        double s = 0.0, a = mesh->elements[i].area;
        for (size_t j = 0; j < n; j++)
            s += (var[i * n + j] > 0.0 ? var[i * n + j] : 0.0) * v[j];
        out[i] = d[i] * v[i] + a * a * s;
    }
}

/* Step 2 for Monte Carlo: the least-squares adjustment of the file header
 * to the closures r[] measured by CLOSURE_RAYS rays; F and var changed in
 * place.  `work`: 5n doubles of scratch.  Cannot fail. */
static void adjust(const rad_mesh *mesh, const double *r, double *F, double *var, double *work)
{
    size_t n = mesh->element_count;
    double *d = work, *l = work + n, *res = work + 2 * n, *p = work + 3 * n, *q = work + 4 * n;
    /* Rounds: each holds the factors driven below 0 at 0; in practice one
     * or two. */
    for (int round = 0; round < 8; round++) {
        /* d_i, and the residual A_i (s_i - r_i) as the right-hand side;
         * the rows whose rays met no front are not constrained (d_i = 0). */
        double rz = 0.0;
        for (size_t i = 0; i < n; i++) {
            double a = mesh->elements[i].area, w = 0.0, s = 0.0;
            for (size_t j = 0; j < n; j++) {
                s += F[i * n + j];
                w += var[i * n + j] > 0.0 ? var[i * n + j] : 0.0;
            }
            d[i] = r[i] > 0.0 ? a * a * (w + r[i] * (1.0 - r[i]) / CLOSURE_RAYS) : 0.0;
            res[i] = d[i] > 0.0 ? a * (s - r[i]) : 0.0;
            l[i] = 0.0;
            p[i] = d[i] > 0.0 ? res[i] / d[i] : 0.0; /* Jacobi preconditioner */
            rz += res[i] * p[i];
        }
        /* Conjugate gradients until every constrained row is right to 1e-9
         * of its area (far below the sampling noise; rows within 1e-9 keep
         * a closed box's energy to ~20 bounces x 1e-9). */
        for (int it = 0; it < 500; it++) {
            double worst = 0.0;
            for (size_t i = 0; i < n; i++)
                worst = fmax(worst, fabs(res[i]) / mesh->elements[i].area);
            if (worst < 1e-9)
                break;
            adjust_product(mesh, var, d, p, q);
            double pq = 0.0;
            for (size_t i = 0; i < n; i++)
                pq += p[i] * q[i];
            if (!(pq > 0.0))
                break;
            double alpha = rz / pq, rz_next = 0.0;
            for (size_t i = 0; i < n; i++) {
                l[i] += alpha * p[i];
                res[i] -= alpha * q[i];
                rz_next += d[i] > 0.0 ? res[i] * res[i] / d[i] : 0.0;
            }
            for (size_t i = 0; i < n; i++)
                p[i] = (d[i] > 0.0 ? res[i] / d[i] : 0.0) + rz_next / rz * p[i];
            rz = rz_next;
        }
        /* G'_ij = G_ij - W_ij (l_i + l_j), row by row: W and G are
         * symmetric, so F_ji's row gives the same G'. */
        int held = 0;
        for (size_t i = 0; i < n; i++) {
            double ai = mesh->elements[i].area;
            for (size_t j = 0; j < n; j++) {
                double w = ai * ai * var[i * n + j];
                if (!(w > 0.0))
                    continue;
                double g = ai * F[i * n + j] - w * (l[i] + l[j]);
                if (g < 0.0) {
                    g = 0.0;
                    var[i * n + j] = -var[i * n + j];
                    held++;
                }
                F[i * n + j] = g / ai;
            }
        }
        if (!held)
            break;
    }
    /* The adjusted variances (file header) from the last round's d; the
     * held factors get their raw variance back. */
    for (size_t i = 0; i < n; i++) {
        double ai = mesh->elements[i].area;
        for (size_t j = 0; j < n; j++) {
            double w = ai * ai * var[i * n + j], inverse = 1.0 / w;
            if (!(w > 0.0)) {
                var[i * n + j] = fabs(var[i * n + j]);
                continue;
            }
            if (d[i] > 0.0)
                inverse += d[i] > w ? 1.0 / (d[i] - w) : INFINITY;
            if (d[j] > 0.0)
                inverse += d[j] > w ? 1.0 / (d[j] - w) : INFINITY;
            var[i * n + j] = 1.0 / (inverse * ai * ai);
        }
    }
}

rad_result rad_ff_balance(rad_context *ctx, const rad_ff_method *method, const rad_ff_request *req,
                          const void *shared, double *F, double *var, rad_ff_stats *stats)
{
    const rad_mesh *mesh = req->mesh;
    size_t n = mesh->element_count;
    double *work = rad_alloc(ctx, RAD_MEM_FORM_FACTORS, 9 * n, sizeof *work, "form factors: reciprocity");
    if (!work)
        return RAD_ERROR_OUT_OF_MEMORY;
    double *raw = work, *target = work + n, *x = work + 2 * n, *row = work + 3 * n, *scratch = work + 4 * n;
    /* The raw rows' sums: a row method's measured closure. */
    double raw_max = 0.0;
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (size_t j = 0; j < n; j++)
            s += F[i * n + j];
        raw[i] = s;
        target[i] = fmin(s, 1.0);
        x[i] = 1.0;
        raw_max = fmax(raw_max, s);
    }
    stats->raw_row_sum_max = raw_max;
    if (method->density) {
        for (size_t i = 0; i < n; i++)
            scratch[i] = method->density(req, shared, (uint32_t)i);
        symmetrize(mesh, scratch, F, var);
        rescale(n, F, target, x, row);
    } else if (req->vis && var) {
        rad_result r = closure_rays(ctx, req, target);
        if (r != RAD_OK) {
            rad_free(work);
            return r;
        }
        adjust(mesh, target, F, var, scratch);
    }
    /* No row above 1: each row over it scaled down by its excess, all
     * at once (scaling x_i down only lowers the other rows). */
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (size_t j = 0; j < n; j++)
            s += F[i * n + j] * x[i] * x[j];
        row[i] = s;
    }
    for (size_t i = 0; i < n; i++)
        if (row[i] > 1.0)
            x[i] /= row[i];
    /* The rows' scales: balanced sum over raw sum. */
    stats->closure_scale_min = INFINITY;
    stats->closure_scale_max = 0.0;
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (size_t j = 0; j < n; j++) {
            double scale = x[i] * x[j];
            F[i * n + j] *= scale;
            s += F[i * n + j];
            if (var)
                var[i * n + j] *= scale * scale;
        }
        if (raw[i] > 0.0) {
            stats->closure_scale_min = fmin(stats->closure_scale_min, s / raw[i]);
            stats->closure_scale_max = fmax(stats->closure_scale_max, s / raw[i]);
        }
    }
    if (!(stats->closure_scale_max > 0.0))
        stats->closure_scale_min = stats->closure_scale_max = 1.0; /* no row saw anything */
    stats->balanced = true;
    rad_free(work);
    return RAD_OK;
}
