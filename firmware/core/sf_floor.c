/* sf_floor.c — see sf_floor.h for the model. */
#include "sf_floor.h"

#include <math.h>
#include <stddef.h>

#include "sf_assert.h"
#include "sf_error.h"
#include "sf_math.h"

#define BARO_K_M 44330.77
#define BARO_P0_PA 101325.0
#define BARO_EXP 0.190263
/* the binomial series of (1 + u)^e to u³, and where it is used: |u| ≤ 1e-3 (±101 Pa, ≈ ±8.5 m) */
#define BARO_C2 (BARO_EXP * (BARO_EXP - 1.0) / 2.0)
#define BARO_C3 (BARO_EXP * (BARO_EXP - 1.0) * (BARO_EXP - 2.0) / 6.0)
#define BARO_SERIES_MAX_U 1e-3

double sf_floor_pressure_to_height_m(const double pressure_pa)
{
    return BARO_K_M * (1.0 - pow(pressure_pa / BARO_P0_PA, BARO_EXP));
}

/* sf_floor_pressure_to_height_m without a pow per sample (sf_floor.h): (p/p0)^e = (r/p0)^e · (1 + u)^e, u = (p − r)/r
 * around a reference pressure r (the sample that last needed a pow), the binomial series to u³. The
 * first term left out, e(e−1)(e−2)(e−3)/24 · u⁴ = 0.033 u⁴, is < 3.3e-14 of the power at |u| ≤ 1e-3:
 * the height is within 2e-9 m of the pow form (≈ 2e-11 m on the sensors walk, test_floor.c), eight
 * orders below a barometer's noise (≈ 1.3 Pa ≈ 0.1 m RMS). Beyond |u| = 1e-3 (≈ 8.5 m of climb) the
 * sample becomes the reference: one pow (≈ 125 instructions, callgrind) per 8.5 m, not per sample. */
double sf_floor_baro_height_m(sf_floor_t *const f, const double pressure_pa)
{
    const double u = (pressure_pa - f->baro_ref_pa) * f->baro_ref_inv_pa;
    if (f->baro_ref_pa > 0.0 && fabs(u) <= BARO_SERIES_MAX_U) {
        const double s = 1.0 + u * (BARO_EXP + u * (BARO_C2 + u * BARO_C3));
        return BARO_K_M * (1.0 - f->baro_ref_pow * s);
    }
    f->baro_ref_pa = pressure_pa;
    f->baro_ref_inv_pa = 1.0 / pressure_pa;
    f->baro_ref_pow = pow(pressure_pa / BARO_P0_PA, BARO_EXP);
    return BARO_K_M * (1.0 - f->baro_ref_pow);
}


static int16_t to_floor16(const int32_t v)
{
    return (int16_t)(v < INT16_MIN ? INT16_MIN : (v > INT16_MAX ? INT16_MAX : v));
}

static int32_t index_of(const sf_floor_t *const f, const int16_t floor)
{
    return (int32_t)floor - (int32_t)f->lowest_floor;
}

/* Storey [m] beyond an end of the table: the end storey, or floor_height_m for a one-floor table. */
static double end_storey_m(const sf_floor_t *const f, const bool top)
{
    const int32_t n = f->n_floors;
    if (n < 2) {
        return f->storey_m;
    }
    return top ? f->height_m[n - 1] - f->height_m[n - 2] : f->height_m[1] - f->height_m[0];
}

/* Height of any floor: the table's, or extrapolated beyond its ends by the end storey (virtual floors:
 * where a wrong start floor puts the walk; sf_floor_vote.h finds it out). */
static double floor_height(const sf_floor_t *const f, const int16_t floor)
{
    const int32_t i = index_of(f, floor);
    if (i < 0) {
        return f->height_m[0] + (double)i * end_storey_m(f, false);
    }
    if (i >= f->n_floors) {
        return f->height_m[f->n_floors - 1] + (double)(i - f->n_floors + 1) * end_storey_m(f, true);
    }
    return f->height_m[i];
}

