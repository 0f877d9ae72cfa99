/* sf_math.h — the small scalar helpers every core module uses, in one place (header-only, static
 * inline: no hidden state, no cost beyond the call site's; sf_lp_gain's memory is the caller's). */
#ifndef SF_MATH_H
#define SF_MATH_H

#include <math.h>

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

#endif
