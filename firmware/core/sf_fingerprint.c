/* sf_fingerprint.c — see sf_fingerprint.h for the model. */
#include "sf_fingerprint.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sf_assert.h"
#include "sf_error.h"
#include "sf_fingerprint_internal.h"

#define HALF_LOG_2PI 0.91893853320467274178

/* log N(x; mu, sigma) */
static double log_normal(const double x, const double mu, const double sigma)
{
    const double z = (x - mu) / sigma;
    return -0.5 * z * z - log(sigma) - HALF_LOG_2PI;
}

/* The level WkNN compares with a scan reading [dBm]: map_level 1 averages over every scan of the RP,
 * the misses at fill (the RP's fingerprint in the same terms as the query's missing APs); map_level 0
 * is the mean of the scans that heard the AP, as stored (one lucky detection looks as strong as a
 * steady one). */
static double entry_level(const sf_radiomap_t *const map, const int32_t entry, const sf_params_t *const p)
{
    const double mu = (double)map->entry_mean_dbm[entry];
    if (p->fingerprint_map_level == 0) {
        return mu;
    }
    const double n = (double)map->rp_scans[map->entry_rp[entry]];
    const double c = (double)map->entry_count[entry];
    return (c * mu + (n - c) * p->fingerprint_fill_dbm) / n;
}

/* The WkNN signal representation of a level [dBm]: v − f (beta 1, plain dBm above the fill level),
 * or the "powed" form |f|·((v − f)/|f|)^beta of Torres-Sospedra et al. (2015), which stretches the
 * strong levels (near APs: position-specific) and squeezes the weak ones (far APs: noisy). A level
 * at or below f is 0 in both, so an AP missing on one side still costs the other side's value². */
static double represent(const double v, const double fill, const double beta)
{
    const double u = v - fill;
    if (!(u > 0.0)) {
        return 0.0;
    }
    if (beta == 1.0) {
        return u;
    }
    const double scale = fabs(fill) > 1.0 ? fabs(fill) : 1.0;
    return scale * pow(u / scale, beta);
}

/* Detection probability of a map entry, clamped to [p, 1 - p]. */
static double detection(const sf_radiomap_t *const map, const int32_t entry, const double p_min)
{
    const double q = (double)map->entry_count[entry] / (double)map->rp_scans[map->entry_rp[entry]];
    return q < p_min ? p_min : (q > 1.0 - p_min ? 1.0 - p_min : q);
}

void sf_fingerprint_init(sf_fingerprint_t *const fp)
{
    memset(fp, 0, sizeof *fp);
}

/* The WkNN level of entry i as matched: g(entry_level), or −1 when censored (the RP "does not hear" it). */
static double entry_g(const sf_radiomap_t *const map, const int32_t i, const sf_params_t *const p)
{
    const double level = entry_level(map, i, p);
    return level >= p->fingerprint_min_rssi_dbm
               ? represent(level, p->fingerprint_fill_dbm, p->fingerprint_powed_beta)
               : -1.0;
}

/* The prepared AP-major levels the full visit reads (entry_g of every entry) and an empty query; the
 * pre-selection builds its RP-major copy from them (sf_fp_preselect_prepare). */
static void prepare_levels(sf_fingerprint_workspace_t *const ws, const sf_radiomap_t *const map,
                           const sf_params_t *const p)
{
    for (int32_t a = 0; a < map->n_ap; a++) {
        ws->ap_query_w[a] = 0.0;
        for (int32_t i = map->ap_first[a]; i < map->ap_first[a + 1]; i++) {
            ws->entry_level_db[i] = entry_g(map, i, p);
        }
    }
}

