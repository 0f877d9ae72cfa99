/* sf_source_quality.c — see sf_source_quality.h for the model. */
#include "sf_source_quality.h"

#include <math.h>
#include <stddef.h>

#include "sf_assert.h"

void sf_source_quality_init(sf_source_quality_t *const q)
{
    SF_ASSERT(q != NULL);
    *q = (sf_source_quality_t){0};
    q->gnss.prev_t_us = INT64_MIN;
    q->ble.prev_t_us = INT64_MIN;
}

void sf_source_quality_reference(sf_source_quality_t *const q, const sf_fix_t *const fix, const double pdr_x_m,
                                 const double pdr_y_m, const double walked_m)
{
    SF_ASSERT(q != NULL && fix != NULL);
    if (!(isfinite(fix->x_m) && isfinite(fix->y_m) && isfinite(fix->accuracy_m))) {
        return;
    }
    q->has_ref = true;
    q->ref_t_us = fix->t_us;
    q->ref_x_m = fix->x_m;
    q->ref_y_m = fix->y_m;
    q->ref_var_m2 = fix->accuracy_m * fix->accuracy_m;
    q->ref_pdr_x_m = pdr_x_m;
    q->ref_pdr_y_m = pdr_y_m;
    q->ref_walked_m = walked_m;
}

static sf_source_stats_t *stats_of(sf_source_quality_t *const q, const int8_t method)
{
    return method == sf_fix_gnss ? &q->gnss : (method == sf_fix_ble ? &q->ble : NULL);
}

static double factor_of(const sf_source_stats_t *const s, const sf_params_t *const p)
{
    if (s == NULL || s->n < (uint32_t)p->quality_min_fixes || !(s->claimed_m2 > 0.0)) {
        return 1.0;
    }
    const double rho = s->n_lag > 0 && s->square_m2 > 0.0 ? fmin(fmax(s->lag_m2 / s->square_m2, 0.0), p->quality_max_rho)
                                                         : 0.0;
    const double k = sqrt(fmax(s->excess_m2 / s->claimed_m2, 1.0) * (1.0 + rho) / (1.0 - rho));
    return fmin(k, p->quality_max_factor);
}

double sf_source_quality_judge(sf_source_quality_t *const q, const sf_params_t *const p, const sf_fix_t *const fix,
                               const double pdr_x_m, const double pdr_y_m, const double walked_m)
{
    SF_ASSERT(q != NULL && p != NULL && fix != NULL);
    sf_source_stats_t *const s = stats_of(q, fix->method);
    if (s == NULL) {
        return 1.0;
    }
    const bool fresh = q->has_ref && fix->t_us >= q->ref_t_us &&
                       (double)(fix->t_us - q->ref_t_us) * 1e-6 <= p->quality_ref_max_age_s;
    if (fresh && isfinite(fix->x_m) && isfinite(fix->y_m) && isfinite(fix->accuracy_m)) {
        const double dx = fix->x_m - (q->ref_x_m + pdr_x_m - q->ref_pdr_x_m);
        const double dy = fix->y_m - (q->ref_y_m + pdr_y_m - q->ref_pdr_y_m);
        const double dr_var_m2 = p->fusion_q_step_m2_per_m * fmax(walked_m - q->ref_walked_m, 0.0);
        const double excess = 0.5 * (dx * dx + dy * dy) - q->ref_var_m2 - dr_var_m2;
        s->n++;
        /* the mean of all comparisons until the memory is full, then an exponential one of that memory */
        const double w = 1.0 / fmin((double)s->n, fmax(p->quality_memory_fixes, 1.0));
        s->excess_m2 += w * (excess - s->excess_m2);
        s->claimed_m2 += w * (fix->accuracy_m * fix->accuracy_m - s->claimed_m2);
        s->square_m2 += w * (dx * dx + dy * dy - s->square_m2);
        /* a pair judged against one Wi-Fi fix shares that fix's error: only pairs across a new
         * reference say how long the source's own error lasts */
        const bool paired = s->prev_t_us != INT64_MIN && fix->t_us >= s->prev_t_us &&
                            (double)(fix->t_us - s->prev_t_us) * 1e-6 <= p->quality_ref_max_age_s;
        if (paired && s->prev_ref_t_us != q->ref_t_us) {
            s->n_lag++;
            const double wl = 1.0 / fmin((double)s->n_lag, fmax(p->quality_memory_fixes, 1.0));
            s->lag_m2 += wl * (dx * s->prev_dx_m + dy * s->prev_dy_m - s->lag_m2);
        }
        s->prev_dx_m = dx;
        s->prev_dy_m = dy;
        s->prev_t_us = fix->t_us;
        s->prev_ref_t_us = q->ref_t_us;
    } else if (s->n > 0 && isfinite(fix->accuracy_m)) {
        /* no reference (outdoors, beyond the radio map): each fix moves the means toward a source as
         * good as it claims, so what was learnt among the buildings fades where the source is all
         * there is */
        const double w = 1.0 / fmax(p->quality_memory_fixes, 1.0);
        const double claim_m2 = fix->accuracy_m * fix->accuracy_m;
        s->claimed_m2 += w * (claim_m2 - s->claimed_m2);
        s->excess_m2 += w * (claim_m2 - s->excess_m2);
        s->lag_m2 += w * (0.0 - s->lag_m2);
        s->prev_t_us = INT64_MIN;
    }
    return factor_of(s, p);
}

double sf_source_quality_factor(const sf_source_quality_t *const q, const sf_params_t *const p, const int8_t method)
{
    SF_ASSERT(q != NULL && p != NULL);
    return factor_of(method == sf_fix_gnss ? &q->gnss : (method == sf_fix_ble ? &q->ble : NULL), p);
}
