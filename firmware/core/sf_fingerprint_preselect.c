/* sf_fingerprint_preselect.c — the WkNN candidate pre-selection (sf_fingerprint.h, "Pre-selection"):
 * a partial distance over the strongest used APs ranks the RPs they reach, and only the best-ranked
 * are scored in full, so a fix costs what those APs' coverage holds, not every entry of every AP heard.
 *
 * With g the WkNN representation (0 for an AP missing on one side), the fill-mode distance is
 *     D_r = Σ_{a ∈ Q ∪ R_r} (u_a − v_ra)²,    u_a = g(s_a), v_ra = g(μ_ra),
 * a sum of non-negative terms, so over the set S of the fingerprint_preselect_aps strongest used APs
 *     LB_r = Σ_{a ∈ S} (u_a − v_ra)² = U_S + Σ_{a ∈ S ∩ R_r} v_ra (v_ra − 2 u_a) ≤ D_r,   U_S = Σ_{a∈S} u_a²,
 * and an RP that hears none of S has LB_r = U_S. One pass over S's entries gives LB of every RP they
 * reach; the fingerprint_preselect_rps of least LB are scored exactly, each from its own entries (the
 * workspace's RP-major copy: the same terms in the same order as the full visit of sf_fingerprint.c,
 * so the same d bit for bit). When the largest LB kept and U_S both exceed the k-th best d, no RP left
 * out can be among the k best, and the answer is the full visit's (audit.preselected = 1, proven).
 * Otherwise the k best of the scored ones are taken (audit.preselected = 2): a winner of the full
 * visit whose strongest APs look unlike the scan's is then missed — the approximation the cost budget
 * buys. Fewer than k reached: undecided (the caller
 * visits everything), as it does on a walk-built map (fewer than fingerprint_preselect_min_scans scans
 * per RP) and where the pre-selection would not halve the entries visited.
 * A leaf of sf_fingerprint.c: its state is the workspace's RP-major arrays, which it builds
 * (sf_fp_preselect_prepare) from the prepared AP-major levels and reads; it calls nothing there. */
#include <math.h>

#include "sf_assert.h"
#include "sf_fingerprint_internal.h"

/* LB is summed in another order than d (rounding ~1e-16 per term); this margin is far above that and
 * far below the gaps between RPs, so "proven" is proven. */
#define PROOF_REL 1e-5
#define PROOF_ABS_DB2 1e-3

/* The fill-mode d of RP r as sf_fingerprint.c computes it, (F_r + Σ g(s)²) + Σ −2 u v over the APs
 * both hear, ascending. Branch-free: ap_query_w is −2u for a used AP and 0 for the others, and a
 * censored entry is 0 here, so every other entry adds an exact zero, which leaves a sum unchanged. */
static double exact_key(const sf_fingerprint_workspace_t *const ws, const int32_t r, const double scan_sum)
{
    const double *const w = ws->ap_query_w;
    const int32_t *const ap = ws->rp_entry_ap;
    const double *const v = ws->rp_entry_level_db;
    double acc = 0.0;
    const int32_t end = ws->rp_entry_first[r + 1];
    int32_t j = ws->rp_entry_first[r];
    for (; j + 3 < end; j += 4) { /* four per trip, still one sum in order: the loop costs less than its body */
        acc += w[ap[j]] * v[j];
        acc += w[ap[j + 1]] * v[j + 1];
        acc += w[ap[j + 2]] * v[j + 2];
        acc += w[ap[j + 3]] * v[j + 3];
    }
    for (; j < end; j++) {
        acc += w[ap[j]] * v[j];
    }
    const double d2 = ws->rp_fill_sq_db2[r] + scan_sum + acc;
    return sqrt(d2 > 0.0 ? d2 : 0.0);
}

/* Could an RP whose d² is at least lb still rank among the k best, whose worst has d = key_k? */
static bool may_beat(const double lb, const double scan_sum, const double key_k)
{
    const double t = key_k * key_k;
    return lb <= t + PROOF_REL * (t + scan_sum + fabs(lb)) + PROOF_ABS_DB2;
}

