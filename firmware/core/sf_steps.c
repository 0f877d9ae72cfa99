/* sf_steps.c — see sf_steps.h for the model. */
#include "sf_steps.h"

#include <math.h>

#include "sf_assert.h"

#define PI 3.14159265358979323846

/* Exact first-order low-pass gain for a step dt: k = 1 − exp(−dt/τ), τ = 1/(2π f_c); expm1 remembered
 * for the last argument in memo. */
static double lp_gain(sf_memo_t *const memo, const double dt_s, const double cutoff_hz)
{
    return -sf_expm1_memo(memo, -dt_s * 2.0 * PI * cutoff_hz);
}

void sf_steps_init(sf_steps_t *const s, const sf_params_t *const p)
{
    *s = (sf_steps_t){0};
    s->last_step_t_us = INT64_MIN / 2;
    /* Start cautious: the noise level is unknown, so assume non-step peaks twice the lowest threshold;
     * NPK learns the real level within a few seconds of peaks. */
    s->npk = 2.0 * p->steps_pt_threshold;
}

/* Restart filters, grid and detector at sample (t, a); the previous step time survives. */
static void restart(sf_steps_t *const s, const int64_t t_us, const double a)
{
    s->started = true;
    s->last_t_us = t_us;
    s->pt1_mps2 = s->pt2_mps2 = a;
    s->tp1_mps2 = s->tp2_mps2 = a;
    s->next_grid_us = t_us;
    s->n_grid = 0;
    s->z1 = s->z2 = 0.0;
    s->cand_valid = false;
    s->trough_valid = false;
    s->ring_count = 0;
}

static void push_event(sf_steps_t *const s, const sf_step_event_t *const ev)
{
    SF_ASSERT(s->queue_count >= 0 && s->queue_count <= SF_STEPS_QUEUE);
    if (s->queue_count == SF_STEPS_QUEUE) {
        s->dropped++;
        return;
    }
    const int32_t i = (s->queue_head + s->queue_count) % SF_STEPS_QUEUE;
    s->queue[i] = *ev;
    s->queue_count++;
}

/* Builds the event for a step at step_t_us found at grid point now_us (the ring's newest). */
static bool emit(sf_steps_t *const s, const sf_params_t *const p, const int64_t step_t_us)
{
    if (step_t_us - s->last_step_t_us < (int64_t)p->steps_refractory_ms * 1000) {
        return false;
    }
    sf_step_event_t ev = {.t_us = step_t_us, .amax_mps2 = -INFINITY, .amin_mps2 = INFINITY, .period_s = 0.0};
    int32_t i = s->ring_head;
    for (int32_t k = 0; k < s->ring_count; k++) {
        if (s->ring_t_us[i] <= s->last_step_t_us) {
            break;
        }
        /* the ring holds finite values only (sf_steps_update refuses the others), so a comparison is
         * fmax/fmin without their NaN rules: inline, not two libm calls per grid point of the step */
        const double x = s->ring_mps2[i];
        ev.amax_mps2 = x > ev.amax_mps2 ? x : ev.amax_mps2;
        ev.amin_mps2 = x < ev.amin_mps2 ? x : ev.amin_mps2;
        i = (i + SF_STEPS_WINDOW - 1) % SF_STEPS_WINDOW;
    }
    if (s->ring_count == 0) { /* cannot happen: a detection needs grid points; keep the event sane */
        ev.amax_mps2 = ev.amin_mps2 = 0.0;
    }
    if (ev.amax_mps2 - ev.amin_mps2 < p->steps_min_range_mps2) {
        s->too_small++; /* the body barely moved: sensor noise or a fidget, not a step */
        return false;
    }
    const int64_t since_us = step_t_us - s->last_step_t_us;
    if (since_us <= (int64_t)p->steps_max_period_ms * 1000) {
        ev.period_s = (double)since_us * 1e-6;
    }
    s->last_step_t_us = step_t_us;
    s->steps++;
    push_event(s, &ev);
    return true;
}

static void pan_tompkins(sf_steps_t *const s, const sf_params_t *const p, const int64_t t_us, const double x)
{
    /* x_hist[0] = x(n−1) … x_hist[3] = x(n−4) */
    const double d = 0.25 * (2.0 * x + s->x_hist[0] - s->x_hist[2] - 2.0 * s->x_hist[3]);
    s->x_hist[3] = s->x_hist[2];
    s->x_hist[2] = s->x_hist[1];
    s->x_hist[1] = s->x_hist[0];
    s->x_hist[0] = x;
    if (s->n_grid < 5) { /* the derivative needs x(n−4) */
        return;
    }
    const double y = d > 0.0 ? d : 0.0;
    const double z = (1.0 + y) * (1.0 + y) - 1.0;
    const int64_t peak_t_us = t_us - SF_STEPS_GRID_US;
    if (peak_t_us - s->last_step_t_us > (int64_t)p->steps_max_period_ms * 1000) {
        /* no step for a while: let the step level fall back so a softer gait is found again */
        s->spk += (1.0 - exp(-(double)SF_STEPS_GRID_US * 1e-6 / 1.0)) * (s->npk - s->spk);
    }
    const double theta = fmax(fmax(p->steps_pt_threshold, p->steps_pt_noise_factor * s->npk),
                              s->npk + p->steps_pt_adaptive * (s->spk - s->npk));
    if (s->n_grid >= 7 && s->z1 > s->z2 && s->z1 >= z) {
        if (s->z1 > theta && peak_t_us - s->last_step_t_us >= (int64_t)p->steps_refractory_ms * 1000 &&
            (!s->cand_valid || s->z1 > s->cand_z)) {
            s->cand_valid = true; /* a first peak, or a higher one within the search time */
            s->cand_z = s->z1;
            s->cand_t_us = peak_t_us;
        } else if (s->z1 <= theta) {
            s->npk += 0.125 * (s->z1 - s->npk);
        }
    }
    if (s->cand_valid && t_us - s->cand_t_us >= (int64_t)p->steps_refractory_ms * 1000) {
        s->cand_valid = false;
        if (emit(s, p, s->cand_t_us)) {
            s->spk += 0.125 * (s->cand_z - s->spk);
        } else {
            s->npk += 0.125 * (s->cand_z - s->npk);
        }
    }
    s->z2 = s->z1;
    s->z1 = z;
}