int sf_fingerprint_prepare(sf_fingerprint_workspace_t *const ws, const sf_radiomap_t *const map,
                           const sf_params_t *const p)
{
    if (ws == NULL || map == NULL || p == NULL || map->n_rp <= 0 || map->n_ap <= 0 || ws->n_rp < map->n_rp ||
        ws->rp_fill_sq_db2 == NULL || ws->rp_miss_loglik == NULL || ws->acc == NULL || ws->n_common == NULL ||
        ws->touched == NULL) {
        return SF_EINVAL;
    }
    const bool any_pre = ws->rp_entry_first != NULL || ws->rp_entry_ap != NULL ||
                         ws->rp_entry_level_db != NULL || ws->ap_query_w != NULL || ws->entry_level_db != NULL;
    const bool all_pre = ws->rp_entry_first != NULL && ws->rp_entry_ap != NULL &&
                         ws->rp_entry_level_db != NULL && ws->ap_query_w != NULL && ws->entry_level_db != NULL;
    if (any_pre && (!all_pre || ws->n_entries < map->n_entries || ws->n_ap < map->n_ap)) {
        return SF_EINVAL;
    }
    if (ws->reuse_prepared && ws->prepared && ws->map_entry_mean_dbm == map->entry_mean_dbm &&
        ws->map_n_ap == map->n_ap && ws->map_n_rp == map->n_rp && ws->map_n_entries == map->n_entries &&
        ws->fill_dbm == p->fingerprint_fill_dbm && ws->nb_p_min == p->fingerprint_nb_p_min &&
        ws->min_rssi_dbm == p->fingerprint_min_rssi_dbm && ws->map_level == p->fingerprint_map_level &&
        ws->powed_beta == p->fingerprint_powed_beta) {
        return SF_OK; /* the scratch is all zero between calls, the prepared arrays are this map's */
    }
    ws->prepared = false;
    if (sf_radiomap_check(map, NULL) != SF_OK || map->n_ap > SF_FINGERPRINT_MAX_MAP_APS) {
        return SF_ERANGE;
    }
    const double fill = p->fingerprint_fill_dbm;
    const double p_min = p->fingerprint_nb_p_min;
    const double log_not_p = log(1.0 - p_min);
    for (int32_t r = 0; r < map->n_rp; r++) {
        ws->rp_fill_sq_db2[r] = 0.0;
        ws->rp_miss_loglik[r] = (double)map->n_ap * log_not_p; /* every AP a phantom, corrected below */
        ws->acc[r] = 0.0;
        ws->n_common[r] = 0;
        ws->touched[r] = 0;
    }
    for (int32_t i = 0; i < map->n_entries; i++) {
        const int32_t r = map->entry_rp[i];
        const double level = entry_level(map, i, p);
        if (level >= p->fingerprint_min_rssi_dbm) { /* censored like the scan: see the header */
            const double v = represent(level, fill, p->fingerprint_powed_beta);
            ws->rp_fill_sq_db2[r] += v * v;
        }
        ws->rp_miss_loglik[r] += log(1.0 - detection(map, i, p_min)) - log_not_p;
    }
    if (all_pre) {
        prepare_levels(ws, map, p);
        sf_fp_preselect_prepare(ws, map);
    }
    ws->map_n_ap = map->n_ap;
    ws->map_n_rp = map->n_rp;
    ws->map_n_entries = map->n_entries;
    ws->map_entry_mean_dbm = map->entry_mean_dbm;
    ws->fill_dbm = fill;
    ws->nb_p_min = p_min;
    ws->min_rssi_dbm = p->fingerprint_min_rssi_dbm;
    ws->map_level = p->fingerprint_map_level;
    ws->powed_beta = p->fingerprint_powed_beta;
    double scans = 0.0;
    for (int32_t r = 0; r < map->n_rp; r++) {
        scans += (double)map->rp_scans[r];
    }
    ws->rp_scans_mean = scans / (double)map->n_rp;
    ws->prepared = true;
    return SF_OK;
}

/* ---- matching ------------------------------------------------------------------------------------- */

/* Adds term to RP r's partial sum, registering r on first touch. */
static void touch(sf_fingerprint_workspace_t *const ws, int32_t *const n_touched, const int32_t r, const double term)
{
    SF_ASSERT(r >= 0 && r < ws->map_n_rp);
    if (ws->n_common[r] == 0) {
        ws->touched[(*n_touched)++] = r;
        ws->acc[r] = 0.0;
    }
    ws->n_common[r]++;
    ws->acc[r] += term;
}

/* Every entry of every used AP: accumulates the per-RP partial sums (touched RPs in ws->touched),
 * scores the candidates into best[0 .. *n_best), and returns the number touched. With the prepared
 * arrays in WkNN fill mode it takes the query's weights (ap_query_w) and *scan_sum from the caller;
 * otherwise it computes *scan_sum (WkNN: Σ g(s)², naive Bayes: Σ C_a). Fills the audit's n_touched and
 * n_candidates. */