/* The n_want strongest used APs (largest u; ties: lower map index), strongest first; returns how many. */
static int32_t strongest(const sf_fingerprint_workspace_t *const ws, const int32_t n_want, int32_t *const s_ap,
                         double *const s_u)
{
    int32_t n_s = 0;
    for (int32_t qi = 0; qi < ws->n_query; qi++) {
        const int32_t a = ws->query_ap[qi];
        const double u = -0.5 * ws->ap_query_w[a];
        int32_t pos = n_s;
        while (pos > 0 && u > s_u[pos - 1]) {
            pos--;
        }
        if (pos >= n_want) {
            continue;
        }
        for (int32_t i = n_s < n_want ? n_s : n_want - 1; i > pos; i--) {
            s_ap[i] = s_ap[i - 1];
            s_u[i] = s_u[i - 1];
        }
        s_ap[pos] = a;
        s_u[pos] = u;
        n_s += n_s < n_want;
    }
    return n_s;
}

/* (key, rp) order: lower key first, ties the lower RP index. */
static bool ranks_before(const sf_fp_ranked_t a, const sf_fp_ranked_t b)
{
    return a.key < b.key || (a.key == b.key && a.rp < b.rp);
}

/* Max-heap on ranks_before (the top is the worst kept). */
static void heap_push(sf_fp_ranked_t *const h, int32_t *const n, const sf_fp_ranked_t e)
{
    int32_t i = (*n)++;
    while (i > 0 && ranks_before(h[(i - 1) / 2], e)) {
        h[i] = h[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h[i] = e;
}

/* Replaces the top of the n-element heap by e and sifts it down. */
static void heap_replace_top(sf_fp_ranked_t *const h, const int32_t n, const sf_fp_ranked_t e)
{
    int32_t i = 0;
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= n) {
            break;
        }
        if (c + 1 < n && ranks_before(h[c], h[c + 1])) {
            c++;
        }
        if (!ranks_before(e, h[c])) {
            break;
        }
        h[i] = h[c];
        i = c;
    }
    if (n > 0) {
        h[i] = e;
    }
}

void sf_fp_preselect_prepare(sf_fingerprint_workspace_t *const ws, const sf_radiomap_t *const map)
{
    int32_t *const cursor = ws->touched; /* scratch, zeroed again below */
    for (int32_t r = 0; r < map->n_rp; r++) {
        cursor[r] = 0;
    }
    for (int32_t i = 0; i < map->n_entries; i++) {
        cursor[map->entry_rp[i]]++;
    }
    ws->rp_entry_first[0] = 0;
    for (int32_t r = 0; r < map->n_rp; r++) {
        ws->rp_entry_first[r + 1] = ws->rp_entry_first[r] + cursor[r];
        cursor[r] = ws->rp_entry_first[r];
    }
    for (int32_t a = 0; a < map->n_ap; a++) {
        for (int32_t i = map->ap_first[a]; i < map->ap_first[a + 1]; i++) {
            const int32_t j = cursor[map->entry_rp[i]]++;
            const double g = ws->entry_level_db[i];
            ws->rp_entry_ap[j] = a;
            ws->rp_entry_level_db[j] = g < 0.0 ? 0.0 : g;
        }
    }
    for (int32_t r = 0; r < map->n_rp; r++) {
        cursor[r] = 0;
    }
}

