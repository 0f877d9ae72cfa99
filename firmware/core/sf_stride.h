/* sf_stride.h — step length by Weinberg's model, with K calibrated online from absolute fixes.
 *
 * Model (Weinberg, Analog Devices AN-602; SmartLocator Eq. 3.5): length_m = K · (amax − amin)^¼, where
 * amax, amin [m/s²] are the extremes of the vertical acceleration over the step (sf_step_event_t, taken
 * on the 3 Hz low-passed a_v of sf_steps.h). K [m/(m/s²)^¼] lumps leg length and unit conversion. It
 * depends on the person, on where the device is worn and on the filter that produced amax/amin; the
 * SmartLocator thesis gives no value. The default 0.47 is what a 0.70 m step with a 5 m/s² low-passed
 * range gives (0.70 / 5^¼ = 0.468); published values for waist- and hand-held units with a in m/s²
 * lie between about 0.4 and 0.55. stride_k_min..stride_k_max (0.25..0.80) bounds what calibration
 * may reach.
 *
 * Calibration. Between two absolute fixes the caller sums w = Σ (amax − amin)^¼ over the steps walked
 * (sf_stride_weinberg_term per step) and knows the true distance D between the fixes. Then
 *     K* = D / w,  K' = K + stride_k_gain · (K* − K),
 *     K' clamped to [K·(1 − stride_k_max_change), K·(1 + stride_k_max_change)], then to [k_min, k_max].
 * Skipped (K unchanged, counted in `skipped`) when D < stride_min_calib_distance_m or D, w are not
 * finite and positive. So one absurd fix (say 10× the distance) moves K by at most k_max_change, and K
 * never leaves [k_min, k_max]. The caller chooses D: the straight distance between fixes is right only
 * for a straight walk; a path length from the map is better.
 *
 * Errors: sf_stride_calibrate returns SF_OK (K updated, possibly clamped) or SF_ERANGE (input outside the
 * documented range: skipped). Cost: O(1), one pow() per step. Memory: sizeof(sf_stride_t) = 24 B on x86-64
 * (20 B on i686; at most 32 B, checked). */
#ifndef SF_STRIDE_H
#define SF_STRIDE_H

#include <stdint.h>

#include "sf_params.h"
#include "sf_steps.h"

typedef struct {
    double k;              /* current Weinberg K [m/(m/s²)^¼] */
    uint32_t calibrations; /* updates applied */
    uint32_t clamped;      /* updates limited by k_max_change or [k_min, k_max] */
    uint32_t skipped;      /* calibrations refused (too short, bad numbers) */
} sf_stride_t;
_Static_assert(sizeof(sf_stride_t) <= 32, "sf_stride.h promises at most 32 B");

/* K = stride_weinberg_k, clamped to [k_min, k_max]; counters 0. */
void sf_stride_init(sf_stride_t *st, const sf_params_t *p);

/* amax − amin of one step [m/s²], never negative (0 for a NaN or inverted range). */
double sf_stride_range_mps2(const sf_step_event_t *ev);

/* (amax − amin)^¼, the per-step term of the calibration sum. */
double sf_stride_weinberg_term(const sf_step_event_t *ev);

/* The step's length: K · (amax − amin)^¼ [m]. */
double sf_stride_length_m(const sf_stride_t *st, const sf_step_event_t *ev);

/* Moves K toward true_distance_m / weinberg_sum (see the model). SF_OK or SF_ERANGE. */
int sf_stride_calibrate(sf_stride_t *st, const sf_params_t *p, double true_distance_m, double weinberg_sum);

#endif
