/* sf_math.h — the small scalar helpers every core module uses, in one place (header-only, static
 * inline: no hidden state, no cost beyond the call site's; sf_lp_gain's memory is the caller's). */
#ifndef SF_MATH_H
#define SF_MATH_H

#include <math.h>
#include <stdbool.h>

/* v limited to [lo, hi] (lo ≤ hi; NaN passes through). */
static inline double sf_clamp(const double v, const double lo, const double hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* An angle [rad] wrapped to (−π, π]. */
static inline double sf_wrap_pi(const double a)
{
    return atan2(sin(a), cos(a));
}

/* The exact first-order low-pass gain k = −expm1(−dt/τ) = 1 − e^(−dt/τ), remembered for the last
 * (dt, τ): a stream sampled at a fixed rate has one dt, so libm's expm1 runs once, not on every sample
 * (≈ 80 instructions each), and k is bit for bit what the call would give. Zero-initialised = empty. */
typedef struct {
    double dt_s;
    double tau_s;
    double k;
} sf_lp_gain_t;

static inline double sf_lp_gain(sf_lp_gain_t *const g, const double dt_s, const double tau_s)
{
    if (dt_s != g->dt_s || tau_s != g->tau_s) {
        g->k = -expm1(-dt_s / tau_s);
        g->dt_s = dt_s;
        g->tau_s = tau_s;
    }
    return g->k;
}

/* exp(x) and expm1(x) remembered for the last x: a decay factor e^(−dt/τ) of a stream at a fixed rate
 * has one argument, so libm runs once per rate change, and the value is bit for bit the call's (the
 * argument is the key, so the caller's expression for it is unchanged). Zero-initialised = empty. */
typedef struct {
    double x;
    double y;
    bool valid;
} sf_memo_t;

static inline double sf_exp_memo(sf_memo_t *const m, const double x)
{
    if (!m->valid || x != m->x) {
        m->y = exp(x);
        m->x = x;
        m->valid = true;
    }
    return m->y;
}

static inline double sf_expm1_memo(sf_memo_t *const m, const double x)
{
    if (!m->valid || x != m->x) {
        m->y = expm1(x);
        m->x = x;
        m->valid = true;
    }
    return m->y;
}

#endif