static int32_t visit_all(sf_fingerprint_workspace_t *const ws, const sf_params_t *const p,
                         const sf_radiomap_t *const map, const int16_t floor_hint, const bool any_floor, const int32_t k,
                         sf_fp_ranked_t *const best, int32_t *const n_best, sf_fingerprint_audit_t *const au,
                         double *const scan_sum)
{
    const bool bayes = p->fingerprint_method == 1;
    const bool common_only = !bayes && p->fingerprint_missing_mode == 1;
    const double fill = p->fingerprint_fill_dbm;
    const double p_min = p->fingerprint_nb_p_min;
    const double log_p = log(p_min);
    const double log_not_p = log(1.0 - p_min);
    const double sigma_floor = p->fingerprint_sigma_floor_db;
    double sum = 0.0;
    int32_t n_touched = 0;
    const bool fill_fast = !bayes && !common_only && ws->entry_level_db != NULL;
    if (fill_fast) {
        sum = *scan_sum; /* the caller's Σ g(s)², summed in this order when it set ap_query_w */
    }
    for (int32_t qi = 0; fill_fast && qi < ws->n_query; qi++) {
        /* WkNN fill mode with the prepared levels: the loop below, its mode tests hoisted and the
         * term -2·u·v as (-2u)·v, which is how C evaluates it there too (bit-identical); -2u is the
         * query's weight the caller set */
        const int32_t a = ws->query_ap[qi];
        const double w = ws->ap_query_w[a];
        const int32_t end = map->ap_first[a + 1];
        for (int32_t i = map->ap_first[a]; i < end; i++) {
            const int32_t r = map->entry_rp[i];
            const double v = ws->entry_level_db[i];
            if (v < 0.0 || (!any_floor && map->rp_floor[r] != floor_hint)) {
                continue;
            }
            if (ws->n_common[r] == 0) {
                ws->touched[n_touched++] = r;
                ws->acc[r] = 0.0;
            }
            ws->n_common[r]++;
            ws->acc[r] += w * v;
        }
    }
    for (int32_t qi = 0; !fill_fast && qi < ws->n_query; qi++) {
        const int32_t a = ws->query_ap[qi];
        const double s = ws->query_rssi_dbm[qi];
        const double u = bayes ? s - fill : represent(s, fill, p->fingerprint_powed_beta);
        const double c_a = bayes ? log_p + log_normal(s, fill, sigma_floor) - log_not_p : 0.0;
        sum += bayes ? c_a : u * u;
        const int32_t end = map->ap_first[a + 1];
        for (int32_t i = map->ap_first[a]; i < end; i++) {
            const int32_t r = map->entry_rp[i];
            if (!any_floor && map->rp_floor[r] != floor_hint) {
                continue;
            }
            double term;
            if (bayes) {
                const double mu = (double)map->entry_mean_dbm[i];
                const double q = detection(map, i, p_min);
                const double sd = (double)map->entry_std_db[i];
                term = log(q) + log_normal(s, mu, sd > sigma_floor ? sd : sigma_floor) - log(1.0 - q) - c_a;
            } else {
                const double v = ws->entry_level_db != NULL ? ws->entry_level_db[i] : entry_g(map, i, p);
                if (v < 0.0) {
                    continue; /* censored: the RP "does not hear" it, as a scan could not report it */
                }
                term = common_only ? (u - v) * (u - v) : -2.0 * u * v;
            }
            touch(ws, &n_touched, r, term);
        }
    }
    au->n_touched = n_touched;
    for (int32_t t = 0; t < n_touched; t++) {
        const int32_t r = ws->touched[t];
        double key;
        if (bayes) {
            ws->acc[r] += ws->rp_miss_loglik[r] + sum; /* now L_r */
            key = -ws->acc[r];
        } else if (common_only) {
            if (ws->n_common[r] < p->fingerprint_min_common_aps) {
                continue;
            }
            key = sqrt(ws->acc[r] / (double)ws->n_common[r]);
        } else {
            const double d2 = ws->rp_fill_sq_db2[r] + sum + ws->acc[r];
            key = sqrt(d2 > 0.0 ? d2 : 0.0);
        }
        ws->acc[r] = bayes ? ws->acc[r] : key; /* acc now holds the score: L or d */
        au->n_candidates++;
        if (*n_best < k || key <= best[k - 1].key) { /* most lose to the k-th best: skip the call */
            sf_fp_insert_best(best, n_best, k, key, r);
        }
    }
    *scan_sum = sum;
    return n_touched;
}

