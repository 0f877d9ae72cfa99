/* test_stride.c — Weinberg step length and its online calibration: exact length on known
 * amplitudes, movement toward the truth, the per-update clamp, [k_min, k_max], refusals. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "sf_error.h"
#include "sf_params.h"
#include "sf_stride.h"

static sf_step_event_t step(const double amax, const double amin)
{
    return (sf_step_event_t){.t_us = 1000000, .amax_mps2 = amax, .amin_mps2 = amin, .period_s = 0.55};
}

static void test_defaults(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    assert_true(p.stride_weinberg_k == 0.47);
    assert_true(p.stride_k_min <= p.stride_weinberg_k && p.stride_weinberg_k <= p.stride_k_max);
    sf_stride_t st;
    sf_stride_init(&st, &p);
    assert_true(st.k == 0.47);
    assert_int_equal(st.calibrations + st.clamped + st.skipped, 0);
}

static void test_weinberg_length_exact(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_stride_t st;
    sf_stride_init(&st, &p);
    /* range 16 m/s²: 16^¼ = 2 exactly; range 1: 1; range 81: 3 */
    const sf_step_event_t a = step(10.0, -6.0), b = step(0.5, -0.5), c = step(40.0, -41.0);
    assert_true(sf_stride_range_mps2(&a) == 16.0);
    assert_true(sf_stride_weinberg_term(&a) == 2.0);
    assert_true(sf_stride_length_m(&st, &a) == 0.47 * 2.0);
    assert_true(sf_stride_length_m(&st, &b) == 0.47);
    assert_true(fabs(sf_stride_length_m(&st, &c) - 0.47 * 3.0) < 1e-15);
    /* any range: K · range^¼ to the bit */
    for (double r = 0.25; r < 20.0; r *= 1.37) {
        const sf_step_event_t e = step(r / 2, -r / 2);
        assert_true(sf_stride_length_m(&st, &e) == st.k * pow(r / 2 - (-r / 2), 0.25));
    }
    /* a degenerate step has no length */
    const sf_step_event_t flat = step(1.0, 1.0), inverted = step(-1.0, 1.0), nan_step = step(NAN, 0.0);
    assert_true(sf_stride_length_m(&st, &flat) == 0.0);
    assert_true(sf_stride_length_m(&st, &inverted) == 0.0);
    assert_true(sf_stride_length_m(&st, &nan_step) == 0.0);
}

/* K moves gain·(K* − K) toward K* = distance / sum when that is within the per-update bound. */
static void test_calibration_moves_toward_truth(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_stride_t st;
    sf_stride_init(&st, &p);
    /* 40 steps of range 16 (term 2): sum 80; the truth K* = 0.50 → distance 40 m */
    const double sum = 40 * 2.0;
    assert_int_equal(sf_stride_calibrate(&st, &p, 0.50 * sum, sum), SF_OK);
    assert_true(fabs(st.k - (0.47 + 0.3 * (0.50 - 0.47))) < 1e-15); /* 0.479 */
    assert_int_equal(st.calibrations, 1);
    assert_int_equal(st.clamped, 0);
    /* repeated fixes converge to the truth */
    for (int i = 0; i < 60; i++) {
        assert_int_equal(sf_stride_calibrate(&st, &p, 0.50 * sum, sum), SF_OK);
    }
    assert_true(fabs(st.k - 0.50) < 1e-6);
    /* and back down to a shorter walker */
    for (int i = 0; i < 100; i++) {
        sf_stride_calibrate(&st, &p, 0.40 * sum, sum);
    }
    assert_true(fabs(st.k - 0.40) < 1e-6);
    /* after calibration the predicted distance matches */
    const sf_step_event_t e = step(8.0, -8.0);
    assert_true(fabs(40 * sf_stride_length_m(&st, &e) - 0.40 * sum) < 1e-4);
}

