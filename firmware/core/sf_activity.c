/* sf_activity.c — see sf_activity.h for the rules. */
#include "sf_activity.h"

#include <math.h>

#include "sf_assert.h"

void sf_activity_init(sf_activity_t *const a, const sf_params_t *const p)
{
    (void)p;
    *a = (sf_activity_t){0};
    a->activity = sf_activity_unknown;
    a->last_detection_t_us = INT64_MIN / 2; /* no detection yet: the first one starts a bout */
    a->window_n = -1;
}

double sf_activity_variance_m2ps4(const sf_activity_t *const a)
{
    const double v = a->meansq_m2ps4 - a->mean_mps2 * a->mean_mps2;
    return v > 0.0 ? v : 0.0;
}

/* Accepted steps within the window ending at t_us, and the newest step time. */
static int32_t steps_in_window(const sf_activity_t *const a, const sf_params_t *const p, const int64_t t_us)
{
    const int64_t from_us = t_us - (int64_t)p->activity_step_window_ms * 1000;
    int32_t n = 0;
    int32_t i = a->step_head; /* newest first, back round the ring (no modulo per step) */
    for (int32_t k = 0; k < a->step_count; k++) {
        if (a->step_t_us[i] > from_us) {
            n++;
        }
        i = i > 0 ? i - 1 : SF_ACTIVITY_STEPS - 1;
    }
    return n;
}

/* steps_in_window, remembered: a step counted at t stays counted until step_t + window, an uncounted
 * one never comes back as t grows, so the count holds from the time it was taken to the earliest of
 * those ends (or until credit() adds a step). The same number as steps_in_window, without the loop
 * over the ring on every sample. */
static int32_t steps_in_window_memo(sf_activity_t *const a, const sf_params_t *const p, const int64_t t_us)
{
    if (a->window_n >= 0 && t_us >= a->window_t_us && t_us < a->window_until_us &&
        a->window_ms == p->activity_step_window_ms) {
        return a->window_n;
    }
    const int64_t w_us = (int64_t)p->activity_step_window_ms * 1000;
    int64_t until_us = INT64_MAX;
    int32_t n = 0;
    int32_t i = a->step_head; /* the ring's entries, as steps_in_window walks them */
    for (int32_t k = 0; k < a->step_count; k++) {
        const int64_t s_us = a->step_t_us[i];
        if (s_us > t_us - w_us) {
            n++;
            until_us = s_us + w_us < until_us ? s_us + w_us : until_us;
        }
        i = i > 0 ? i - 1 : SF_ACTIVITY_STEPS - 1;
    }
    a->window_n = n;
    a->window_ms = p->activity_step_window_ms;
    a->window_t_us = t_us;
    a->window_until_us = until_us;
    return n;
}

double sf_activity_step_rate_hz(const sf_activity_t *const a, const sf_params_t *const p)
{
    return (double)steps_in_window(a, p, a->last_t_us) / ((double)p->activity_step_window_ms * 1e-3);
}

static void classify(sf_activity_t *const a, const sf_params_t *const p)
{
    if (!a->started) {
        a->activity = sf_activity_unknown;
        return;
    }
    const double v = a->vspeed_mps;
    if (fabs(v) > 2.0 * p->activity_elevator_vspeed_mps) {
        a->activity = sf_activity_elevator; /* faster than anyone climbs stairs: whatever the steps say */
        return;                             /* (so the step window is not even counted) */
    }
    const int64_t t_us = a->last_t_us;
    const bool stepping = steps_in_window_memo(a, p, t_us) >= p->activity_min_steps;
    const bool recent_step =
        a->step_count > 0 && t_us - a->step_t_us[a->step_head] <= (int64_t)p->activity_still_time_ms * 1000;
    if (stepping && v > p->activity_stairs_vspeed_mps) {
        a->activity = sf_activity_stairs_up;
    } else if (stepping && v < -p->activity_stairs_vspeed_mps) {
        a->activity = sf_activity_stairs_down;
    } else if (stepping) {
        a->activity = sf_activity_walking;
    } else if (fabs(v) > p->activity_elevator_vspeed_mps) {
        a->activity = sf_activity_elevator;
    } else if (!recent_step && sf_activity_variance_m2ps4(a) < p->activity_still_var_m2ps4) {
        a->activity = sf_activity_still;
    } else if (recent_step) {
        a->activity = sf_activity_walking;
    } else {
        a->activity = sf_activity_unknown;
    }
}

