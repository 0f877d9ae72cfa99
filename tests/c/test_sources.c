/* test_sources.c — the absolute sources besides Wi-Fi: the geo-reference (sf_geo, against the
 * analyzer's projection), BLE ranging (sf_ble: exact on noiseless readings, bounded on noisy ones,
 * one beacon, other floors, unknown beacons), and the estimator's GNSS, BLE and landmark fixes through
 * every scheme (landmark puts every fusing scheme on it, wifi_only ignores other sources, inaccurate
 * GNSS refused with its reason). */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "sf_ble.h"
#include "sf_error.h"
#include "sf_estimator.h"
#include "sf_geo.h"
#include "sf_test_rng.h"

#define S_US 1000000LL

static sf_geo_ref_t gsd_geo(void)
{
    return (sf_geo_ref_t){.valid = true, .origin_lat_deg = 49.4612, .origin_lon_deg = 11.1110, .rotation_deg = 0.0};
}

/* The values of analyzer/stridefix_analyzer/datasets/gsd_convert.project for the same points (run
 * once with that function: the firmware and the importer must share one frame). */
static void test_geo_matches_the_analyzer(void **state)
{
    (void)state;
    const sf_geo_ref_t g = gsd_geo();
    double x, y;
    assert_int_equal(sf_geo_to_map(&g, 49.4612903284181, 11.1112051602244, &x, &y), SF_OK);
    assert_true(fabs(x - 14.87284637) < 1e-6 && fabs(y - 10.04620595) < 1e-6);
    assert_int_equal(sf_geo_to_map(&g, 49.4710, 11.1250, &x, &y), SF_OK);
    assert_true(fabs(x - 1014.91334263) < 1e-6 && fabs(y - 1089.94290415) < 1e-6);
}

static void test_geo_rotation_and_inverse(void **state)
{
    (void)state;
    sf_geo_ref_t g = gsd_geo();
    g.rotation_deg = 90.0; /* map x axis = north: a point 10 m north is at x = 10 */
    double lat, lon, x, y;
    sf_geo_ref_t g0 = gsd_geo();
    assert_int_equal(sf_geo_from_map(&g0, 0.0, 10.0, &lat, &lon), SF_OK); /* 10 m north in east-north */
    assert_int_equal(sf_geo_to_map(&g, lat, lon, &x, &y), SF_OK);
    assert_true(fabs(x - 10.0) < 1e-9 && fabs(y) < 1e-9);
    g.rotation_deg = 33.0;
    assert_int_equal(sf_geo_from_map(&g, -123.4, 56.7, &lat, &lon), SF_OK);
    assert_int_equal(sf_geo_to_map(&g, lat, lon, &x, &y), SF_OK);
    assert_true(fabs(x + 123.4) < 1e-9 && fabs(y - 56.7) < 1e-9);
    /* refused: no geo-reference, out of range, another continent */
    sf_geo_ref_t none = {0};
    assert_int_equal(sf_geo_to_map(&none, 49.0, 11.0, &x, &y), SF_EINVAL);
    assert_int_equal(sf_geo_to_map(&g, 91.0, 11.0, &x, &y), SF_ERANGE);
    assert_int_equal(sf_geo_to_map(&g, NAN, 11.0, &x, &y), SF_ERANGE);
    assert_int_equal(sf_geo_to_map(&g, 40.0, -74.0, &x, &y), SF_ERANGE);
}

/* Six beacons on two floors, the site's model P1 = −59 dBm, n = 2, σ = 4 dB. */
static const int64_t ids[] = {0x0200000001LL, 0x0200000002LL, 0x0200000003LL, 0x0200000004LL, 0x0200000005LL,
                              0x0200000006LL};
static const float bx[] = {0.0f, 20.0f, 0.0f, 20.0f, 10.0f, 10.0f};
static const float by[] = {0.0f, 0.0f, 15.0f, 15.0f, 7.0f, 7.0f};
static const int16_t bfloor[] = {0, 0, 0, 0, 0, 1};
static const float bp1[] = {NAN, NAN, NAN, NAN, -65.0f, NAN};

static sf_beacons_t beacons(void)
{
    return (sf_beacons_t){.n_beacons = 6, .id = ids, .x_m = bx, .y_m = by, .floor = bfloor,
                          .rssi_1m_dbm = bp1, .site_rssi_1m_dbm = -59.0, .path_loss_exponent = 2.0,
                          .range_sigma_db = 4.0};
}

static float model_rssi(const sf_beacons_t *const b, const int k, const double x, const double y)
{
    const double p1 = isfinite(b->rssi_1m_dbm[k]) ? b->rssi_1m_dbm[k] : b->site_rssi_1m_dbm;
    const double d = fmax(hypot(x - b->x_m[k], y - b->y_m[k]), SF_BLE_RANGE_MIN_M);
    return (float)(p1 - 10.0 * b->path_loss_exponent * log10(d));
}

