/* sf_estimator_fix.c — the estimator's absolute fixes (see sf_estimator.h): a Wi-Fi scan matched on
 * the radio map (sf_fingerprint), a GNSS fix through the geo-reference (sf_geo), a BLE scan ranged to
 * the site's beacons (sf_ble), a landmark as it is, and the staircase endpoint of a controller event;
 * each fix then votes on the floor and is offered to every scheme (sf_fusion), and a Kalman-accepted
 * Wi-Fi or landmark fix recalibrates the stride. Around each: the controller's CLS gets the raw reading
 * first, its policy may keep the source off (CONTEXT_OFF audits; never a landmark), and the controller
 * steps after it (sf_estimator_run_controller, sf_estimator.c).
 *
 * DEVIATION: not a leaf. sf_estimator is one module over one state, sf_estimator_t, whose fix inputs
 * (here) and sample inputs (sf_estimator.c) are both public entry points; it is split in two files only
 * for the 500-line cap. A fix reads and moves most of that state (the floor and its vote, every scheme,
 * the stride calibration, the source quality, the controller), so it cannot have a small state of its
 * own, and every input ends with the controller's step, which the IMU path takes too. What is kept:
 * the calls go one way, from this file into sf_estimator.c (that one function, four call sites), never
 * back; sf_estimator.c calls nothing here. */
#include <math.h>

#include "sf_ble.h"
#include "sf_cls.h"
#include "sf_error.h"
#include "sf_estimator.h"
#include "sf_estimator_internal.h"
#include "sf_geo.h"

/* A Kalman-accepted fix: recalibrate K over the walk since the previous one (see sf_estimator.h). */
static void calibrate_stride(sf_estimator_t *const e, const sf_params_t *const p, const sf_fix_t *const fix)
{
    if (!p->stride_calib_enable) {
        return;
    }
    if (e->calib_anchor_valid) {
        const double walked_m = e->distance_m - e->calib_distance_m;
        if (walked_m < p->stride_min_calib_distance_m) {
            return; /* keep the anchor: the walk is still too short */
        }
        const double d_fix_m = hypot(fix->x_m - e->calib_fix_x_m, fix->y_m - e->calib_fix_y_m);
        const double d_pdr_m = hypot(e->x_m - e->calib_pdr_x_m, e->y_m - e->calib_pdr_y_m);
        if (d_pdr_m >= p->stride_calib_straightness * walked_m && d_pdr_m > 0.0 &&
            sf_stride_calibrate(&e->stride, p, walked_m * d_fix_m / d_pdr_m, e->weinberg_sum) == SF_OK) {
            e->stride_calibrations++;
        }
    }
    e->calib_anchor_valid = true;
    e->calib_fix_x_m = fix->x_m;
    e->calib_fix_y_m = fix->y_m;
    e->calib_pdr_x_m = e->x_m;
    e->calib_pdr_y_m = e->y_m;
    e->calib_distance_m = e->distance_m;
    e->weinberg_sum = 0.0;
}

/* A fix's floor votes on the start floor (sf_floor_vote.h); the barometric floor is renumbered. */
static void vote_floor(sf_estimator_t *const e, const sf_params_t *const p, const sf_fix_t *const fix)
{
    if (e->floor_vote_active) {
        const int32_t shift = sf_floor_vote_fix(&e->floor_vote, p, fix, sf_floor_current(&e->floor),
                                                sf_floor_settled(&e->floor, p));
        sf_floor_shift(&e->floor, shift, false);
    }
}

/* Every scheme judges the fix (one audit each); the floor vote first when the fix knows its floor. */
static int offer_fix(sf_estimator_t *const e, const sf_params_t *const p, const sf_fix_t *const fix, const bool votes,
                     sf_fix_audit_t audits[sf_scheme_count])
{
    if (votes) { /* the fix votes before the schemes see it */
        vote_floor(e, p, fix);
    }
    /* between floors (the activity's stairs or moving lift, or a landing half-way up) only where there
     * are floors to be between; a phone moved in the hand is not (settled's 0.1 m/s is for the vote) */
    const int8_t activity = sf_activity_current(&e->activity);
    const bool climbing = activity == sf_activity_stairs_up || activity == sf_activity_stairs_down ||
                          activity == sf_activity_elevator;
    const bool between = p->floor_between_reject && e->floor_vote_active && e->floor_vote.n_floors > 1 &&
                         (climbing || !sf_floor_at_floor(&e->floor, p));
    const int16_t floor = sf_floor_current(&e->floor);
    for (int s = 0; s < sf_scheme_count; s++) {
        (void)sf_fusion_fix_on_floor(&e->fusion[s], p, fix, floor, between, &audits[s]);
    }
    /* the stride is calibrated on fixes whose error does not grow with the building: Wi-Fi (as since
     * the first absolute fixes) and landmarks; GNSS and BLE fixes err by metres over a few metres of walk */
    if (audits[sf_scheme_kalman].accepted && (fix->method == sf_fix_wifi || fix->method == sf_fix_landmark)) {
        calibrate_stride(e, p, fix);
    }
    return sf_scheme_count;
}

