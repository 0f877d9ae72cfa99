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

/* GIVEN a stream of IMU samples with noise, jumps, out-of-range and non-finite values on either sensor
 * and repeated or backwards times, WHEN sf_sample_gate_imu judges each THEN its verdict and both gates'
 * state are those of the two sf_sample_gate_stream calls it stands for (accel, then gyro only when
 * accel accepted). */
static void test_imu_gate_is_the_two_stream_gates(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    sf_sample_gate_t a1, g1, a2, g2;
    sf_sample_gate_init(&a1);
    sf_sample_gate_init(&g1);
    sf_sample_gate_init(&a2);
    sf_sample_gate_init(&g2);
    uint64_t r = 0x1234567887654321ULL;
    int64_t t_us = 0;
    int refused = 0;
    for (int k = 0; k < 5000; k++) {
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        const unsigned pick = (unsigned)(r >> 59); /* 0..31 */
        t_us += pick == 3 ? 0 : (pick == 4 ? -5000 : 10000);
        double acc[3] = {0.1 * (double)(pick % 7), -0.2, 9.81}, gyr[3] = {0.01, 0.02 * (double)(pick % 5), -0.03};
        if (pick == 5) {
            acc[2] = 300.0; /* a jump */
        } else if (pick == 6) {
            gyr[0] = 40.0; /* a gyro jump */
        } else if (pick == 7) {
            acc[1] = (double)NAN;
        } else if (pick == 8) {
            gyr[2] = (double)INFINITY;
        } else if (pick == 9) {
            acc[0] = 1e6; /* beyond full scale */
        }
        sf_gate_verdict_t two = sf_sample_gate_stream(&a1, &p, sf_gate_accel, t_us, acc);
        if (two == sf_gate_accepted) {
            two = sf_sample_gate_stream(&g1, &p, sf_gate_gyro, t_us, gyr);
        }
        const sf_gate_verdict_t one = sf_sample_gate_imu(&a2, &g2, &p, t_us, acc, gyr);
        assert_int_equal(one, two);
        assert_memory_equal(&a1, &a2, sizeof a1);
        assert_memory_equal(&g1, &g2, sizeof g1);
        refused += one != sf_gate_accepted;
    }
    assert_true(refused > 500 && refused < 4500); /* both kinds of sample were seen */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walking_signal_passes),
        cmocka_unit_test(test_flipped_sign_bit_is_refused_once),
        cmocka_unit_test(test_a_real_step_change_is_accepted_on_the_second_sample),
        cmocka_unit_test(test_full_scale_not_finite_and_order),
        cmocka_unit_test(test_a_long_gap_allows_a_large_change),
        cmocka_unit_test(test_imu_gate_is_the_two_stream_gates),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