static void trough_peak(sf_steps_t *const s, const sf_params_t *const p, const int64_t t_us, const double x)
{
    if (s->n_grid >= 3) {
        const double mid = s->tp_prev1;
        const int64_t mid_t_us = t_us - SF_STEPS_GRID_US;
        const int64_t max_us = (int64_t)p->steps_tp_max_interval_ms * 1000;
        if (mid < s->tp_prev2 && mid <= x) { /* local minimum: a trough candidate */
            if (!s->trough_valid || mid < s->trough_mps2 || mid_t_us - s->trough_t_us > max_us) {
                s->trough_valid = true;
                s->trough_mps2 = mid;
                s->trough_t_us = mid_t_us;
            }
        } else if (mid > s->tp_prev2 && mid >= x && s->trough_valid) { /* local maximum */
            if (mid_t_us - s->trough_t_us <= max_us && mid - s->trough_mps2 >= p->steps_tp_min_rise_mps2 &&
                mid_t_us - s->last_step_t_us >= (int64_t)p->steps_refractory_ms * 1000) {
                (void)emit(s, p, mid_t_us);
                s->trough_valid = false;
            }
        }
    }
    s->tp_prev2 = s->tp_prev1;
    s->tp_prev1 = x;
}

/* One grid point at t_us with the filtered values. */
static void grid_point(sf_steps_t *const s, const sf_params_t *const p, const int64_t t_us, const double x_pt,
                       const double x_tp)
{
    s->ring_head = (s->ring_head + 1) % SF_STEPS_WINDOW;
    s->ring_mps2[s->ring_head] = x_tp;
    s->ring_t_us[s->ring_head] = t_us;
    if (s->ring_count < SF_STEPS_WINDOW) {
        s->ring_count++;
    }
    if (s->n_grid < INT32_MAX) {
        s->n_grid++;
    }
    if (p->steps_detector == sf_steps_trough_peak) {
        trough_peak(s, p, t_us, x_tp);
    } else {
        pan_tompkins(s, p, t_us, x_pt);
    }
}

bool sf_steps_update(sf_steps_t *const s, const sf_params_t *const p, const int64_t t_us, const double accel_v_mps2,
                     sf_step_event_t *const ev)
{
    SF_ASSERT(s != NULL && p != NULL && ev != NULL);
    if (!isfinite(accel_v_mps2)) {
        s->bad++;
    } else if (!s->started) {
        restart(s, t_us, accel_v_mps2);
    } else if (t_us <= s->last_t_us) {
        s->backwards++;
    } else if (t_us - s->last_t_us > (int64_t)p->steps_max_gap_ms * 1000) {
        s->gaps++;
        restart(s, t_us, accel_v_mps2);
    } else {
        const int64_t t0_us = s->last_t_us;
        const double dt_s = (double)(t_us - t0_us) * 1e-6;
        const double kpt = lp_gain(&s->gain_pt, dt_s, p->steps_pt_lowpass_hz);
        const double ktp = lp_gain(&s->gain_tp, dt_s, p->steps_tp_lowpass_hz);
        const double pt0 = s->pt2_mps2, tp0 = s->tp2_mps2;
        s->pt1_mps2 += kpt * (accel_v_mps2 - s->pt1_mps2);
        s->pt2_mps2 += kpt * (s->pt1_mps2 - s->pt2_mps2);
        s->tp1_mps2 += ktp * (accel_v_mps2 - s->tp1_mps2);
        s->tp2_mps2 += ktp * (s->tp1_mps2 - s->tp2_mps2);
        s->last_t_us = t_us;
        /* Grid points in (t0, t]: linear interpolation between the filtered samples. */
        while (s->next_grid_us <= t_us) {
            const double w = (double)(s->next_grid_us - t0_us) / (double)(t_us - t0_us);
            grid_point(s, p, s->next_grid_us, pt0 + w * (s->pt2_mps2 - pt0), tp0 + w * (s->tp2_mps2 - tp0));
            s->next_grid_us += SF_STEPS_GRID_US;
        }
    }
    if (s->queue_count == 0) {
        return false;
    }
    *ev = s->queue[s->queue_head];
    s->queue_head = (s->queue_head + 1) % SF_STEPS_QUEUE;
    s->queue_count--;
    return true;
}
