/* test_sample_gate.c — sf_sample_gate: what no body-worn sensor produces is refused, a rejection
 * never latches, and a long gap allows a large change. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "sf_params.h"
#include "sf_sample_gate.h"

/* the default accelerometer limits of the params table */
static sf_sample_limits_t accel_limits(void)
{
    sf_params_t p;
    sf_params_default(&p);
    return sf_sample_limits(&p, sf_gate_accel);
}

static sf_gate_verdict_t feed(sf_sample_gate_t *const g, const int64_t t_us, const double z)
{
    const sf_sample_limits_t lim = accel_limits();
    const double v[3] = {0.1, -0.2, z};
    return sf_sample_gate_check(g, &lim, t_us, v, 3);
}

static void test_walking_signal_passes(void **state)
{
    (void)state;
    sf_sample_gate_t g;
    sf_sample_gate_init(&g);
    /* 60 s at 100 Hz of a brisk gait: 9.8 ± 6 m/s² at 2.2 Hz with sharp heel strikes */
    for (int k = 0; k < 6000; k++) {
        const double t = k * 0.01;
        const double z = 9.81 + 6.0 * sin(2.0 * 3.14159265 * 2.2 * t) + 8.0 * exp(-pow(fmod(t, 0.4545) / 0.02, 2));
        assert_int_equal(feed(&g, (int64_t)k * 10000, z), sf_gate_accepted);
    }
}

static void test_flipped_sign_bit_is_refused_once(void **state)
{
    (void)state;
    sf_sample_gate_t g;
    sf_sample_gate_init(&g);
    assert_int_equal(feed(&g, 0, 9.81), sf_gate_accepted);
    assert_int_equal(feed(&g, 10000, 9.81), sf_gate_accepted);
    /* 9.81 m/s² with its int16 sign bit flipped: −147.1 m/s², inside full scale */
    assert_int_equal(feed(&g, 20000, 9.81 - 156.9), sf_gate_jump);
    assert_int_equal(feed(&g, 30000, 9.9), sf_gate_accepted); /* the next one is judged against 9.81 */
}

static void test_a_real_step_change_is_accepted_on_the_second_sample(void **state)
{
    (void)state;
    sf_sample_gate_t g;
    sf_sample_gate_init(&g);
    assert_int_equal(feed(&g, 0, 9.81), sf_gate_accepted);
    assert_int_equal(feed(&g, 10000, 100.0), sf_gate_jump);
    assert_int_equal(feed(&g, 20000, 100.5), sf_gate_accepted); /* two agreeing: the signal moved */
    assert_int_equal(feed(&g, 30000, 100.0), sf_gate_accepted);
}

static void test_full_scale_not_finite_and_order(void **state)
{
    (void)state;
    sf_sample_gate_t g;
    sf_sample_gate_init(&g);
    assert_int_equal(feed(&g, 0, 156.95), sf_gate_out_of_range); /* saturated */
    assert_int_equal(feed(&g, 0, NAN), sf_gate_out_of_range);
    assert_int_equal(feed(&g, 0, INFINITY), sf_gate_out_of_range);
    assert_int_equal(feed(&g, 10000, 9.81), sf_gate_accepted);
    assert_int_equal(feed(&g, 10000, 9.81), sf_gate_out_of_order);
    assert_int_equal(feed(&g, 5000, 9.81), sf_gate_out_of_order);
    assert_int_equal(feed(&g, 20000, 9.81), sf_gate_accepted);
}

static void test_a_long_gap_allows_a_large_change(void **state)
{
    (void)state;
    sf_sample_gate_t g;
    sf_sample_gate_init(&g);
    assert_int_equal(feed(&g, 0, 9.81), sf_gate_accepted);
    assert_int_equal(feed(&g, 10000, 9.81 + 60.0), sf_gate_accepted);  /* 20 + 5000 · 0.01 = 70 */
    assert_int_equal(feed(&g, 20000, 9.81 + 140.0), sf_gate_jump);
    assert_int_equal(feed(&g, 1020000, -100.0), sf_gate_accepted); /* 1 s later: anything in range */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walking_signal_passes),
        cmocka_unit_test(test_flipped_sign_bit_is_refused_once),
        cmocka_unit_test(test_a_real_step_change_is_accepted_on_the_second_sample),
        cmocka_unit_test(test_full_scale_not_finite_and_order),
        cmocka_unit_test(test_a_long_gap_allows_a_large_change),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