static void test_ble_noiseless_is_exact(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.ble_min_rssi_dbm = -150.0;
    p.ble_max_range_m = 100.0; /* the solver on every beacon of the box */
    const sf_beacons_t b = beacons();
    sf_ble_t ble = {0};
    const double tx = 6.0, ty = 4.0;
    int64_t id[5];
    float rssi[5];
    for (int k = 0; k < 5; k++) {
        id[k] = ids[k];
        rssi[k] = model_rssi(&b, k, tx, ty);
    }
    const sf_ble_scan_t scan = {.t_us = 5 * S_US, .n = 5, .beacon_id = id, .rssi_dbm = rssi};
    sf_fix_t fix;
    int32_t used = 0;
    assert_int_equal(sf_ble_fix(&ble, &p, &b, &scan, 0, &fix, &used), SF_OK);
    print_message("noiseless: %.3f m off, accuracy %.2f m\n", hypot(fix.x_m - tx, fix.y_m - ty), fix.accuracy_m);
    /* the prior at the centroid pulls a little (0.18 m here, SF_BLE_PRIOR_SCALE says why) */
    assert_true(hypot(fix.x_m - tx, fix.y_m - ty) < 0.25);
    assert_int_equal(fix.method, sf_fix_ble);
    assert_int_equal(fix.n_ap_used, 5);
    assert_int_equal(used, 5);
    assert_true(fix.accuracy_m >= p.ble_min_accuracy_m && fix.accuracy_m < 5.0);
    /* by default the beacon 17.8 m away (20, 15) is too far to say where: four are used */
    sf_params_default(&p);
    assert_int_equal(sf_ble_fix(&ble, &p, &b, &scan, 0, &fix, &used), SF_OK);
    assert_int_equal(used, 4);
}

static void test_ble_noisy_error_is_bounded(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    p.ble_min_rssi_dbm = -150.0;
    p.ble_max_range_m = 100.0;
    const sf_beacons_t b = beacons();
    sf_ble_t ble = {0};
    rng_t r = {0x5eedULL};
    double sum_err = 0.0, sum_acc = 0.0;
    const int n = 400;
    for (int i = 0; i < n; i++) {
        const double tx = 2.0 + 16.0 * rng_uniform01(&r), ty = 2.0 + 11.0 * rng_uniform01(&r);
        int64_t id[5];
        float rssi[5];
        for (int k = 0; k < 5; k++) {
            id[k] = ids[k];
            rssi[k] = model_rssi(&b, k, tx, ty) + (float)(4.0 * rng_gauss(&r));
        }
        const sf_ble_scan_t scan = {.t_us = i * S_US, .n = 5, .beacon_id = id, .rssi_dbm = rssi};
        sf_fix_t fix;
        assert_int_equal(sf_ble_fix(&ble, &p, &b, &scan, 0, &fix, NULL), SF_OK);
        sum_err += hypot(fix.x_m - tx, fix.y_m - ty);
        sum_acc += fix.accuracy_m;
    }
    const double mean_err = sum_err / n, mean_acc = sum_acc / n;
    print_message("BLE 5 beacons, 4 dB: mean error %.2f m, mean stated accuracy %.2f m\n", mean_err, mean_acc);
    /* a random guess in the 20 × 15 m box errs ~7 m; 4 dB of shadowing at n = 2 is ~±60 % in range */
    assert_true(mean_err < 4.0);
    /* the stated 1σ per axis is of the size of the error (mean 2-D error ≈ 1.25 σ) */
    assert_true(mean_acc > 0.4 * mean_err && mean_acc < 2.5 * mean_err);
    assert_int_equal(ble.fixes, (uint32_t)n);
}

static void test_ble_one_beacon_other_floor_unknown(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    const sf_beacons_t b = beacons();
    sf_ble_t ble = {0};
    /* beacon 6 is on floor 1: skipped on floor 0; an unknown id; a reading below the floor; beacon 1
     * twice (averaged) */
    const int64_t id[] = {ids[5], 0x0300000000LL, ids[1], ids[0], ids[0]};
    const float rssi[] = {-40.0f, -50.0f, -120.0f, -70.0f, -72.0f};
    const sf_ble_scan_t scan = {.t_us = S_US, .n = 5, .beacon_id = id, .rssi_dbm = rssi};
    sf_fix_t fix;
    int32_t used = 0;
    assert_int_equal(sf_ble_fix(&ble, &p, &b, &scan, 0, &fix, &used), SF_OK);
    assert_int_equal(used, 1);
    assert_int_equal(ble.other_floor, 1);
    assert_int_equal(ble.unknown, 1);
    assert_int_equal(ble.weak_or_bad, 1);
    /* one beacon: the fix is the beacon, its accuracy the range (−71 dBm at P1 −59, n 2: 3.98 m) and
     * the beacon's own position σ in quadrature */
    assert_true(hypot(fix.x_m - 0.0, fix.y_m - 0.0) < 1e-6);
    assert_true(fabs(fix.accuracy_m - hypot(sf_ble_range_m(&b, -59.0, -71.0), p.ble_position_sigma_m)) < 0.05);
    /* nothing usable: no fix */
    p.ble_min_beacons = 2;
    assert_int_equal(sf_ble_fix(&ble, &p, &b, &scan, 0, &fix, &used), SF_ERANGE);
}

