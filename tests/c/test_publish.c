/* test_publish.c — sf_publish (firmware/board/sf_publish.h): what goes out is what the core said.
 * A FIX audit with the adaptive terms, a POSE, a STEP, a HEALTH and a CONFIG (and the controller's
 * CONTEXT events with their evidence in words, and HEALTH's controller counters) are written to a log,
 * read back with liblcm's reader and decoded with the generated types, field by field. Each scheme's
 * pose goes on its own channel POSE_<SCHEME> (the name from the scheme registry), the primary on POSE. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "sf_error.h"
#include "sf_fusion.h"
#include "sf_publish.h"
#include "stridefix_config_t.h"
#include "stridefix_context_t.h"
#include "stridefix_fix_t.h"
#include "stridefix_health_t.h"
#include "stridefix_pose_t.h"
#include "stridefix_step_t.h"

/* An LCM output on a fresh name in /tmp (path receives it). The log is created O_EXCL: mkstemp gives
 * the name only, not the file. */
static sf_lcm_out_t *open_fresh_log(char *const path, const size_t size)
{
    snprintf(path, size, "/tmp/sf_test_publish_XXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path);
    sf_lcm_out_t *out = NULL;
    assert_int_equal(sf_lcm_out_open(&out, path, NULL, 16, true, NULL, 0), SF_OK);
    return out;
}

static void test_every_output_round_trips(void **state)
{
    (void)state;
    char path[64];
    sf_lcm_out_t *const out = open_fresh_log(path, sizeof path);

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
    const char *const want[] = {"FIX", "POSE_KALMAN", "STEP", "HEALTH", "CONFIG"}; /* a kalman pose: its own channel */
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

/* The controller's outputs: CONTEXT field by field with the rule and its evidence in words (a stairs
 * exit with its recalibration, a door settled by the outline), HEALTH's controller counters. */
/* Every fusion scheme's poses go on POSE_ + its upper-cased registry name (pose_t.SCHEME_*: POSE_EKF
 * for ekf), the controller's and the primary pose on POSE, whatever scheme the primary copies. */
static void test_pose_channels(void **state)
{
    (void)state;
    for (int s = 0; s < sf_scheme_count; s++) {
        char want[64] = "POSE_";
        const char *const name = sf_fusion_scheme_name(s);
        assert_non_null(name);
        for (size_t k = 0; name[k] != '\0' && k + 6 < sizeof want; k++) {
            want[5 + k] = (char)toupper((unsigned char)name[k]);
        }
        assert_string_equal(sf_publish_pose_channel(s), want);
    }
    assert_string_equal(sf_publish_pose_channel(sf_scheme_controller), "POSE");

    char path[64];
    sf_lcm_out_t *const out = open_fresh_log(path, sizeof path);
    const sf_pose_t ekf = {.t_us = 5, .x_m = 4.25, .y_m = -2.0, .scheme = sf_scheme_ekf};
    const sf_pose_t controller = {.t_us = 6, .x_m = 4.25, .y_m = -2.0, .scheme = sf_scheme_controller};
    sf_publish_pose(out, 21, &ekf);
    sf_publish_primary_pose(out, 22, &ekf);
    sf_publish_pose(out, 23, &controller);
    assert_int_equal(sf_lcm_out_close(out, NULL), SF_OK);

    lcm_eventlog_t *const log = lcm_eventlog_create(path, "r");
    assert_non_null(log);
    const char *const channel[] = {"POSE_EKF", "POSE", "POSE"};
    const int scheme[] = {sf_scheme_ekf, sf_scheme_ekf, sf_scheme_controller};
    for (int i = 0; i < 3; i++) {
        lcm_eventlog_event_t *const e = lcm_eventlog_read_next_event(log);
        assert_non_null(e);
        assert_string_equal(e->channel, channel[i]);
        assert_int_equal(e->timestamp, 21 + i);
        stridefix_pose_t m;
        assert_true(stridefix_pose_t_decode(e->data, 0, e->datalen, &m) > 0);
        assert_true(m.x_m == 4.25 && m.y_m == -2.0 && m.scheme == scheme[i]);
        lcm_eventlog_free_event(e);
    }
    assert_null(lcm_eventlog_read_next_event(log));
    lcm_eventlog_destroy(log);
    unlink(path);
}

static void test_context_round_trips(void **state)
{
    (void)state;
    char path[64];
    sf_lcm_out_t *const out = open_fresh_log(path, sizeof path);
    static const int16_t kind[] = {sf_context_outdoor, sf_context_floor, sf_context_floor};
    static const int16_t building[] = {-1, 0, 0};
    static const int16_t floor[] = {0, 0, 1};
    static const int16_t port_kind[] = {sf_port_stairs};
    static const int16_t steps[] = {20};
    sf_site_t site = {.n_floors = 2};
    site.ports = (sf_ports_t){.n_ports = 1, .kind = port_kind};
    site.contexts = (sf_context_map_t){.n_contexts = 3, .kind = kind, .building = building, .floor = floor,
                                       .port_steps = steps};
    sf_params_t p;
    sf_params_default(&p);
    const sf_context_event_t stairs = {.t_us = 9000000, .state = sf_ctl_in_context, .context = 2, .prev_context = 1,
                                       .kind = sf_context_floor, .building = 0, .floor = 1, .scheme = sf_scheme_ekf,
                                       .method = sf_fix_wifi, .port = 0, .port_kind = sf_port_stairs,
                                       .rule = sf_ctl_rule_stairs, .switched = true, .steps_in_transition = 22,
                                       .cls_candidates = 2, .cls_identified = 1, .cls_method = sf_fix_wifi,
                                       .cls_hits = 4, .recalibrated = true, .recal_x_m = 7.0, .recal_y_m = 15.0,
                                       .wifi_on = true};
    sf_publish_context(out, 21, &stairs, &site, &p);
    const sf_context_event_t door = {.t_us = 9500000, .state = sf_ctl_in_context, .context = 0, .prev_context = 0,
                                     .kind = sf_context_outdoor, .building = -1, .floor = 0, .port = -1,
                                     .port_kind = sf_port_door, .rule = sf_ctl_rule_door, .steps_in_transition = 5,
                                     .cls_candidates = 2, .cls_identified = 2, .gnss_on = true};
    sf_publish_context(out, 22, &door, &site, &p);
    sf_input_counters_t ic = {0};
    const sf_publish_sources_t src = {{0}, {0}};
    const sf_publish_loop_t loop = {0};
    const sf_estimator_status_t st = {.controller_active = true, .context_transitions = 3, .context_switches = 2,
                                      .context_recalibrations = 1, .gnss_on_s = 12.5, .wifi_on_s = 30.0,
                                      .ble_on_s = 0.25};
    sf_publish_health(out, 23, 9600000, &ic, &st, &src, &loop);
    assert_int_equal(sf_lcm_out_close(out, NULL), SF_OK);

    lcm_eventlog_t *const log = lcm_eventlog_create(path, "r");
    assert_non_null(log);
    lcm_eventlog_event_t *e = lcm_eventlog_read_next_event(log);
    assert_string_equal(e->channel, "CONTEXT");
    stridefix_context_t m;
    assert_true(stridefix_context_t_decode(e->data, 0, e->datalen, &m) > 0);
    assert_true(m.t_us == 9000000 && m.state == sf_ctl_in_context && m.context == 2 && m.prev_context == 1);
    assert_true(m.kind == sf_context_floor && m.building == 0 && m.floor == 1 && m.scheme == sf_scheme_ekf);
    assert_true(m.method == sf_fix_wifi && m.port == 0 && m.port_kind == sf_port_stairs && m.rule == sf_ctl_rule_stairs);
    assert_true(m.switched && m.steps_in_transition == 22 && m.cls_candidates == 2 && m.cls_identified == 1);
    assert_true(m.cls_method == sf_fix_wifi && m.cls_hits == 4 && m.recalibrated);
    assert_true(m.recal_x_m == 7.0 && m.recal_y_m == 15.0 && !m.gnss_on && m.wifi_on && !m.ble_on);
    assert_string_equal(m.rule_text, "stairs: the staircase's steps and a unique floor: 22 of 20 steps, floor 1 of "
                                     "building 0 unique (Wi-Fi, 4 APs), recalibrated to (7.0, 15.0)");
    stridefix_context_t_decode_cleanup(&m);
    lcm_eventlog_free_event(e);
    e = lcm_eventlog_read_next_event(log);
    assert_true(stridefix_context_t_decode(e->data, 0, e->datalen, &m) > 0);
    assert_string_equal(m.rule_text, "door: steps since the transition began: 5 of 5 steps, 2 of 2 candidates "
                                     "identified: by the outline, outdoor");
    stridefix_context_t_decode_cleanup(&m);
    lcm_eventlog_free_event(e);
    e = lcm_eventlog_read_next_event(log);
    assert_string_equal(e->channel, "HEALTH");
    stridefix_health_t h;
    assert_true(stridefix_health_t_decode(e->data, 0, e->datalen, &h) > 0);
    assert_true(h.context_transitions == 3 && h.context_switches == 2 && h.context_recalibrations == 1);
    assert_true(h.gnss_on_s == 12.5f && h.wifi_on_s == 30.0f && h.ble_on_s == 0.25f);
    lcm_eventlog_free_event(e);
    assert_null(lcm_eventlog_read_next_event(log));
    lcm_eventlog_destroy(log);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_output_round_trips),
        cmocka_unit_test(test_pose_channels),
        cmocka_unit_test(test_context_round_trips),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
