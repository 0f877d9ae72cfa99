/* test_core_api.c — what the board layer may ask the core: sf_estimator_status (instead of reading
 * sf_estimator_t's internals) and the scheme registry (ids and names from pose_t.SCHEME_*).
 *
 * GIVEN a level device walking in place at 1.8 Hz with a magnetometer whose field is far off the
 * expected strength, WHEN the samples go through sf_estimator, THEN the status reports the steps, the
 * newest time, the floor and the rejected magnetometer samples that the internals hold. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sf_error.h"
#include "sf_estimator.h"
#include "stridefix_pose_t.h"

#define PI 3.14159265358979323846
#define G 9.80665

static void test_status_mirrors_the_estimator(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.init_floor = 2;
    p.attitude_mag_acquire_s = 0.0; /* judge the field against attitude.mag_field_ut from the start */
    static sf_estimator_t est;
    sf_estimator_init(&est, &p);
    sf_estimator_status_t st;
    sf_estimator_status(&est, &st);
    assert_int_equal(st.step_count, 0);
    assert_int_equal(st.floor, 2);
    assert_false(st.has_site);

    const double step_hz = 1.8, w = 2.0 * PI * step_hz;
    for (int k = 0; k < 3000; k++) {
        const double t = k / 100.0;
        const bool walking = t >= 5.0 && t < 25.0;
        const sf_imu_sample_t s = {.t_us = (int64_t)llround(t * 1e6),
                                   .accel_mps2 = {walking ? 1.2 * cos(w * t) : 0.0, 0.0,
                                                  G + (walking ? 2.5 * sin(w * t) : 0.0)}};
        if (k % 2 == 0) {
            const double field_ut[3] = {0.0, 150.0, -150.0}; /* ~212 µT: a disturbed field */
            sf_estimator_mag(&est, &p, s.t_us, field_ut);
        }
        sf_step_t steps[SF_ESTIMATOR_MAX_STEPS];
        (void)sf_estimator_imu(&est, &p, &s, steps);
    }
    sf_estimator_status(&est, &st);
    assert_true(st.step_count > 20);
    assert_int_equal(st.step_count, est.step_count);
    assert_int_equal(st.t_us, est.t_us);
    assert_int_equal(st.t_us, 29990000);
    assert_int_equal(st.floor, sf_floor_current(&est.floor));
    assert_true(st.mag_rejected > 0);
    assert_int_equal(st.mag_rejected, est.attitude.mag_rejected);
    assert_int_equal(st.steps_refused, est.steps_refused);
    assert_int_equal(st.stride_calibrations, 0);
}

/* Every pose_t.SCHEME_* has a registry row, a name that maps back to its id, and the id the
 * generated LCM constant has. */
static void test_scheme_registry_follows_pose_t(void **state)
{
    (void)state;
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_true(sf_fusion_scheme_is_registered(s));
        const char *const name = sf_fusion_scheme_name(s);
        assert_non_null(name);
        assert_int_equal(sf_fusion_scheme_from_name(name), s);
    }
    assert_null(sf_fusion_scheme_name(-1));
    assert_null(sf_fusion_scheme_name(sf_scheme_count));
    assert_false(sf_fusion_scheme_is_registered(sf_scheme_count));
    assert_int_equal(sf_fusion_scheme_from_name("all"), SF_EINVAL);
    assert_int_equal(sf_fusion_scheme_from_name(NULL), SF_EINVAL);
    assert_int_equal(sf_scheme_pdr_only, STRIDEFIX_POSE_T_SCHEME_PDR_ONLY);
    assert_int_equal(sf_scheme_wifi_only, STRIDEFIX_POSE_T_SCHEME_WIFI_ONLY);
    assert_int_equal(sf_scheme_overwrite, STRIDEFIX_POSE_T_SCHEME_OVERWRITE);
    assert_int_equal(sf_scheme_static, STRIDEFIX_POSE_T_SCHEME_STATIC);
    assert_int_equal(sf_scheme_adaptive, STRIDEFIX_POSE_T_SCHEME_ADAPTIVE);
    assert_int_equal(sf_scheme_kalman, STRIDEFIX_POSE_T_SCHEME_KALMAN);
    assert_string_equal(sf_fusion_scheme_name(sf_scheme_kalman), "kalman");
    /* the params range of output.scheme ends at the last pose_t id: the controller's primary pose,
     * which follows the fusion schemes (not one itself) */
    const sf_param_desc_t *const d = sf_param_find("output", "scheme");
    assert_non_null(d);
    assert_int_equal(sf_scheme_controller, sf_scheme_count);
    assert_int_equal(sf_scheme_controller, STRIDEFIX_POSE_T_SCHEME_CONTROLLER);
    assert_true(d->max_value == (double)sf_scheme_controller);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_status_mirrors_the_estimator),
        cmocka_unit_test(test_scheme_registry_follows_pose_t),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
