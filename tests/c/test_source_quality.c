/* test_source_quality.c — what a GNSS or BLE source delivers against the Wi-Fi fixes: a source as good
 * as it claims keeps its accuracy, one three times worse (white) gets about three, a biased one (the
 * basement GNSS of ipin2023 Trial26, one offset for a minute) gets the persistence inflation, and
 * without a fresh Wi-Fi reference nothing is learnt. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "sf_params.h"
#include "sf_rng.h"
#include "sf_source_quality.h"

#define S_US 1000000LL

static sf_fix_t fix_at(const int8_t method, const int64_t t_us, const double x_m, const double y_m, const double acc_m)
{
    return (sf_fix_t){.t_us = t_us, .method = method, .x_m = x_m, .y_m = y_m, .accuracy_m = acc_m};
}

/* A walk standing at the origin: a Wi-Fi fix every 4 s with 1 m of its own error (claim 1 m), the
 * source at 1 Hz with error(k) and claim acc_m. Returns the factor after n_s seconds. */
static double run(const sf_params_t *p, const double acc_m, const double sigma_m, const double bias_m, const int n_s,
                  const bool wifi)
{
    sf_source_quality_t q;
    sf_source_quality_init(&q);
    sf_rng_t rng;
    sf_rng_seed(&rng, 7, 1);
    double k = 1.0;
    for (int t = 0; t < n_s; t++) {
        /* one draw per statement: the order of a call's arguments is the compiler's */
        if (wifi && t % 4 == 0) {
            const double wx = sf_rng_normal(&rng);
            const double wy = sf_rng_normal(&rng);
            const sf_fix_t w = fix_at(sf_fix_wifi, t * S_US, wx, wy, 1.0);
            sf_source_quality_reference(&q, &w, 0.0, 0.0, 0.0);
        }
        const double gx = bias_m + sigma_m * sf_rng_normal(&rng);
        const double gy = sigma_m * sf_rng_normal(&rng);
        const sf_fix_t g = fix_at(sf_fix_gnss, t * S_US + S_US / 2, gx, gy, acc_m);
        k = sf_source_quality_judge(&q, p, &g, 0.0, 0.0, 0.0);
    }
    assert_true(fabs(k - sf_source_quality_factor(&q, p, sf_fix_gnss)) < 1e-12);
    return k;
}

static void test_a_true_claim_is_kept(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    /* 5 m white, claimed 5 m: the means find 5 m (factor 1) and little persistence (the shared
     * reference error of a 4 s Wi-Fi period is 1 m against 5) */
    const double k = run(&p, 5.0, 5.0, 0.0, 400, true);
    assert_true(k >= 1.0 && k < 1.3);
}

static void test_three_times_worse_white(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const double k = run(&p, 5.0, 15.0, 0.0, 400, true);
    assert_true(k > 2.5 && k < 3.8);
}

static void test_a_bias_persists(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    /* 20 m off in x, 2 m of noise, claimed 8 m per axis: the excess alone says √((400/2 + 4) / 64) ≈ 1.8;
     * consecutive residuals (against different Wi-Fi fixes) agree, ρ ≈ 0.92, so the factor is about
     * 1.8·√((1 + ρ)/(1 − ρ)) ≈ 8.9, under the cap of 10 */
    const double k = run(&p, 8.0, 2.0, 20.0, 200, true);
    assert_true(k > 7.0 && k <= p.quality_max_factor);
    p.quality_max_factor = 5.0;
    assert_true(fabs(run(&p, 8.0, 2.0, 20.0, 200, true) - 5.0) < 1e-9); /* the cap holds */
    p.quality_max_factor = 10.0;
    p.quality_max_rho = 0.0; /* without the persistence term: the excess alone */
    const double k0 = run(&p, 8.0, 2.0, 20.0, 200, true);
    assert_true(k0 > 1.6 && k0 < 2.1);
}

static void test_nothing_without_a_reference(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    assert_true(run(&p, 5.0, 30.0, 20.0, 100, false) == 1.0);
    /* a reference older than quality_ref_max_age_s is none */
    sf_source_quality_t q;
    sf_source_quality_init(&q);
    const sf_fix_t w = fix_at(sf_fix_wifi, 0, 0.0, 0.0, 1.0);
    sf_source_quality_reference(&q, &w, 0.0, 0.0, 0.0);
    for (int t = 0; t < 20; t++) {
        const sf_fix_t g = fix_at(sf_fix_ble, (int64_t)(p.quality_ref_max_age_s + 1.0 + t) * S_US, 50.0, 0.0, 2.0);
        assert_true(sf_source_quality_judge(&q, &p, &g, 0.0, 0.0, 0.0) == 1.0);
    }
    assert_int_equal(q.ble.n, 0);
    /* Wi-Fi is the reference, never judged */
    assert_true(sf_source_quality_factor(&q, &p, sf_fix_wifi) == 1.0);
}

static void test_the_pdr_displacement_moves_the_reference(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_source_quality_t q;
    sf_source_quality_init(&q);
    /* walking east at 1 m/s from a Wi-Fi fix at the origin; a source exactly on the walker agrees */
    for (int t = 0; t < 60; t++) {
        if (t % 4 == 0) {
            const sf_fix_t w = fix_at(sf_fix_wifi, t * S_US, (double)t, 0.0, 1.0);
            sf_source_quality_reference(&q, &w, (double)t, 0.0, (double)t);
        }
        const sf_fix_t g = fix_at(sf_fix_gnss, t * S_US + S_US / 2, (double)t + 0.5, 0.0, 3.0);
        sf_source_quality_judge(&q, &p, &g, (double)t + 0.5, 0.0, (double)t + 0.5);
    }
    assert_true(q.gnss.excess_m2 < 0.0); /* |d| = 0: the whole claim is spare */
    assert_true(sf_source_quality_factor(&q, &p, sf_fix_gnss) == 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_true_claim_is_kept),
        cmocka_unit_test(test_three_times_worse_white),
        cmocka_unit_test(test_a_bias_persists),
        cmocka_unit_test(test_nothing_without_a_reference),
        cmocka_unit_test(test_the_pdr_displacement_moves_the_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