/* An estimator with a site that has a geo-reference and beacons, no radio map. */
static const double heights[] = {0.0};

static void attach(sf_estimator_t *const est, const sf_params_t *const p, sf_site_t *const site,
                   sf_fingerprint_workspace_t *const ws)
{
    static sf_particle_state_t states[SF_PARTICLE_MAX];
    static int16_t floors[SF_PARTICLE_MAX];
    *site = (sf_site_t){.lowest_floor = 0, .n_floors = 1, .floor_height_m = heights, .geo = gsd_geo(),
                        .beacons = beacons()};
    sf_estimator_init(est, p);
    assert_int_equal(sf_estimator_attach_site(est, p, site, ws), SF_OK);
    assert_int_equal(sf_estimator_attach_particles(est, p, states, floors, SF_PARTICLE_MAX, NULL), SF_OK);
}

static void test_gnss_fix_through_every_scheme(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    static sf_estimator_t est;
    static sf_fingerprint_workspace_t ws;
    sf_site_t site;
    attach(&est, &p, &site, &ws);
    sf_fix_audit_t audits[sf_scheme_count];
    sf_fix_t fix;
    bool has_fix = false;
    const sf_gnss_t g = {.t_us = 2 * S_US, .lat_deg = 49.4612903284181, .lon_deg = 11.1112051602244,
                         .accuracy_m = 0.5};
    assert_int_equal(sf_estimator_gnss(&est, &p, &g, &fix, &has_fix, audits), sf_scheme_count);
    assert_true(has_fix);
    assert_true(fabs(fix.x_m - 14.87284637) < 1e-6 && fabs(fix.y_m - 10.04620595) < 1e-6);
    assert_true(fix.accuracy_m == p.gnss_min_accuracy_m); /* 0.5 m reported: floored */
    for (int s = 0; s < sf_scheme_count; s++) {
        assert_int_equal(audits[s].method, sf_fix_gnss);
        if (s == sf_scheme_wifi_only || s == sf_scheme_pdr_only) { /* the Wi-Fi baselines */
            assert_int_equal(audits[s].reason, sf_fix_reason_scheme_ignores);
        } else {
            assert_int_equal(audits[s].reason, sf_fix_reason_initialised);
        }
    }
    /* beyond gnss_max_accuracy_m: refused, with its reason, nothing moves */
    const sf_gnss_t bad = {.t_us = 3 * S_US, .lat_deg = 49.4613, .lon_deg = 11.1113, .accuracy_m = 80.0};
    assert_int_equal(sf_estimator_gnss(&est, &p, &bad, &fix, &has_fix, audits), sf_scheme_count);
    assert_false(has_fix);
    assert_int_equal(audits[sf_scheme_kalman].reason, sf_fix_reason_inaccurate);
    sf_estimator_status_t st;
    sf_estimator_status(&est, &st);
    assert_int_equal(st.gnss_offered, 2);
    assert_int_equal(st.gnss_refused, 1);
    /* without a geo-reference: not used at all */
    site.geo.valid = false;
    assert_int_equal(sf_estimator_gnss(&est, &p, &g, &fix, &has_fix, audits), 0);
}

/* Every fusing scheme starts at a BLE fix (no Wi-Fi), then a landmark 40 m away, far outside every
 * gate: every fusing scheme is on the landmark at once. */
