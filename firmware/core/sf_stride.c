/* sf_stride.c — see sf_stride.h for the model. */
#include "sf_stride.h"

#include <math.h>

#include "sf_error.h"
#include "sf_math.h"

void sf_stride_init(sf_stride_t *const st, const sf_params_t *const p)
{
    *st = (sf_stride_t){0};
    st->k = sf_clamp(p->stride_weinberg_k, p->stride_k_min, p->stride_k_max);
}

double sf_stride_range_mps2(const sf_step_event_t *const ev)
{
    const double r = ev->amax_mps2 - ev->amin_mps2;
    return r > 0.0 ? r : 0.0; /* also maps NaN to 0 */
}

double sf_stride_weinberg_term(const sf_step_event_t *const ev)
{
    return pow(sf_stride_range_mps2(ev), 0.25);
}

double sf_stride_length_m(const sf_stride_t *const st, const sf_step_event_t *const ev)
{
    return st->k * sf_stride_weinberg_term(ev);
}

int sf_stride_calibrate(sf_stride_t *const st, const sf_params_t *const p, const double true_distance_m,
                        const double weinberg_sum)
{
    if (!(isfinite(true_distance_m) && isfinite(weinberg_sum) && weinberg_sum > 0.0 &&
          true_distance_m >= p->stride_min_calib_distance_m)) {
        st->skipped++;
        return SF_ERANGE;
    }
    const double k_target = true_distance_m / weinberg_sum;
    const double k_raw = st->k + p->stride_k_gain * (k_target - st->k);
    const double c = p->stride_k_max_change;
    const double k_step = sf_clamp(k_raw, st->k * (1.0 - c), st->k * (1.0 + c));
    const double k_new = sf_clamp(k_step, p->stride_k_min, p->stride_k_max);
    if (k_new != k_raw) {
        st->clamped++;
    }
    st->k = k_new;
    st->calibrations++;
    return SF_OK;
}
