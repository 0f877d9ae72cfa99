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

/* An angle [rad] wrapped to (−π, π].
 *
 * Inside it already (the usual case) the angle is returned as it is. A sum of two or three wrapped
 * angles is within a turn of it: one 2π is taken off, exactly (Sterbenz: the operands are within a
 * factor 2 of each other), so the only error is the double 2π being 2.4e-16 short of 2π. Up to four
 * turns whole turns are taken off, each subtraction rounding by ≤ ½ ulp of 8π (1.8e-15): ≤ 3e-15 rad
 * in all, where atan2(sin a, cos a) had ≈ 2 ulp (4e-16 rad) of its own at ≈ 200 instructions (sincos
 * and atan2) a call. Beyond four turns, and for ±inf and NaN, it is atan2(sin a, cos a) as before.
 * Both are ten orders below any heading the sensors can tell (the gyro's noise alone: ≈ 1e-5 rad per
 * 100 Hz sample). */
#define SF_PI 3.14159265358979323846
static inline double sf_wrap_pi(const double a)
{
    if (a > -SF_PI && a <= SF_PI) {
        return a;
    }
    if (a > -8.0 * SF_PI && a <= 8.0 * SF_PI) {
        double r = a;
        while (r > SF_PI) {
            r -= 2.0 * SF_PI;
        }
        while (r <= -SF_PI) {
            r += 2.0 * SF_PI;
        }
        return r;
    }
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
