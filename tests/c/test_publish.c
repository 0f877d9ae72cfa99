/* test_publish.c — sf_publish (firmware/board/sf_publish.h): what goes out is what the core said.
 * A FIX audit with the adaptive terms, a POSE, a STEP, a HEALTH and a CONFIG are written to a log,
 * read back with liblcm's reader and decoded with the generated types, field by field. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "sf_error.h"
#include "sf_publish.h"
#include "stridefix_config_t.h"
#include "stridefix_fix_t.h"
#include "stridefix_health_t.h"
#include "stridefix_pose_t.h"
#include "stridefix_step_t.h"

static void test_every_output_round_trips(void **state)
{
    (void)state;
    char path[64];
    snprintf(path, sizeof path, "/tmp/sf_test_publish_XXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path); /* the log is created O_EXCL: the name only, not the file */
    sf_lcm_out_t *out = NULL;
    assert_int_equal(sf_lcm_out_open(&out, path, NULL, 16, true, NULL, 0), SF_OK);

    const sf_fix_audit_t audit = {.t_us = 7000000, .method = sf_fix_wifi, .x_m = 3.5, .y_m = -1.25, .floor = 1,
                                  .accuracy_m = 2.0, .n_ap_used = 5, .scheme = sf_scheme_adaptive,
                                  .innovation_m = {0.5, -0.25}, .innovation_var_m2 = 4.5, .test_ratio = 0.125,
                                  .alpha = 0.5, .accepted = true, .reason = sf_fix_reason_accepted,
                                  .accuracy_factor = 0.375, .drift = 0.125};
    sf_publish_fix(out, 11, &audit);
    const sf_pose_t pose = {.t_us = 7000001, .x_m = 1.5, .y_m = 2.5, .floor = -1, .heading_rad = 0.5,
                            .sigma_m = 0.75, .step_count = 12, .scheme = sf_scheme_kalman};
    sf_publish_pose(out, 12, &pose);
    const sf_step_t step = {.t_us = 7000002, .index = 12, .length_m = 0.625, .accel_range_mps2 = 4.0,
                            .period_s = 0.5, .heading_rad = 1.0, .activity = sf_activity_walking, .floor = 3};
    sf_publish_step(out, 13, &step);
    sf_input_counters_t ic = {.frames_total = 10, .bad_syntax = 2,
                              .rx = {.frames = 8, .frames_ok = 6, .imu = 4, .ble = 5, .landmark = 2, .ble_adverts = 17,
                                     .ble_dropped = 1}};
    sf_publish_sources_t src = {{0}, {0}};
    src.offered[sf_fix_wifi] = 9;
    src.made[sf_fix_wifi] = 7;
    src.offered[sf_fix_gnss] = 6;
    src.made[sf_fix_gnss] = 4;
    src.offered[sf_fix_ble] = 5;
    src.made[sf_fix_ble] = 3;
    src.offered[sf_fix_landmark] = 2;
    src.made[sf_fix_landmark] = 1;
    const sf_estimator_status_t st = {.step_count = 12, .mag_rejected = 3};
    const sf_publish_loop_t loop = {.sum_us = 30.0, .max_us = 9.0, .n = 3};
    sf_publish_health(out, 14, 7000003, &ic, &st, &src, &loop);
    sf_params_t p;
    sf_params_default(&p);
    p.stride_weinberg_k = 0.5;
    sf_publish_config(out, 15, 7000004, &p, "9.9.9", "abc");
    assert_int_equal(sf_lcm_out_close(out, NULL), SF_OK);

    lcm_eventlog_t *const log = lcm_eventlog_create(path, "r");
    assert_non_null(log);
    const char *const want[] = {"FIX", "POSE", "STEP", "HEALTH", "CONFIG"};
    for (int i = 0; i < 5; i++) {
        lcm_eventlog_event_t *const e = lcm_eventlog_read_next_event(log);
        assert_non_null(e);
        assert_string_equal(e->channel, want[i]);
        assert_int_equal(e->timestamp, 11 + i);
        if (i == 0) {
            stridefix_fix_t m;
            assert_true(stridefix_fix_t_decode(e->data, 0, e->datalen, &m) > 0);
            assert_int_equal(m.scheme, sf_scheme_adaptive);
            assert_true(m.accuracy_factor == 0.375f && m.drift == 0.125f && m.alpha == 0.5f);
            assert_true(m.innovation_m[0] == 0.5f && m.innovation_m[1] == -0.25f && m.accepted);
            assert_string_equal(m.reason_text, "accepted");
            stridefix_fix_t_decode_cleanup(&m);
        } else if (i == 1) {
            stridefix_pose_t m;
            assert_true(stridefix_pose_t_decode(e->data, 0, e->datalen, &m) > 0);
            assert_true(m.x_m == 1.5 && m.floor == -1 && m.sigma_m == 0.75f && m.scheme == sf_scheme_kalman);
        } else if (i == 2) {
            stridefix_step_t m;
            assert_true(stridefix_step_t_decode(e->data, 0, e->datalen, &m) > 0);
            assert_true(m.index == 12 && m.length_m == 0.625f && m.floor == 3);
        } else if (i == 3) {
            stridefix_health_t m;
            assert_true(stridefix_health_t_decode(e->data, 0, e->datalen, &m) > 0);
            assert_int_equal(m.t_us, 7000003);
            assert_int_equal(m.host_t_us, 14);
            assert_true(m.frames_total == 10 && m.bad_syntax == 2 && m.frames_ok == 6 && m.imu_samples == 4);
            assert_true(m.steps == 12 && m.mag_rejected == 3 && m.loop_mean_us == 10.0f && m.loop_max_us == 9.0f);
            assert_true(m.ble_scans == 5 && m.landmark_events == 2 && m.ble_adverts == 17 && m.ble_dropped == 1);
            assert_true(m.fixes_offered_wifi == 9 && m.fixes_made_wifi == 7);
            assert_true(m.fixes_offered_gnss == 6 && m.fixes_made_gnss == 4);
            assert_true(m.fixes_offered_ble == 5 && m.fixes_made_ble == 3);
            assert_true(m.fixes_offered_landmark == 2 && m.fixes_made_landmark == 1);
        } else {
            stridefix_config_t m;
            assert_true(stridefix_config_t_decode(e->data, 0, e->datalen, &m) > 0);
            assert_int_equal(m.n, (int32_t)sf_param_count);
            assert_string_equal(m.version, "9.9.9");
            bool found = false;
            for (int32_t k = 0; k < m.n; k++) {
                if (strcmp(m.key[k], "stride.weinberg_k") == 0) {
                    assert_string_equal(m.value[k], "0.5");
                    found = true;
                }
            }
            assert_true(found);
            stridefix_config_t_decode_cleanup(&m);
        }
        lcm_eventlog_free_event(e);
    }
    assert_null(lcm_eventlog_read_next_event(log));
    lcm_eventlog_destroy(log);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_output_round_trips),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