bool sf_fp_preselect(const sf_radiomap_t *const map, sf_fingerprint_workspace_t *const ws, const sf_params_t *const p,
                     const int16_t floor_hint, const bool any_floor, const double scan_sum, const int32_t k,
                     sf_fp_ranked_t *const best, int32_t *const n_best, sf_fingerprint_audit_t *const au)
{
    SF_ASSERT(k >= 1 && k <= SF_FINGERPRINT_K_MAX && map->n_rp > 0);
    *n_best = 0;
    if (ws->rp_scans_mean < (double)p->fingerprint_preselect_min_scans) {
        return false; /* a walk-built map: an AP missing at an RP may just not have been scanned there */
    }
    int32_t s_ap[SF_FINGERPRINT_PRESELECT_APS_MAX];
    double s_u[SF_FINGERPRINT_PRESELECT_APS_MAX];
    const int32_t n_want = p->fingerprint_preselect_aps < SF_FINGERPRINT_PRESELECT_APS_MAX
                               ? p->fingerprint_preselect_aps
                               : SF_FINGERPRINT_PRESELECT_APS_MAX;
    const int32_t n_s = strongest(ws, n_want, s_ap, s_u);
    int32_t n_rank_max = p->fingerprint_preselect_rps < SF_FINGERPRINT_PRESELECT_RPS_MAX
                             ? p->fingerprint_preselect_rps
                             : SF_FINGERPRINT_PRESELECT_RPS_MAX;
    n_rank_max = n_rank_max < k ? k : n_rank_max;
    /* Only where it at least halves the work, an approximation being worth no less: the entries it
     * visits (S's, and the kept RPs' own, about n_entries / n_rp each) against the full visit's
     * (every used AP's). */
    int64_t work = (int64_t)n_rank_max * map->n_entries / map->n_rp;
    for (int32_t si = 0; si < n_s; si++) {
        work += map->ap_first[s_ap[si] + 1] - map->ap_first[s_ap[si]];
    }
    if (2 * work > (int64_t)au->n_entries_visited) {
        return false;
    }
    /* LB − U_S of every RP that hears one of S (touched, marked in n_common). */
    double u_s = 0.0;
    int32_t n_touched = 0;
    for (int32_t si = 0; si < n_s; si++) {
        const double u = s_u[si];
        u_s += u * u;
        const int32_t end = map->ap_first[s_ap[si] + 1];
        for (int32_t i = map->ap_first[s_ap[si]]; i < end; i++) {
            const int32_t r = map->entry_rp[i];
            const double v = ws->entry_level_db[i];
            if (v < 0.0 || (!any_floor && map->rp_floor[r] != floor_hint)) {
                continue; /* censored at r (r does not hear it), or another floor */
            }
            if (ws->n_common[r] == 0) {
                ws->n_common[r] = 1;
                ws->acc[r] = 0.0;
                ws->touched[n_touched++] = r;
            }
            ws->acc[r] += v * (v - 2.0 * u);
        }
    }
    /* The n_rank least LB (ties: lower RP index) in a max-heap, so most RPs cost one comparison with
     * its top (the worst kept). */
    sf_fp_ranked_t rank[SF_FINGERPRINT_PRESELECT_RPS_MAX];
    int32_t n_rank = 0;
    for (int32_t t = 0; t < n_touched; t++) {
        const int32_t r = ws->touched[t];
        ws->n_common[r] = 0;
        const sf_fp_ranked_t e = {u_s + ws->acc[r], r};
        if (n_rank < n_rank_max) {
            heap_push(rank, &n_rank, e);
        } else if (ranks_before(e, rank[0])) {
            heap_replace_top(rank, n_rank, e);
        }
    }
    /* Exact scores of the kept; the worst kept LB (the heap's top) bounds every RP left out. */
    for (int32_t i = 0; i < n_rank; i++) {
        const double key = exact_key(ws, rank[i].rp, scan_sum);
        if (*n_best < k || key <= best[k - 1].key) { /* most lose to the k-th best: skip the insertion's call */
            sf_fp_insert_best(best, n_best, k, key, rank[i].rp);
        }
    }
    if (*n_best < k) {
        *n_best = 0;
        return false;
    }
    /* Proven when no RP left out can rank: those S reaches have LB ≥ the heap's top (when it is full),
     * and those it does not reach have LB = U_S. */
    const bool proven = (n_rank < n_rank_max || !may_beat(rank[0].key, scan_sum, best[k - 1].key)) &&
                        !may_beat(u_s, scan_sum, best[k - 1].key);
    au->n_touched = n_touched;
    au->n_candidates = n_rank;
    au->preselected = proven ? 1 : 2;
    return true;
}