static void advance_time(sf_activity_t *const a, const int64_t t_us)
{
    if (t_us > a->last_t_us) {
        a->last_t_us = t_us;
    }
}

void sf_activity_accel(sf_activity_t *const a, const sf_params_t *const p, const int64_t t_us,
                       const double accel_v_mps2)
{
    if (!isfinite(accel_v_mps2)) {
        return;
    }
    if (!a->started) {
        a->started = true;
        a->accel_t_us = t_us;
        a->last_t_us = t_us;
        a->mean_mps2 = accel_v_mps2;
        a->meansq_m2ps4 = accel_v_mps2 * accel_v_mps2;
        classify(a, p);
        return;
    }
    if (t_us <= a->accel_t_us) {
        return;
    }
    const double dt_s = (double)(t_us - a->accel_t_us) * 1e-6;
    const double k = sf_lp_gain(&a->var_gain, dt_s, p->activity_var_tau_s);
    a->mean_mps2 += k * (accel_v_mps2 - a->mean_mps2);
    a->meansq_m2ps4 += k * (accel_v_mps2 * accel_v_mps2 - a->meansq_m2ps4);
    a->accel_t_us = t_us;
    advance_time(a, t_us);
    classify(a, p);
}

/* Records one credited step at t_us. */
static void credit(sf_activity_t *const a, const int64_t t_us)
{
    a->step_head = (a->step_head + 1) % SF_ACTIVITY_STEPS;
    a->step_t_us[a->step_head] = t_us;
    if (a->step_count < SF_ACTIVITY_STEPS) {
        a->step_count++;
    }
    a->accepted_steps++;
    a->window_n = -1; /* the window's count changed */
}

/* Ends the bout being held: its detections were no walk. */
static void drop_held(sf_activity_t *const a)
{
    a->lone_steps += (uint32_t)a->held_n;
    a->held_n = 0;
}

int sf_activity_step(sf_activity_t *const a, const sf_params_t *const p, const sf_step_event_t *const ev)
{
    SF_ASSERT(a != NULL && p != NULL && ev != NULL);
    SF_ASSERT(p->activity_bout_steps >= 2 && p->activity_bout_steps <= SF_ACTIVITY_BOUT_MAX);
    if (!a->started || sf_activity_variance_m2ps4(a) < p->activity_still_var_m2ps4 ||
        fabs(a->vspeed_mps) > 2.0 * p->activity_elevator_vspeed_mps) {
        a->rejected_steps++; /* a quiet body, or one rising faster than stairs allow (a lift) */
        return 0;
    }
    /* the sway bound is the sway's rate at the fastest step rate (1 / activity_min_step_period_ms);
     * at a slower cadence the same sway turns proportionally slower (A·2πf/√2) */
    const int64_t gap_us = ev->t_us - a->last_detection_t_us;
    const int64_t min_period_us = (int64_t)p->activity_min_step_period_ms * 1000;
    const double cadence = gap_us > min_period_us && gap_us <= (int64_t)p->steps_max_period_ms * 1000
                               ? (double)min_period_us / (double)gap_us
                               : 1.0;
    if (a->rotation_radps > p->activity_max_rotation_radps ||
        sf_activity_off_axis_radps(a) > p->activity_max_off_axis_radps * cadence) {
        /* turning faster than a walker turns, or about two axes at once: a gesture; the walk starts anew */
        a->rejected_steps++;
        a->turning_steps++;
        drop_held(a);
        a->last_detection_t_us = INT64_MIN / 2;
        return 0;
    }
    const int64_t since_us = ev->t_us - a->last_detection_t_us;
    /* the next step of the same walk comes one gait period later: not sooner than a fast walker's
     * step (activity_min_step_period_ms) while the bout is unconfirmed, not later than steps_max_period_ms */
    bool in_bout = since_us <= (int64_t)p->steps_max_period_ms * 1000 &&
                   (a->held_n == 0 || since_us >= (int64_t)p->activity_min_step_period_ms * 1000);
    if (in_bout && a->held_n >= 2 && p->activity_bout_rhythm > 0.0) {
        /* a walk keeps its rhythm: the interval to this detection within the tolerance of the held one */
        const double prev = (double)(a->held_t_us[a->held_n - 1] - a->held_t_us[a->held_n - 2]);
        const double ratio = (double)since_us / prev;
        in_bout = ratio <= 1.0 + p->activity_bout_rhythm && ratio * (1.0 + p->activity_bout_rhythm) >= 1.0;
    }
    a->last_detection_t_us = ev->t_us;
    int credited = 0;
    if (!in_bout) {
        drop_held(a); /* the held detections never got their confirmation */
        a->held_t_us[a->held_n++] = ev->t_us;
    } else if (a->held_n > 0) {
        a->held_t_us[a->held_n++] = ev->t_us;
        if (a->held_n >= p->activity_bout_steps) {
            for (int32_t i = 0; i < a->held_n; i++) {
                credit(a, a->held_t_us[i]);
            }
            credited = a->held_n;
            a->held_n = 0;
        }
    } else {
        credit(a, ev->t_us);
        credited = 1;
    }
    advance_time(a, ev->t_us);
    classify(a, p);
    return credited;
}

