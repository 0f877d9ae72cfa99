/* sf_floor.c — see sf_floor.h for the model. */
#include "sf_floor.h"

#include <math.h>
#include <stddef.h>

#include "sf_assert.h"
#include "sf_error.h"

double sf_floor_pressure_to_height_m(const double pressure_pa)
{
    return 44330.77 * (1.0 - pow(pressure_pa / 101325.0, 0.190263));
}

/* Exact first-order low-pass gain for step dt and time constant tau. */
static double lp_gain(const double dt_s, const double tau_s)
{
    return -expm1(-dt_s / tau_s);
}

static int32_t index_of(const sf_floor_t *const f, const int16_t floor)
{
    return (int32_t)floor - (int32_t)f->lowest_floor;
}

static double floor_height(const sf_floor_t *const f, const int16_t floor)
{
    SF_ASSERT(index_of(f, floor) >= 0 && index_of(f, floor) < f->n_floors);
    return f->height_m[index_of(f, floor)];
}

static int16_t nearest_floor(const sf_floor_t *const f, const double h_m)
{
    int32_t best = 0;
    for (int32_t i = 1; i < f->n_floors; i++) {
        if (fabs(h_m - f->height_m[i]) < fabs(h_m - f->height_m[best])) {
            best = i;
        }
    }
    return (int16_t)(f->lowest_floor + best);
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

/* Floor control after the filters moved: start, continue, commit a change; re-reference; drift. */
static void control(sf_floor_t *const f, const sf_params_t *const p, const int64_t t_us, const double dt_s)
{
    const int16_t g = nearest_floor(f, f->height_m_f);
    const double margin = fabs(f->height_m_f - floor_height(f, f->floor)) - fabs(f->height_m_f - floor_height(f, g));
    if (g == f->floor || margin < 2.0 * p->floor_hysteresis_m) {
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
    if (f->reref_due && settled && !f->change_pending) {
        rereference(f);
    } else if (!f->reref_due && !f->change_pending && settled) {
        const double shift = lp_gain(dt_s, p->floor_drift_tau_s) * (floor_height(f, f->floor) - f->height_m_f);
        f->offset_m += shift;
        f->height_m_f += shift;
    }
}

void sf_floor_update(sf_floor_t *const f, const sf_params_t *const p, const int64_t t_us, const double pressure_pa)
{
    SF_ASSERT(f != NULL && p != NULL);
    if (!isfinite(pressure_pa) || pressure_pa < SF_FLOOR_MIN_PA || pressure_pa > SF_FLOOR_MAX_PA) {
        f->bad++;
        return;
    }
    const double h_baro = sf_floor_pressure_to_height_m(pressure_pa);
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
    f->height_m_f += lp_gain(dt_s, p->floor_height_tau_s) * (h - f->height_m_f);
    const double rate_mps = (f->height_m_f - h_prev) / dt_s;
    f->vspeed_mps += lp_gain(dt_s, p->floor_vspeed_tau_s) * (rate_mps - f->vspeed_mps);
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
