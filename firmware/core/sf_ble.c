/* sf_ble.c — see sf_ble.h for the path-loss model and the fix. */
#include "sf_ble.h"

#include <math.h>
#include <stddef.h>

#include "sf_error.h"
#include "sf_math.h"

#define LN10 2.302585092994046

typedef struct {
    int32_t beacon;  /* index into the site's table */
    double sum_dbm;  /* of the window's readings */
    int32_t count;
} group_t;

static int32_t find_beacon(const sf_beacons_t *const b, const int64_t id)
{
    int32_t lo = 0, hi = b->n_beacons - 1;
    while (lo <= hi) {
        const int32_t mid = lo + (hi - lo) / 2;
        if (b->id[mid] == id) {
            return mid;
        }
        if (b->id[mid] < id) {
            lo = mid + 1;
        } else {
            hi = mid - 1;
        }
    }
    return -1;
}

static double mean_dbm(const group_t *const g)
{
    return g->sum_dbm / (double)g->count;
}

static double p1_of(const sf_beacons_t *const b, const int32_t i)
{
    const double own = (double)b->rssi_1m_dbm[i];
    return isfinite(own) ? own : b->site_rssi_1m_dbm;
}

double sf_ble_range_m(const sf_beacons_t *const b, const double p1_dbm, const double rssi_dbm)
{
    return pow(10.0, (p1_dbm - rssi_dbm) / (10.0 * b->path_loss_exponent));
}

/* Adds a reading to its beacon's group; a window with more beacons than groups keeps the strongest. */
static void add_reading(sf_ble_t *const ble, group_t g[SF_BLE_MAX_GROUPS], int32_t *const n_groups,
                        const int32_t beacon, const double rssi_dbm)
{
    for (int32_t k = 0; k < *n_groups; k++) {
        if (g[k].beacon == beacon) {
            g[k].sum_dbm += rssi_dbm;
            g[k].count++;
            return;
        }
    }
    if (*n_groups < SF_BLE_MAX_GROUPS) {
        g[(*n_groups)++] = (group_t){beacon, rssi_dbm, 1};
        return;
    }
    int32_t weakest = 0;
    for (int32_t k = 1; k < *n_groups; k++) {
        weakest = mean_dbm(&g[k]) < mean_dbm(&g[weakest]) ? k : weakest;
    }
    ble->dropped++;
    if (rssi_dbm > mean_dbm(&g[weakest])) {
        g[weakest] = (group_t){beacon, rssi_dbm, 1};
    }
}

/* The strongest SF_BLE_MAX_USED groups first (selection; ties keep the earlier), returns how many. */
static int32_t strongest_first(group_t g[SF_BLE_MAX_GROUPS], const int32_t n_groups)
{
    const int32_t n = n_groups < SF_BLE_MAX_USED ? n_groups : SF_BLE_MAX_USED;
    for (int32_t i = 0; i < n; i++) {
        int32_t best = i;
        for (int32_t k = i + 1; k < n_groups; k++) {
            best = mean_dbm(&g[k]) > mean_dbm(&g[best]) ? k : best;
        }
        const group_t t = g[i];
        g[i] = g[best];
        g[best] = t;
    }
    return n;
}

