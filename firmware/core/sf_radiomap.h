/* sf_radiomap.h — the site as the core sees it: floors, map rotation and the radio map, as plain
 * read-only arrays owned by the caller (the board layer loads them from the site file, the only place
 * that allocates; see firmware/board/sf_site.h and lcmtypes/stridefix/site_t.lcm).
 *
 * Radio map layout: sparse and AP-major, which is the inverted index AP → reference points that makes
 * a match cost follow the APs heard, not the map size. Access point a (0 ≤ a < n_ap, BSSIDs ascending
 * so a scan's BSSID is found by binary search) owns entries ap_first[a] .. ap_first[a+1]−1; entry i
 * says that reference point entry_rp[i] heard it entry_count[i] times out of rp_scans[entry_rp[i]]
 * scans, with mean entry_mean_dbm[i] and spread entry_std_db[i]. Within one AP, entries are sorted by
 * reference point. Positions are in the map frame [m]; floors are indices (lowest_floor …). */
#ifndef SF_RADIOMAP_H
#define SF_RADIOMAP_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    int32_t n_ap;
    const int64_t *ap_bssid; /* [n_ap], strictly ascending */
    const int32_t *ap_first; /* [n_ap + 1], ap_first[0] = 0, ap_first[n_ap] = n_entries, non-decreasing */
    int32_t n_rp;
    const float *rp_x_m;     /* [n_rp] */
    const float *rp_y_m;     /* [n_rp] */
    const int16_t *rp_floor; /* [n_rp] */
    const int32_t *rp_scans; /* [n_rp], ≥ 1 */
    int32_t n_entries;
    const int32_t *entry_rp;       /* [n_entries], 0 ≤ value < n_rp */
    const float *entry_mean_dbm;   /* [n_entries] */
    const float *entry_std_db;     /* [n_entries], ≥ 0 */
    const int32_t *entry_count;    /* [n_entries], 1 ≤ value ≤ rp_scans[entry_rp] */
} sf_radiomap_t;

/* The ekf's Wi-Fi fix-error model as the site measured it (sf_ekf.h; the ekf.fix_* parameters when
 * not valid): one fix's error covariance = floor [m², xx, xy, yy] + accuracy² · per-accuracy² part,
 * the correlated part's σ [m] and length [m], the least white share. */
typedef struct {
    bool valid;
    double floor_cov_m2[3]; /* one fix's error = floor_cov_m2 + accuracy² · cov_per_acc2 */
    double cov_per_acc2[3];
    double bias_sigma_m;
    double bias_length_m;
    double white_share;
} sf_fix_model_t;

/* Floors and frame of the site. */
typedef struct {
    double map_rotation_deg;
    int16_t lowest_floor;
    int32_t n_floors;
    const double *floor_height_m; /* [n_floors], strictly increasing */
    sf_fix_model_t fix_model;     /* measured fix errors, if the builder had held-out walks */
    sf_radiomap_t radiomap;       /* n_rp = 0: no radio map */
} sf_site_t;

/* Checks every structural invariant above (sizes, orderings, index ranges, finite values).
 * Returns 0 (SF_OK) or SF_ERANGE; *what (may be NULL) points to a static text naming the first
 * violated invariant. Cost O(n_ap + n_rp + n_entries). */
int sf_radiomap_check(const sf_radiomap_t *map, const char **what);

/* Index of bssid in the AP table, or −1. O(log n_ap). */
int32_t sf_radiomap_find_ap(const sf_radiomap_t *map, int64_t bssid);

#endif
