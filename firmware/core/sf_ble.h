/* sf_ble.h — one BLE scan → a position fix from ranges to the site's known beacons.
 *
 * Model (log-distance path loss, the standard indoor model; e.g. Rappaport, "Wireless Communications",
 * §4.9): a beacon b at distance d is heard at RSSI = P_b − 10·n·log10(d) + ε, ε ~ N(0, σ²), with
 * P_b the RSSI at 1 m (the beacon's own when the site knows it, else the site's), n the path-loss
 * exponent and σ the shadowing spread, all from the site's beacon table (sf_beacons_t; the site
 * builder fits them on survey walks).
 *
 * The fix. The readings of the window are grouped by beacon (mean in dBm; readings weaker than
 * ble_min_rssi_dbm or that the model puts farther than ble_max_range_m, non-finite, of beacons the
 * site does not know, or — with ble_same_floor — of
 * beacons on another floor than the caller's are counted and skipped); the SF_BLE_MAX_USED strongest
 * beacons are used. The position maximises the likelihood of their RSSIs under the model with a weak
 * prior at their weighted centroid (weights 1/d², d the model's range of each reading; prior σ² = the
 * weighted mean of d²), which keeps one or two beacons well posed (one beacon: a disc about it), by
 * SF_BLE_ITERATIONS Gauss–Newton steps on the 2-D position. The accuracy is √(½ trace) of the
 * posterior covariance (the inverse of the normal matrix) with the beacons' own position uncertainty
 * ble_position_sigma_m added in quadrature, floored at ble_min_accuracy_m. Ranges are
 * clamped to SF_BLE_RANGE_MIN_M … SF_BLE_RANGE_MAX_M (the model says nothing nearer than the antenna
 * size, and a reading at the noise floor says "far", not how far).
 *
 * Errors: SF_OK with *fix filled; SF_ERANGE when fewer than ble_min_beacons usable beacons were heard
 * (no fix; the audit's reason is then too_few_aps, the caller's); SF_EINVAL for NULL or a site without
 * beacons. Counters in sf_ble_t. Cost: O(n · log n_beacons) for the lookup plus SF_BLE_ITERATIONS ×
 * SF_BLE_MAX_USED flops-dozens; no heap (the groups live on the stack, SF_BLE_MAX_GROUPS of them).
 * Memory: sizeof(sf_ble_t) = 24 B (checked ≤ 32). */
#ifndef SF_BLE_H
#define SF_BLE_H

#include <stdint.h>

#include "sf_params.h"
#include "sf_radiomap.h"
#include "sf_types.h"

#define SF_BLE_MAX_GROUPS 32 /* distinct beacons of one window considered (the strongest kept) */
#define SF_BLE_MAX_USED 8    /* the strongest beacons a fix uses */
#define SF_BLE_ITERATIONS 6  /* Gauss–Newton steps (converged to mm in the tests after 4) */
#define SF_BLE_RANGE_MIN_M 0.5
#define SF_BLE_RANGE_MAX_M 100.0
#define SF_BLE_PRIOR_SCALE 1.0 /* prior σ = this × the beacons' weighted rms range (2 halves the pull on exact
                                * readings, 0.18 → 0.05 m, but errs more in 4 dB shadowing, 3.71 → 3.91 m) */

typedef struct {
    uint32_t scans;          /* windows offered */
    uint32_t fixes;          /* fixes produced */
    uint32_t unknown;        /* readings of beacons the site does not know */
    uint32_t other_floor;    /* readings of beacons on another floor (ble_same_floor) */
    uint32_t weak_or_bad;    /* readings below ble_min_rssi_dbm or not finite */
    uint32_t dropped;        /* beacons beyond SF_BLE_MAX_GROUPS in one window (weakest dropped) */
} sf_ble_t;
_Static_assert(sizeof(sf_ble_t) <= 32, "sf_ble.h promises at most 32 B");

/* One window of readings while the caller is on `floor`: fills *fix (method sf_fix_ble, floor =
 * floor, n_ap_used = beacons used) on SF_OK; *n_used (may be NULL) is the beacons usable in any case. */
int sf_ble_fix(sf_ble_t *ble, const sf_params_t *p, const sf_beacons_t *beacons, const sf_ble_scan_t *scan,
               int16_t floor, sf_fix_t *fix, int32_t *n_used);

/* The reading of a beacon the site knows (any floor) that the model puts nearest, when within
 * max_range_m: fills *at with the beacon's position and floor (method sf_fix_ble, accuracy = its model
 * range) and returns SF_OK; else SF_ERANGE. For the floor vote: a beacon that near is on the caller's
 * floor (the range is the model's, so a site of weak beacons is judged by its own 1-m level). */
int sf_ble_nearest(const sf_beacons_t *beacons, const sf_ble_scan_t *scan, double max_range_m, sf_fix_t *at);

/* The model's range [m] of an RSSI from a beacon of RSSI-at-1-m p1_dbm (unclamped), for tests and
 * the analyzer. */
double sf_ble_range_m(const sf_beacons_t *beacons, double p1_dbm, double rssi_dbm);

#endif