int sf_fingerprint_match(sf_fingerprint_t *const fp, const sf_params_t *const p, const sf_radiomap_t *const map,
                         sf_fingerprint_workspace_t *const ws, const sf_wifi_scan_t *const scan,
                         const int16_t floor_hint, const bool any_floor, sf_fix_t *const fix)
{
    if (fp == NULL || p == NULL || map == NULL || ws == NULL || scan == NULL || fix == NULL) {
        return SF_EINVAL;
    }
    if (map->n_rp <= 0 || map->n_ap <= 0 || scan->n_ap < 0 ||
        (scan->n_ap > 0 && (scan->bssid == NULL || scan->rssi_dbm == NULL))) {
        return SF_EINVAL;
    }
    if (!ws->prepared || ws->map_n_ap != map->n_ap || ws->map_n_rp != map->n_rp ||
        ws->map_n_entries != map->n_entries || ws->fill_dbm != p->fingerprint_fill_dbm ||
        ws->nb_p_min != p->fingerprint_nb_p_min || ws->min_rssi_dbm != p->fingerprint_min_rssi_dbm ||
        ws->map_level != p->fingerprint_map_level || ws->powed_beta != p->fingerprint_powed_beta) {
        return SF_EINVAL;
    }
    fp->scans++;
    const int32_t weak = sf_fp_store_scan(fp, p, map, scan);
    sf_fingerprint_audit_t *const au = &fp->audit;
    memset(au, 0, sizeof *au);
    au->t_us = scan->t_us;
    au->method = (int8_t)p->fingerprint_method;
    au->missing_mode = (int8_t)p->fingerprint_missing_mode;
    au->n_readings_weak = weak;
    for (int32_t i = 0; i < SF_FINGERPRINT_K_MAX; i++) {
        au->winner_rp[i] = -1;
    }
    sf_fp_build_query(fp, ws, p);
    if (ws->n_query < p->fingerprint_min_aps) {
        au->reason = sf_fp_too_few_aps;
        fp->rejected_too_few_aps++;
        return SF_ERANGE;
    }

    /* The k best candidates: by the pre-selection (sf_fingerprint_preselect.c) where it runs, else by
     * visiting the entries of every used AP. */
    const bool bayes = p->fingerprint_method == 1;
    const bool common_only = !bayes && p->fingerprint_missing_mode == 1;
    const bool pre = !bayes && !common_only && ws->entry_level_db != NULL; /* the arrays come together */
    int32_t k = p->fingerprint_k;
    k = k < 1 ? 1 : (k > SF_FINGERPRINT_K_MAX ? SF_FINGERPRINT_K_MAX : k);
    sf_fp_ranked_t best[SF_FINGERPRINT_K_MAX];
    int32_t n_best = 0;
    double scan_sum = 0.0; /* WkNN fill: Σ (s − f)²; naive Bayes: Σ C_a */
    bool decided = false;
    for (int32_t qi = 0; qi < ws->n_query; qi++) {
        const int32_t a = ws->query_ap[qi];
        au->n_entries_visited += map->ap_first[a + 1] - map->ap_first[a];
        if (pre) {
            const double u = represent(ws->query_rssi_dbm[qi], p->fingerprint_fill_dbm, p->fingerprint_powed_beta);
            ws->ap_query_w[a] = -2.0 * u; /* exact: a power of two */
            scan_sum += u * u;
        }
    }
    if (pre && p->fingerprint_preselect_aps > 0) {
        decided = sf_fp_preselect(map, ws, p, floor_hint, any_floor, scan_sum, k, best, &n_best, au);
    }
    const int32_t n_touched = decided ? 0 : visit_all(ws, p, map, floor_hint, any_floor, k, best, &n_best, au, &scan_sum);

    int result = SF_OK;
    if (n_best == 0) {
        au->reason = sf_fp_no_candidate;
        fp->rejected_no_candidate++;
        result = SF_ERANGE;
    } else {
        /* Weights. */
        double z = 1.0; /* naive Bayes: Σ over candidates of exp(L − L_max) */
        const double l_max = -best[0].key;
        if (bayes) {
            z = 0.0;
            for (int32_t t = 0; t < n_touched; t++) {
                z += exp(ws->acc[ws->touched[t]] - l_max);
            }
        }
        au->k_used = n_best;
        for (int32_t i = 0; i < n_best; i++) {
            const int32_t r = best[i].rp;
            au->winner_rp[i] = r;
            au->winner_score[i] = bayes ? -best[i].key : best[i].key;
            au->winner_weight[i] = bayes ? exp(-best[i].key - l_max) / z
                                         : 1.0 / (best[i].key > SF_FINGERPRINT_D_MIN_DB ? best[i].key
                                                                                        : SF_FINGERPRINT_D_MIN_DB);
        }
        /* Floor: largest summed weight; ties go to the better winner. */
        int16_t floor = map->rp_floor[best[0].rp];
        double floor_weight = -1.0;
        for (int32_t i = 0; i < n_best; i++) {
            const int16_t fl = map->rp_floor[best[i].rp];
            double total = 0.0;
            for (int32_t j = 0; j < n_best; j++) {
                total += map->rp_floor[best[j].rp] == fl ? au->winner_weight[j] : 0.0;
            }
            if (total > floor_weight) {
                floor_weight = total;
                floor = fl;
            }
        }
        /* Position: weighted mean of the winners on that floor. */
        double sw = 0.0, sx = 0.0, sy = 0.0;
        for (int32_t i = 0; i < n_best; i++) {
            const int32_t r = best[i].rp;
            if (map->rp_floor[r] == floor) {
                sw += au->winner_weight[i];
                sx += au->winner_weight[i] * (double)map->rp_x_m[r];
                sy += au->winner_weight[i] * (double)map->rp_y_m[r];
            }
        }
        const double x = sx / sw;
        const double y = sy / sw;
        /* Spread: WkNN over the winners, naive Bayes over the whole posterior, on that floor. */
        double ss = 0.0, sws = 0.0;
        if (bayes) {
            for (int32_t t = 0; t < n_touched; t++) {
                const int32_t r = ws->touched[t];
                if (map->rp_floor[r] == floor) {
                    const double w = exp(ws->acc[r] - l_max) / z;
                    const double dx = (double)map->rp_x_m[r] - x;
                    const double dy = (double)map->rp_y_m[r] - y;
                    ss += w * (dx * dx + dy * dy);
                    sws += w;
                }
            }
        } else {
            for (int32_t i = 0; i < n_best; i++) {
                const int32_t r = best[i].rp;
                if (map->rp_floor[r] == floor) {
                    const double dx = (double)map->rp_x_m[r] - x;
                    const double dy = (double)map->rp_y_m[r] - y;
                    ss += au->winner_weight[i] * (dx * dx + dy * dy);
                    sws += au->winner_weight[i];
                }
            }
        }
        const double spread = sws > 0.0 ? sqrt(ss / sws) : 0.0;
        const double acc_floor = p->fingerprint_accuracy_floor_m;
        const double ratio = (double)p->fingerprint_accuracy_ref_aps / (double)ws->n_query;
        au->spread_m = spread;
        fix->t_us = scan->t_us;
        fix->method = sf_fix_wifi;
        fix->x_m = x;
        fix->y_m = y;
        fix->floor = floor;
        fix->accuracy_m = sqrt(spread * spread + acc_floor * acc_floor) * (ratio > 1.0 ? sqrt(ratio) : 1.0);
        fix->n_ap_used = (int16_t)ws->n_query;
        fp->fixes++;
    }

    /* Leave the scratch as found. */
    for (int32_t t = 0; t < n_touched; t++) {
        ws->n_common[ws->touched[t]] = 0;
    }
    for (int32_t qi = 0; pre && qi < ws->n_query; qi++) {
        ws->ap_query_w[ws->query_ap[qi]] = 0.0;
    }
    return result;
}