static int16_t nearest_floor(const sf_floor_t *const f, const double h_m)
{
    const int32_t n = f->n_floors;
    if (h_m < f->height_m[0]) { /* below the table: the nearest virtual floor (or the lowest) */
        const double k = floor((f->height_m[0] - h_m) / end_storey_m(f, false) + 0.5);
        return to_floor16((int32_t)f->lowest_floor - (int32_t)fmin(k, (double)SF_FLOOR_CAPACITY));
    }
    if (h_m > f->height_m[n - 1]) {
        const double k = floor((h_m - f->height_m[n - 1]) / end_storey_m(f, true) + 0.5);
        return to_floor16((int32_t)f->lowest_floor + n - 1 + (int32_t)fmin(k, (double)SF_FLOOR_CAPACITY));
    }
    if (isnan(h_m)) {
        return f->lowest_floor; /* NaN: no distance is smaller than another, the first floor */
    }
    /* The table is strictly increasing (sf_floor_set_heights checks it; the default's storey is
     * ≥ 1 m), so |h − H_i| falls, then rises with i, and rounding keeps that order (fl is
     * monotone). Bisect for lo = the last floor at or below h (H_0 ≤ h ≤ H_{n−1} here), then take
     * what a scan from floor 0 keeping the first strictly nearest would: lo + 1 when strictly nearer,
     * else the first floor at lo's distance (lo itself unless heights round to one distance).
     * O(log n) instead of O(n): 64 floors cost ~800 instructions per sample scanned. */
    int32_t lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        const int32_t mid = lo + (hi - lo) / 2;
        if (f->height_m[mid] <= h_m) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    const double d_lo = fabs(h_m - f->height_m[lo]);
    if (lo + 1 < n && fabs(h_m - f->height_m[lo + 1]) < d_lo) {
        return (int16_t)(f->lowest_floor + lo + 1);
    }
    while (lo > 0 && fabs(h_m - f->height_m[lo - 1]) == d_lo) {
        lo--;
    }
    return (int16_t)(f->lowest_floor + lo);
}

/* Moves the altimeter so the filtered height equals the current floor's height. */
static void rereference(sf_floor_t *const f)
{
    const double shift = floor_height(f, f->floor) - f->height_m_f;
    f->offset_m += shift;
    f->height_m_f += shift;
    f->reref_due = false;
    f->rereferences++;
}

void sf_floor_init(sf_floor_t *const f, const sf_params_t *const p)
{
    *f = (sf_floor_t){0};
    int32_t lowest = p->init_floor - SF_FLOOR_DEFAULT_BELOW;
    if (lowest < INT16_MIN) {
        lowest = INT16_MIN;
    }
    f->lowest_floor = (int16_t)lowest;
    f->n_floors = SF_FLOOR_CAPACITY;
    for (int32_t i = 0; i < SF_FLOOR_CAPACITY; i++) {
        f->height_m[i] = p->floor_height_m * (double)(lowest + i);
    }
    f->storey_m = p->floor_height_m;
    f->floor = (int16_t)p->init_floor;
    f->candidate = f->floor;
}

int sf_floor_set_heights(sf_floor_t *const f, const double *const floor_height_m, const int n_floors,
                         const int16_t lowest_floor)
{
    if (f == NULL || floor_height_m == NULL || n_floors < 1 || n_floors > SF_FLOOR_CAPACITY ||
        (int32_t)lowest_floor + n_floors - 1 > INT16_MAX) {
        return SF_EINVAL;
    }
    for (int i = 0; i < n_floors; i++) {
        if (!isfinite(floor_height_m[i]) || (i > 0 && !(floor_height_m[i] > floor_height_m[i - 1]))) {
            return SF_EINVAL;
        }
    }
    for (int i = 0; i < n_floors; i++) {
        f->height_m[i] = floor_height_m[i];
    }
    f->n_floors = n_floors;
    f->lowest_floor = lowest_floor;
    const int32_t highest = (int32_t)lowest_floor + n_floors - 1;
    if (f->floor < lowest_floor) {
        f->floor = lowest_floor;
    } else if (f->floor > highest) {
        f->floor = (int16_t)highest;
    }
    f->change_pending = false;
    f->candidate = f->floor;
    if (f->started) {
        rereference(f);
    }
    return SF_OK;
}

