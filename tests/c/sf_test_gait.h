/* sf_test_gait.h — synthetic gravity-aligned vertical acceleration of a walker, with a seeded RNG,
 * for test_steps.c and test_activity.c (header-only: static inline functions; the RNG is sf_test_rng.h).
 *
 * Waveform of step k (heel strike at t_k, period P_k, amplitude A_k):
 *   - heel strike: a sharp Gaussian spike A_k · exp(−½ ((t − t_k)/σ)²), σ = 40 ms (spikes of the
 *     neighbouring steps overlap where they reach);
 *   - swing/mid-stance: a smooth trough −B_k · sin²(π (t − t_k)/P_k) over the step, with
 *     B_k = 2 A_k σ √(2π) / P_k so each step's acceleration integrates to zero (the vertical velocity
 *     closes);
 *   - gait initiation: one trough (no spike) in the period before the first heel strike (the body dips
 *     when stepping off), and the trough after the last heel strike, then rest.
 * Step-to-step variation: P_k = P (1 ± 5 %), A_k = A (1 ± 10 %) uniform. Plus white noise per sample.
 * So a walk of n steps has exactly n heel strikes, each preceded by a trough. */
#ifndef SF_TEST_GAIT_H
#define SF_TEST_GAIT_H

#include <math.h>
#include <stdint.h>

#include "sf_test_rng.h"

#define GAIT_PI 3.14159265358979323846
#define GAIT_MAX_STEPS 400
#define GAIT_SPIKE_S 0.040

typedef struct {
    const char *name;
    double step_hz;  /* cadence */
    double amp_mps2; /* heel-strike spike amplitude */
} pace_t;

static const pace_t k_slow = {"slow 1.4 Hz", 1.4, 2.5};
static const pace_t k_normal = {"normal 1.8 Hz", 1.8, 3.5};
static const pace_t k_fast = {"fast 2.2 Hz", 2.2, 4.5};

typedef struct {
    int n;                           /* heel strikes */
    double t_s[GAIT_MAX_STEPS + 1];  /* heel-strike times; t_s[n] = end of the last step */
    double period_s[GAIT_MAX_STEPS]; /* P_k = t_s[k+1] − t_s[k] */
    double amp_mps2[GAIT_MAX_STEPS];
    double pre_s;                    /* start of the initiation trough */
} gait_t;

/* n steps at the pace, first heel strike at start_s. */
static inline void gait_make(gait_t *const g, const pace_t *const pace, const int n, const double start_s, rng_t *const r)
{
    g->n = n;
    double t = start_s;
    for (int k = 0; k < n; k++) {
        g->t_s[k] = t;
        g->period_s[k] = (1.0 / pace->step_hz) * (1.0 + 0.05 * rng_pm1(r));
        g->amp_mps2[k] = pace->amp_mps2 * (1.0 + 0.10 * rng_pm1(r));
        t += g->period_s[k];
    }
    g->t_s[n] = t;
    g->pre_s = start_s - g->period_s[0];
}

static inline double gait_trough_depth(const gait_t *const g, const int k)
{
    return 2.0 * g->amp_mps2[k] * GAIT_SPIKE_S * sqrt(2.0 * GAIT_PI) / g->period_s[k];
}

/* Noise-free a_v at time t [m/s²]. */
static inline double gait_accel(const gait_t *const g, const double t)
{
    if (g->n == 0 || t < g->pre_s || t >= g->t_s[g->n] + 0.5) {
        return 0.0;
    }
    double a = 0.0;
    if (t < g->t_s[0]) { /* initiation trough */
        const double s = sin(GAIT_PI * (t - g->pre_s) / g->period_s[0]);
        return -gait_trough_depth(g, 0) * s * s + g->amp_mps2[0] * exp(-0.5 * pow((t - g->t_s[0]) / GAIT_SPIKE_S, 2));
    }
    /* the step j containing t (binary search) */
    int lo = 0, hi = g->n; /* t_s[lo] <= t < t_s[hi] */
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (g->t_s[mid] <= t) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    const int j = lo;
    if (t < g->t_s[g->n]) {
        const double s = sin(GAIT_PI * (t - g->t_s[j]) / g->period_s[j]);
        a -= gait_trough_depth(g, j) * s * s;
    }
    for (int k = j - 1; k <= j + 1; k++) {
        if (k >= 0 && k < g->n) {
            const double u = (t - g->t_s[k]) / GAIT_SPIKE_S;
            a += g->amp_mps2[k] * exp(-0.5 * u * u);
        }
    }
    return a;
}

/* Sample clocks: uniform at rate_hz, or with each interval scaled by (1 ± jitter) uniform. */
typedef struct {
    double rate_hz;
    double jitter; /* 0.3 = ±30 % */
} clock_t_;

static inline double clock_next_dt(const clock_t_ *const c, rng_t *const r)
{
    return (1.0 / c->rate_hz) * (1.0 + c->jitter * rng_pm1(r));
}

#endif