void sf_activity_gyro(sf_activity_t *const a, const sf_params_t *const p, const int64_t t_us,
                      const double gyro_radps[3])
{
    const double w0 = gyro_radps[0], w1 = gyro_radps[1], w2 = gyro_radps[2];
    const double rate_radps = sqrt(w0 * w0 + w1 * w1 + w2 * w2);
    if (!isfinite(rate_radps)) {
        return;
    }
    /* ω ωᵀ: xx, yy, zz, xy, xz, yz */
    const double outer[6] = {w0 * w0, w1 * w1, w2 * w2, w0 * w1, w0 * w2, w1 * w2};
    if (!a->gyro_started) {
        a->gyro_started = true;
        a->gyro_t_us = t_us;
        a->rotation_radps = rate_radps;
        for (int i = 0; i < 6; i++) {
            a->gyro_moment_r2ps2[i] = outer[i];
        }
        return;
    }
    if (t_us <= a->gyro_t_us) {
        return;
    }
    const double dt_s = (double)(t_us - a->gyro_t_us) * 1e-6;
    const double k = sf_lp_gain(&a->var_gain, dt_s, p->activity_var_tau_s);
    a->rotation_radps += k * (rate_radps - a->rotation_radps);
    for (int i = 0; i < 6; i++) {
        a->gyro_moment_r2ps2[i] += k * (outer[i] - a->gyro_moment_r2ps2[i]);
    }
    a->gyro_t_us = t_us;
}

double sf_activity_off_axis_radps(const sf_activity_t *const a)
{
    /* middle eigenvalue of the symmetric 3×3 M (trigonometric solution of the characteristic cubic,
     * Smith 1961): λ1 ≥ λ2 ≥ λ3, λ2 = tr M − λ1 − λ3 */
    const double *const m = a->gyro_moment_r2ps2;
    const double off = m[3] * m[3] + m[4] * m[4] + m[5] * m[5];
    const double q = (m[0] + m[1] + m[2]) / 3.0;
    const double d0 = m[0] - q, d1 = m[1] - q, d2 = m[2] - q;
    const double p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off;
    if (!(p2 > 0.0)) {
        return sqrt(fmax(q, 0.0)); /* isotropic (or no sample yet: 0) */
    }
    const double pp = sqrt(p2 / 6.0);
    /* det((M − qI)/pp) / 2 */
    const double b0 = d0 / pp, b1 = d1 / pp, b2 = d2 / pp, b3 = m[3] / pp, b4 = m[4] / pp, b5 = m[5] / pp;
    const double det = b0 * (b1 * b2 - b5 * b5) - b3 * (b3 * b2 - b5 * b4) + b4 * (b3 * b5 - b1 * b4);
    const double r = fmin(fmax(0.5 * det, -1.0), 1.0);
    const double phi = acos(r) / 3.0;
    const double l1 = q + 2.0 * pp * cos(phi);
    const double l3 = q + 2.0 * pp * cos(phi + 2.0 * 3.14159265358979323846 / 3.0);
    return sqrt(fmax(3.0 * q - l1 - l3, 0.0));
}

void sf_activity_vspeed(sf_activity_t *const a, const sf_params_t *const p, const int64_t t_us,
                        const double vspeed_mps)
{
    if (!isfinite(vspeed_mps)) {
        return;
    }
    a->vspeed_mps = vspeed_mps;
    advance_time(a, t_us);
    classify(a, p);
}

int8_t sf_activity_current(const sf_activity_t *const a)
{
    return a->activity;
}