/* Whether height h_m is at the current floor: nearer its height than the neighbour's on that side by
 * the margin a floor change needs (2 · floor_hysteresis_m). Not a landing half-way up; a table storey
 * 40 % off still passes (gsd: 2.4 m storeys against a 4 m default table). */
static bool near_own_floor(const sf_floor_t *const f, const sf_params_t *const p, const double h_m)
{
    const double h0 = floor_height(f, f->floor);
    const int32_t side = h_m >= h0 ? 1 : -1;
    const double h1 = floor_height(f, to_floor16((int32_t)f->floor + side));
    return fabs(h_m - h0) < fabs(h_m - h1) - 2.0 * p->floor_hysteresis_m;
}

/* The most the drift relaxation can lag the weather [m]: the fastest pressure tendency times its time
 * constant, at the sea-level slope 1/12 m/Pa. */
static double weather_lag_m(const sf_params_t *const p)
{
    return p->floor_weather_max_hpa_per_h * 100.0 / 3600.0 / 12.0 * p->floor_drift_tau_s;
}

static void move_altimeter(sf_floor_t *const f, const double shift_m)
{
    f->offset_m += shift_m;
    f->height_m_f += shift_m;
}

/* Floor control after the filters moved: start, continue, commit a change; re-reference; drift. */
static void control(sf_floor_t *const f, const sf_params_t *const p, const int64_t t_us, const double dt_s)
{
    /* the low-pass lags a climb at speed v by v·τ (exact for a ramp): judge the lead-corrected height */
    const double h_m = f->height_m_f + f->vspeed_mps * p->floor_height_tau_s;
    const int16_t g = nearest_floor(f, h_m);
    const double margin = fabs(h_m - floor_height(f, f->floor)) - fabs(h_m - floor_height(f, g));
    /* climbing toward g, the mid-height is enough (a dog-leg's landing sits there); standing, the
     * hysteresis keeps noise and drift from flipping the floor */
    const bool toward = fabs(f->vspeed_mps) >= p->floor_settle_vspeed_mps &&
                        f->vspeed_mps * (floor_height(f, g) - floor_height(f, f->floor)) > 0.0;
    if (g == f->floor || margin < (toward ? 0.0 : 2.0 * p->floor_hysteresis_m)) {
        f->change_pending = false; /* back on (or near) the current floor: cancel */
    } else if (!f->change_pending || g != f->candidate) {
        f->change_pending = true; /* start, or restart with another candidate */
        f->candidate = g;
        f->candidate_since_us = t_us;
    }
    if (f->change_pending && t_us - f->candidate_since_us >= (int64_t)p->floor_confirm_ms * 1000) {
        f->floor = f->candidate; /* commit */
        f->change_pending = false;
        f->reref_due = true;
        f->changes++;
    }
    const bool settled = fabs(f->vspeed_mps) < p->floor_settle_vspeed_mps;
    if (f->reref_due && settled && !f->change_pending && near_own_floor(f, p, f->height_m_f)) {
        rereference(f);
    } else if (!f->reref_due && !f->change_pending && settled) {
        move_altimeter(f, sf_lp_gain(&f->gain_drift, dt_s, p->floor_drift_tau_s) * (floor_height(f, f->floor) - f->height_m_f));
    } else if (!settled && f->was_settled && !f->reref_due && f->stood_valid &&
               fabs(f->stood_height_m - floor_height(f, f->floor)) <= weather_lag_m(p)) {
        /* leaving the floor: the body stood on it until the climb began, so the climb counts from there
         * (the drift relaxation lags a weather trend by rate · floor_drift_tau_s: 0.15–0.4 m on the
         * SIL tours). The height a filter delay before (τ_h + τ_v) is the one the climb has not yet
         * moved; only a gap the weather can make is closed, a pause part-way down a stair is not a
         * floor (gsd Trial51). */
        move_altimeter(f, floor_height(f, f->floor) - f->stood_height_m);
        f->rereferences++;
    }
    f->was_settled = settled;
    const int64_t delay_us = (int64_t)((p->floor_height_tau_s + p->floor_vspeed_tau_s) * 1e6);
    if (!settled || f->reref_due) {
        f->stood_valid = false; /* a climb or an arrival: what stood before is history */
        f->recent_t_us = t_us;
        f->recent_height_m = f->height_m_f;
    } else if (t_us - f->recent_t_us >= delay_us) { /* two snapshots: the older is a delay old or more */
        f->stood_valid = true;
        f->stood_height_m = f->recent_height_m;
        f->recent_t_us = t_us;
        f->recent_height_m = f->height_m_f;
    }
}