/* No fix from this input: each scheme records the refusal, nothing moves. */
static int refuse(sf_estimator_t *const e, const int64_t t_us, const int8_t method, const int16_t n_used,
                  const int8_t reason, sf_fix_audit_t audits[sf_scheme_count])
{
    const sf_fix_t none = {.t_us = t_us, .method = method, .floor = sf_floor_current(&e->floor), .n_ap_used = n_used};
    for (int s = 0; s < sf_scheme_count; s++) {
        sf_fusion_audit_refused(&e->fusion[s], &none, reason, &audits[s]);
    }
    return sf_scheme_count;
}

static int wifi_fix(sf_estimator_t *const e, const sf_params_t *const p, const sf_wifi_scan_t *const scan,
                      sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    if (e->site == NULL || e->site->radiomap.n_rp == 0) {
        return 0;
    }
    const int16_t baro_floor = sf_floor_current(&e->floor);
    const int rc = sf_fingerprint_match(&e->fingerprint, p, &e->site->radiomap, e->ws, scan, baro_floor, true, fix);
    if (rc != SF_OK) {
        return refuse(e, scan->t_us, sf_fix_wifi, (int16_t)e->fingerprint.audit.n_used, sf_fix_reason_too_few_aps,
                      audits);
    }
    *has_fix = true;
    const int n = offer_fix(e, p, fix, true, audits);
    /* the reference for GNSS and BLE: a Wi-Fi fix the kalman scheme took (as for the stride): one it
     * gated is off the walk, outdoors beyond the radio map or between its reference points */
    if (audits[sf_scheme_kalman].accepted) {
        sf_source_quality_reference(&e->quality, fix, e->x_m, e->y_m, e->distance_m);
    }
    return n;
}

/* A GNSS or BLE fix at the accuracy its source delivers on this walk (sf_source_quality.h). */
static void judge_source(sf_estimator_t *const e, const sf_params_t *const p, sf_fix_t *const fix)
{
    const double k = sf_source_quality_judge(&e->quality, p, fix, e->x_m, e->y_m, e->distance_m);
    if (p->quality_enable) {
        fix->accuracy_m *= k;
    }
}

static int gnss_fix(sf_estimator_t *const e, const sf_params_t *const p, const sf_gnss_t *const gnss,
                      sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    if (e->site == NULL || !e->site->geo.valid || p->gnss_use == 0) {
        return 0;
    }
    double x_m, y_m;
    const double acc_m = gnss->accuracy_m * p->gnss_accuracy_scale;
    if (!(isfinite(acc_m) && acc_m >= 0.0 && acc_m <= p->gnss_max_accuracy_m) ||
        sf_geo_to_map(&e->site->geo, gnss->lat_deg, gnss->lon_deg, &x_m, &y_m) != SF_OK) {
        e->gnss_refused++;
        return refuse(e, gnss->t_us, sf_fix_gnss, 0, sf_fix_reason_inaccurate, audits);
    }
    /* a GNSS fix knows no floor: it is on the caller's, and does not vote */
    *fix = (sf_fix_t){.t_us = gnss->t_us, .method = sf_fix_gnss, .x_m = x_m, .y_m = y_m,
                      .floor = sf_floor_current(&e->floor), .accuracy_m = fmax(acc_m, p->gnss_min_accuracy_m)};
    judge_source(e, p, fix);
    *has_fix = true;
    return offer_fix(e, p, fix, false, audits);
}

static int ble_fix(sf_estimator_t *const e, const sf_params_t *const p, const sf_ble_scan_t *const scan,
                     sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    if (e->site == NULL || e->site->beacons.n_beacons == 0) {
        return 0;
    }
    /* the scan votes for a floor before the fix (which uses only the beacons of the caller's floor):
     * with BLE constellations in the site, the floor they identify (measured on the survey, sf_cls.h);
     * without, the nearest known beacon by the path-loss model, if near enough */
    sf_fix_t vote = {.t_us = scan->t_us, .method = sf_fix_ble};
    const sf_context_map_t *const map = &e->site->contexts;
    const bool by_cdd = map->n_contexts > 0 && sf_cls_uses(map, sf_cls_all(map), sf_fix_ble);
    const bool votes =
        e->floor_vote_active &&
        (by_cdd ? sf_cls_ble_floor(map, scan, &vote.floor) == SF_OK
                : p->ble_floor_vote_range_m > 0.0 &&
                      sf_ble_nearest(&e->site->beacons, scan, p->ble_floor_vote_range_m, &vote) == SF_OK);
    if (votes) {
        vote.n_ap_used = (int16_t)p->fingerprint_accuracy_ref_aps; /* a full-weight vote (sf_floor_vote.h) */
        vote_floor(e, p, &vote);
        e->ble_floor_votes++;
    }
    int32_t n_used = 0;
    if (sf_ble_fix(&e->ble, p, &e->site->beacons, scan, sf_floor_current(&e->floor), fix, &n_used) != SF_OK) {
        return refuse(e, scan->t_us, sf_fix_ble, (int16_t)n_used, sf_fix_reason_too_few_aps, audits);
    }
    judge_source(e, p, fix);
    *has_fix = true;
    return offer_fix(e, p, fix, false, audits); /* on the caller's floor by construction: no vote */
}