/* One absurd fix (10× the distance, or a tenth) moves K by at most k_max_change. */
static void test_absurd_fix_is_clamped(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.stride_min_calib_distance_m = 10.0; /* the distances below were chosen for this value */
    sf_stride_t st;
    sf_stride_init(&st, &p);
    const double sum = 100.0, true_d = 0.47 * sum;
    assert_int_equal(sf_stride_calibrate(&st, &p, 10.0 * true_d, sum), SF_OK);
    assert_true(st.k <= 0.47 * (1.0 + p.stride_k_max_change) + 1e-15);
    assert_true(fabs(st.k - 0.47 * 1.10) < 1e-15);
    assert_int_equal(st.clamped, 1);
    sf_stride_init(&st, &p);
    assert_int_equal(sf_stride_calibrate(&st, &p, 0.1 * true_d + 10.0, sum), SF_OK);
    assert_true(fabs(st.k - 0.47 * 0.90) < 1e-15);
    /* a good fix right after recovers toward the truth */
    const double k_low = st.k;
    sf_stride_calibrate(&st, &p, true_d, sum);
    assert_true(st.k > k_low && st.k <= 0.47);
    /* the clamp is a parameter */
    p.stride_k_max_change = 0.02;
    sf_stride_init(&st, &p);
    sf_stride_calibrate(&st, &p, 10.0 * true_d, sum);
    assert_true(fabs(st.k - 0.47 * 1.02) < 1e-15);
}

/* K never leaves [k_min, k_max], however many absurd fixes. */
static void test_k_bounds(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.stride_min_calib_distance_m = 10.0; /* the distances below were chosen for this value */
    sf_stride_t st;
    sf_stride_init(&st, &p);
    for (int i = 0; i < 100; i++) {
        sf_stride_calibrate(&st, &p, 1000.0, 10.0);
        assert_true(st.k <= p.stride_k_max);
    }
    assert_true(st.k == p.stride_k_max);
    for (int i = 0; i < 100; i++) {
        sf_stride_calibrate(&st, &p, 10.0, 1000.0);
        assert_true(st.k >= p.stride_k_min);
    }
    assert_true(st.k == p.stride_k_min);
    /* a start value outside the bounds is clamped at init */
    p.stride_weinberg_k = 1.5;
    sf_stride_init(&st, &p);
    assert_true(st.k == p.stride_k_max);
}

/* Too short, non-finite or empty walks are refused and leave K alone. */
static void test_refusals(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_stride_t st;
    sf_stride_init(&st, &p);
    assert_int_equal(sf_stride_calibrate(&st, &p, p.stride_min_calib_distance_m - 0.01, 10.0), SF_ERANGE);
    assert_int_equal(sf_stride_calibrate(&st, &p, 50.0, 0.0), SF_ERANGE);
    assert_int_equal(sf_stride_calibrate(&st, &p, 50.0, -3.0), SF_ERANGE);
    assert_int_equal(sf_stride_calibrate(&st, &p, NAN, 10.0), SF_ERANGE);
    assert_int_equal(sf_stride_calibrate(&st, &p, 50.0, INFINITY), SF_ERANGE);
    assert_int_equal(sf_stride_calibrate(&st, &p, INFINITY, 10.0), SF_ERANGE);
    assert_true(st.k == 0.47);
    assert_int_equal(st.skipped, 6);
    assert_int_equal(st.calibrations, 0);
    /* exactly the minimum distance is used */
    assert_int_equal(sf_stride_calibrate(&st, &p, p.stride_min_calib_distance_m, 20.0), SF_OK);
    /* gain 0: calibration does nothing but is counted */
    p.stride_k_gain = 0.0;
    const double k = st.k;
    assert_int_equal(sf_stride_calibrate(&st, &p, 100.0, 20.0), SF_OK);
    assert_true(st.k == k);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_weinberg_length_exact),
        cmocka_unit_test(test_calibration_moves_toward_truth),
        cmocka_unit_test(test_absurd_fix_is_clamped),
        cmocka_unit_test(test_k_bounds),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