void sf_floor_update(sf_floor_t *const f, const sf_params_t *const p, const int64_t t_us, const double pressure_pa)
{
    SF_ASSERT(f != NULL && p != NULL);
    if (!isfinite(pressure_pa) || pressure_pa < SF_FLOOR_MIN_PA || pressure_pa > SF_FLOOR_MAX_PA) {
        f->bad++;
        return;
    }
    const double h_baro = sf_floor_baro_height_m(f, pressure_pa);
    if (!f->started) {
        f->started = true;
        f->last_t_us = t_us;
        f->offset_m = floor_height(f, f->floor) - h_baro;
        f->height_m_f = floor_height(f, f->floor);
        f->vspeed_mps = 0.0;
        return;
    }
    if (t_us <= f->last_t_us) {
        f->backwards++;
        return;
    }
    const int64_t dt_us = t_us - f->last_t_us;
    const double dt_s = (double)dt_us * 1e-6;
    f->last_t_us = t_us;
    const double h = h_baro + f->offset_m;
    if (dt_us > (int64_t)p->floor_max_gap_ms * 1000) {
        f->gaps++;
        f->height_m_f = h;
        f->vspeed_mps = 0.0;
        return;
    }
    const double h_prev = f->height_m_f;
    f->height_m_f += sf_lp_gain(&f->gain_height, dt_s, p->floor_height_tau_s) * (h - f->height_m_f);
    const double rate_mps = (f->height_m_f - h_prev) / dt_s;
    f->vspeed_mps += sf_lp_gain(&f->gain_vspeed, dt_s, p->floor_vspeed_tau_s) * (rate_mps - f->vspeed_mps);
    control(f, p, t_us, dt_s);
}

int16_t sf_floor_current(const sf_floor_t *const f)
{
    return f->floor;
}

double sf_floor_vertical_speed_mps(const sf_floor_t *const f)
{
    return f->vspeed_mps;
}

double sf_floor_height_m(const sf_floor_t *const f)
{
    return f->height_m_f;
}

bool sf_floor_at_floor(const sf_floor_t *const f, const sf_params_t *const p)
{
    return f->started && !f->change_pending && near_own_floor(f, p, f->height_m_f);
}

bool sf_floor_settled(const sf_floor_t *const f, const sf_params_t *const p)
{
    return sf_floor_at_floor(f, p) && fabs(f->vspeed_mps) < p->floor_settle_vspeed_mps;
}

void sf_floor_shift(sf_floor_t *const f, const int32_t delta, const bool rereference_now)
{
    if (delta == 0) {
        return;
    }
    const int16_t to = to_floor16((int32_t)f->floor + delta);
    const double shift = floor_height(f, to) - floor_height(f, f->floor); /* keeps h_f − H(floor) */
    f->floor = to;
    f->candidate = to;
    f->change_pending = false;
    f->shifts++;
    if (f->started) {
        f->offset_m += shift;
        f->height_m_f += shift;
        if (rereference_now) {
            rereference(f);
        }
    }
}