static int landmark_fix(sf_estimator_t *const e, const sf_params_t *const p, const sf_landmark_t *const lm,
                          sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    if (!(isfinite(lm->x_m) && isfinite(lm->y_m) && isfinite(lm->accuracy_m) && lm->accuracy_m >= 0.0)) {
        e->landmarks_refused++;
        return refuse(e, lm->t_us, sf_fix_landmark, 0, sf_fix_reason_inaccurate, audits);
    }
    /* a landmark needs no site: its position is in the map frame already */
    *fix = (sf_fix_t){.t_us = lm->t_us, .method = sf_fix_landmark, .x_m = lm->x_m, .y_m = lm->y_m,
                      .floor = lm->floor, .accuracy_m = lm->accuracy_m};
    *has_fix = true;
    return offer_fix(e, p, fix, true, audits);
}

/* Whether the controller keeps this source off now; if so, *n = the CONTEXT_OFF audits written. */
static bool context_off(sf_estimator_t *const e, const sf_params_t *const p, const int8_t method, const int64_t t_us,
                        sf_fix_audit_t audits[sf_scheme_count], int *const n)
{
    if (!p->controller_gate_sources || sf_controller_source_on(&e->controller, method)) {
        return false;
    }
    e->context_off++;
    *n = refuse(e, t_us, method, 0, sf_fix_reason_context_off, audits);
    return true;
}

/* ---- the public inputs: CLS first, the controller's gate, the fix, the controller's step ---------- */

int sf_estimator_wifi(sf_estimator_t *const e, const sf_params_t *const p, const sf_wifi_scan_t *const scan,
                      sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    sf_controller_wifi(&e->controller, p, scan);
    int n;
    if (!context_off(e, p, sf_fix_wifi, scan->t_us, audits, &n)) {
        n = wifi_fix(e, p, scan, fix, has_fix, audits);
    }
    sf_estimator_run_controller(e, p, scan->t_us);
    return n;
}

int sf_estimator_gnss(sf_estimator_t *const e, const sf_params_t *const p, const sf_gnss_t *const gnss,
                      sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    e->gnss_offered++;
    sf_controller_gnss(&e->controller, p, gnss->t_us, gnss->accuracy_m);
    int n;
    if (!context_off(e, p, sf_fix_gnss, gnss->t_us, audits, &n)) {
        n = gnss_fix(e, p, gnss, fix, has_fix, audits);
    }
    sf_estimator_run_controller(e, p, gnss->t_us);
    return n;
}

int sf_estimator_ble(sf_estimator_t *const e, const sf_params_t *const p, const sf_ble_scan_t *const scan,
                     sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    sf_controller_ble(&e->controller, p, scan);
    int n;
    if (!context_off(e, p, sf_fix_ble, scan->t_us, audits, &n)) {
        n = ble_fix(e, p, scan, fix, has_fix, audits);
    }
    sf_estimator_run_controller(e, p, scan->t_us);
    return n;
}

int sf_estimator_landmark(sf_estimator_t *const e, const sf_params_t *const p, const sf_landmark_t *const lm,
                          sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count])
{
    *has_fix = false;
    const int n = landmark_fix(e, p, lm, fix, has_fix, audits); /* a landmark overrides everything: never off */
    sf_estimator_run_controller(e, p, lm->t_us);
    return n;
}

bool sf_estimator_next_context(sf_estimator_t *const e, const sf_params_t *const p, sf_context_event_t *const ev,
                               sf_fix_t *const fix, bool *const has_fix, sf_fix_audit_t audits[sf_scheme_count],
                               int *const n_audits)
{
    *has_fix = false;
    *n_audits = 0;
    if (!sf_controller_next_event(&e->controller, ev)) {
        return false;
    }
    if (ev->recalibrated) { /* the staircase's endpoint on the new floor: a known position */
        *fix = (sf_fix_t){.t_us = ev->t_us, .method = sf_fix_port, .x_m = ev->recal_x_m, .y_m = ev->recal_y_m,
                          .floor = ev->floor, .accuracy_m = p->controller_recal_sigma_m};
        *has_fix = true;
        *n_audits = offer_fix(e, p, fix, true, audits);
    }
    return true;
}