static void test_landmark_puts_every_scheme_on_it(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    static sf_estimator_t est;
    static sf_fingerprint_workspace_t ws;
    sf_site_t site;
    attach(&est, &p, &site, &ws);
    sf_fix_audit_t audits[sf_scheme_count];
    sf_fix_t fix;
    bool has_fix = false;
    const sf_beacons_t b = beacons();
    int64_t id[4];
    float rssi[4];
    for (int k = 0; k < 4; k++) {
        id[k] = ids[k];
        rssi[k] = model_rssi(&b, k, 10.0, 7.0);
    }
    const sf_ble_scan_t scan = {.t_us = S_US, .n = 4, .beacon_id = id, .rssi_dbm = rssi};
    assert_int_equal(sf_estimator_ble(&est, &p, &scan, &fix, &has_fix, audits), sf_scheme_count);
    assert_true(has_fix);
    assert_int_equal(audits[sf_scheme_kalman].reason, sf_fix_reason_initialised);
    assert_int_equal(audits[sf_scheme_wifi_only].reason, sf_fix_reason_scheme_ignores);
    assert_int_equal(audits[sf_scheme_pdr_only].reason, sf_fix_reason_scheme_ignores);
    const sf_landmark_t lm = {.t_us = 10 * S_US, .landmark_id = 7, .x_m = 50.0, .y_m = 7.0, .floor = 0,
                              .accuracy_m = 0.3};
    assert_int_equal(sf_estimator_landmark(&est, &p, &lm, &fix, &has_fix, audits), sf_scheme_count);
    for (int s = 0; s < sf_scheme_count; s++) {
        sf_pose_t pose;
        const bool valid = sf_estimator_scheme_pose(&est, &p, s, &pose);
        const double d = hypot(pose.x_m - lm.x_m, pose.y_m - lm.y_m);
        if (s == sf_scheme_pdr_only || s == sf_scheme_wifi_only) {
            assert_false(audits[s].accepted); /* the PDR baseline and the Wi-Fi baseline keep their own */
            assert_true(!valid || d > 30.0);
            continue;
        }
        assert_true(audits[s].accepted);
        assert_int_equal(audits[s].method, sf_fix_landmark);
        assert_true(audits[s].test_ratio > 1.0); /* far outside the gate, taken anyway */
        print_message("scheme %d: %.3f m from the landmark\n", s, d);
        assert_true(d < 0.5);
        if (s == sf_scheme_overwrite || s == sf_scheme_static || s == sf_scheme_adaptive) {
            assert_true(d < 1e-9); /* α = 1 */
        }
    }
    /* a landmark with a non-finite position: refused, counted */
    const sf_landmark_t bad = {.t_us = 11 * S_US, .x_m = NAN, .y_m = 0.0, .accuracy_m = 0.3};
    assert_int_equal(sf_estimator_landmark(&est, &p, &bad, &fix, &has_fix, audits), sf_scheme_count);
    assert_false(has_fix);
    assert_int_equal(audits[sf_scheme_ekf].reason, sf_fix_reason_inaccurate);
}

/* A loud beacon of floor 1 heard again and again while the barometer is flat on the start floor 0:
 * its floor wins the start-floor vote, and every scheme is on floor 1. */
static void test_loud_beacon_votes_for_its_floor(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    static sf_estimator_t est;
    static sf_fingerprint_workspace_t ws;
    static const double two_floors[] = {0.0, 4.0};
    const sf_site_t site = {.lowest_floor = 0, .n_floors = 2, .floor_height_m = two_floors, .geo = gsd_geo(),
                            .beacons = beacons()};
    sf_estimator_init(&est, &p);
    assert_int_equal(sf_estimator_attach_site(&est, &p, &site, &ws), SF_OK);
    sf_fix_audit_t audits[sf_scheme_count];
    sf_fix_t fix;
    bool has_fix = false;
    const int64_t id[] = {ids[5], ids[0]};
    const float rssi[] = {-62.0f, -80.0f}; /* beacon 6 (floor 1) loud, beacon 1 (floor 0) faint */
    for (int i = 0; i < 250; i++) { /* 25 Hz barometer, flat; a BLE window every second */
        sf_estimator_baro(&est, &p, S_US + (int64_t)i * 40000, 100000.0);
        if (i % 25 == 24) {
            const sf_ble_scan_t scan = {.t_us = S_US + (int64_t)i * 40000, .n = 2, .beacon_id = id, .rssi_dbm = rssi};
            (void)sf_estimator_ble(&est, &p, &scan, &fix, &has_fix, audits);
        }
    }
    sf_estimator_status_t st;
    sf_estimator_status(&est, &st);
    assert_true(est.ble_floor_votes >= 5);
    assert_int_equal(st.floor, 1);
    /* once on floor 1 the fix uses beacon 6, the floor's own */
    assert_true(has_fix);
    assert_int_equal(fix.floor, 1);
    assert_true(hypot(fix.x_m - 10.0, fix.y_m - 7.0) < 1e-6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_geo_matches_the_analyzer),
        cmocka_unit_test(test_geo_rotation_and_inverse),
        cmocka_unit_test(test_ble_noiseless_is_exact),
        cmocka_unit_test(test_ble_noisy_error_is_bounded),
        cmocka_unit_test(test_ble_one_beacon_other_floor_unknown),
        cmocka_unit_test(test_gnss_fix_through_every_scheme),
        cmocka_unit_test(test_landmark_puts_every_scheme_on_it),
        cmocka_unit_test(test_loud_beacon_votes_for_its_floor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
