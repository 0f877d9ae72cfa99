/* sf_radiomap.c — see sf_radiomap.h for the layout and its invariants. */
#include "sf_radiomap.h"

#include <math.h>
#include <stddef.h>

#include "sf_error.h"

static int fail(const char **const what, const char *const text)
{
    if (what != NULL) {
        *what = text;
    }
    return SF_ERANGE;
}

int sf_radiomap_check(const sf_radiomap_t *const map, const char **const what)
{
    if (what != NULL) {
        *what = "ok";
    }
    if (map == NULL) {
        return fail(what, "map is NULL");
    }
    if (map->n_ap < 0 || map->n_rp < 0 || map->n_entries < 0) {
        return fail(what, "negative n_ap, n_rp or n_entries");
    }
    if ((map->n_ap > 0 && (map->ap_bssid == NULL || map->ap_first == NULL)) ||
        (map->n_rp > 0 && (map->rp_x_m == NULL || map->rp_y_m == NULL || map->rp_floor == NULL ||
                           map->rp_scans == NULL)) ||
        (map->n_entries > 0 && (map->entry_rp == NULL || map->entry_mean_dbm == NULL ||
                                map->entry_std_db == NULL || map->entry_count == NULL))) {
        return fail(what, "NULL array with a non-zero size");
    }
    if (map->n_ap == 0 && map->n_entries != 0) {
        return fail(what, "entries without access points");
    }
    for (int32_t a = 1; a < map->n_ap; a++) {
        if (!(map->ap_bssid[a] > map->ap_bssid[a - 1])) {
            return fail(what, "ap_bssid not strictly ascending");
        }
    }
    if (map->n_ap > 0) {
        if (map->ap_first[0] != 0) {
            return fail(what, "ap_first[0] != 0");
        }
        for (int32_t a = 0; a < map->n_ap; a++) {
            if (map->ap_first[a + 1] < map->ap_first[a]) {
                return fail(what, "ap_first decreasing");
            }
        }
        if (map->ap_first[map->n_ap] != map->n_entries) {
            return fail(what, "ap_first[n_ap] != n_entries");
        }
    }
    for (int32_t r = 0; r < map->n_rp; r++) {
        if (!isfinite(map->rp_x_m[r]) || !isfinite(map->rp_y_m[r])) {
            return fail(what, "rp position not finite");
        }
        if (map->rp_scans[r] < 1) {
            return fail(what, "rp_scans < 1");
        }
    }
    for (int32_t a = 0; a < map->n_ap; a++) {
        for (int32_t i = map->ap_first[a]; i < map->ap_first[a + 1]; i++) {
            const int32_t r = map->entry_rp[i];
            if (r < 0 || r >= map->n_rp) {
                return fail(what, "entry_rp out of range");
            }
            if (i > map->ap_first[a] && !(r > map->entry_rp[i - 1])) {
                return fail(what, "entries of an AP not strictly ascending by rp");
            }
            if (!isfinite(map->entry_mean_dbm[i])) {
                return fail(what, "entry_mean_dbm not finite");
            }
            if (!isfinite(map->entry_std_db[i]) || map->entry_std_db[i] < 0.0f) {
                return fail(what, "entry_std_db not finite or negative");
            }
            if (map->entry_count[i] < 1 || map->entry_count[i] > map->rp_scans[r]) {
                return fail(what, "entry_count outside [1, rp_scans]");
            }
        }
    }
    return SF_OK;
}

int32_t sf_radiomap_find_ap(const sf_radiomap_t *const map, const int64_t bssid)
{
    if (map == NULL || map->n_ap <= 0 || map->ap_bssid == NULL) {
        return -1;
    }
    int32_t lo = 0;
    int32_t hi = map->n_ap - 1;
    while (lo <= hi) {
        const int32_t mid = lo + (hi - lo) / 2;
        const int64_t b = map->ap_bssid[mid];
        if (b == bssid) {
            return mid;
        }
        if (b < bssid) {
            lo = mid + 1;
        } else {
            hi = mid - 1;
        }
    }
    return -1;
}