int sf_ble_fix(sf_ble_t *const ble, const sf_params_t *const p, const sf_beacons_t *const b,
               const sf_ble_scan_t *const scan, const int16_t floor, sf_fix_t *const fix, int32_t *const n_used)
{
    if (ble == NULL || p == NULL || b == NULL || scan == NULL || fix == NULL || b->n_beacons <= 0) {
        return SF_EINVAL;
    }
    ble->scans++;
    group_t g[SF_BLE_MAX_GROUPS];
    int32_t n_groups = 0;
    for (int32_t i = 0; i < scan->n; i++) {
        const double rssi = (double)scan->rssi_dbm[i];
        if (!(isfinite(rssi) && rssi >= p->ble_min_rssi_dbm)) {
            ble->weak_or_bad++;
            continue;
        }
        const int32_t k = find_beacon(b, scan->beacon_id[i]);
        if (k < 0) {
            ble->unknown++;
        } else if (sf_ble_range_m(b, p1_of(b, k), rssi) > p->ble_max_range_m) {
            ble->weak_or_bad++; /* too far to say where */
        } else if (p->ble_same_floor != 0 && b->floor[k] != floor) {
            ble->other_floor++;
        } else {
            add_reading(ble, g, &n_groups, k, rssi);
        }
    }
    const int32_t n = strongest_first(g, n_groups);
    if (n_used != NULL) {
        *n_used = n;
    }
    if (n < p->ble_min_beacons || n == 0) {
        return SF_ERANGE;
    }

    /* the prior: the weighted centroid of the beacons, weights 1/d², σ² the weighted mean of d² */
    double bx[SF_BLE_MAX_USED], by[SF_BLE_MAX_USED], rssi[SF_BLE_MAX_USED], p1[SF_BLE_MAX_USED];
    double sw = 0.0, cx = 0.0, cy = 0.0, sd2 = 0.0;
    for (int32_t i = 0; i < n; i++) {
        bx[i] = (double)b->x_m[g[i].beacon];
        by[i] = (double)b->y_m[g[i].beacon];
        rssi[i] = mean_dbm(&g[i]);
        p1[i] = p1_of(b, g[i].beacon);
        const double d = sf_clamp(sf_ble_range_m(b, p1[i], rssi[i]), SF_BLE_RANGE_MIN_M, SF_BLE_RANGE_MAX_M);
        const double w = 1.0 / (d * d);
        sw += w;
        cx += w * bx[i];
        cy += w * by[i];
        sd2 += w * d * d;
    }
    cx /= sw;
    cy /= sw;
    const double prior_info = sw / (SF_BLE_PRIOR_SCALE * SF_BLE_PRIOR_SCALE * sd2); /* 1/σ_prior² */
    const double info_db = 1.0 / (b->range_sigma_db * b->range_sigma_db);
    const double k_db = 10.0 * b->path_loss_exponent / LN10; /* dB per unit of ln d */

    /* Gauss–Newton on the position; the normal matrix of the last step is the posterior information */
    double x = cx, y = cy, a00 = prior_info, a01 = 0.0, a11 = prior_info;
    for (int it = 0; it < SF_BLE_ITERATIONS; it++) {
        a00 = prior_info, a01 = 0.0, a11 = prior_info;
        double g0 = -prior_info * (x - cx), g1 = -prior_info * (y - cy);
        for (int32_t i = 0; i < n; i++) {
            const double dx = x - bx[i], dy = y - by[i];
            const double r = fmax(hypot(dx, dy), SF_BLE_RANGE_MIN_M);
            const double model = p1[i] - k_db * log(fmin(r, SF_BLE_RANGE_MAX_M));
            const double res = rssi[i] - model;
            /* ∂model/∂(x, y) = −k·(p − b)/r² */
            const double jx = -k_db * dx / (r * r), jy = -k_db * dy / (r * r);
            a00 += info_db * jx * jx;
            a01 += info_db * jx * jy;
            a11 += info_db * jy * jy;
            g0 += info_db * jx * res;
            g1 += info_db * jy * res;
        }
        const double det = a00 * a11 - a01 * a01;
        if (!(det > 0.0)) {
            break; /* cannot happen with the prior; keep the last position */
        }
        x += (a11 * g0 - a01 * g1) / det;
        y += (a00 * g1 - a01 * g0) / det;
    }
    const double det = a00 * a11 - a01 * a01;
    const double var_m2 = det > 0.0 ? 0.5 * (a00 + a11) / det : sd2 / sw; /* ½ trace of the inverse */
    *fix = (sf_fix_t){
        .t_us = scan->t_us,
        .method = sf_fix_ble,
        .x_m = x,
        .y_m = y,
        .floor = floor,
        .accuracy_m = fmax(sqrt(var_m2 + p->ble_position_sigma_m * p->ble_position_sigma_m), p->ble_min_accuracy_m),
        .n_ap_used = (int16_t)n,
    };
    ble->fixes++;
    return SF_OK;
}

int sf_ble_nearest(const sf_beacons_t *const b, const sf_ble_scan_t *const scan, const double max_range_m,
                   sf_fix_t *const at)
{
    int32_t best = -1;
    double best_m = max_range_m;
    for (int32_t i = 0; i < scan->n; i++) {
        const double rssi = (double)scan->rssi_dbm[i];
        const int32_t k = isfinite(rssi) ? find_beacon(b, scan->beacon_id[i]) : -1;
        const double d_m = k >= 0 ? sf_ble_range_m(b, p1_of(b, k), rssi) : INFINITY;
        if (d_m <= best_m) {
            best = k;
            best_m = d_m;
        }
    }
    if (best < 0) {
        return SF_ERANGE;
    }
    *at = (sf_fix_t){.t_us = scan->t_us, .method = sf_fix_ble, .x_m = (double)b->x_m[best],
                     .y_m = (double)b->y_m[best], .floor = b->floor[best], .accuracy_m = best_m, .n_ap_used = 1};
    return SF_OK;
}
