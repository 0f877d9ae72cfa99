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

/* atan2(y, x) given h = √(x² + y²), by the half angle: atan2(y, x) = 2·atan(t), t = y/(h + x) = tan of
 * half the angle. The errors an attitude filter corrects each sample (the tilt an accelerometer sees,
 * the yaw a magnetometer sees: sf_attitude) are mostly a few degrees: for |t| ≤ SF_ATAN_SERIES_MAX
 * (angles ≤ 11.4°) atan's series to t¹³ leaves out < t¹⁵/15 = 6.7e-17, so the angle is within a few ulp of atan2's
 * (≈ 25 instructions, not ≈ 130); larger angles, and x ≤ −h (no half angle), are atan2's. */
#define SF_ATAN_SERIES_MAX 0.1
/* atan(t)/t = 1 − t²/3 + … − t¹²/13 for t² = t2 ≤ SF_ATAN_SERIES_MAX² (the bound above). */
static inline double sf_atan_series(const double t2)
{
    return 1.0 - t2 * (1.0 / 3 - t2 * (1.0 / 5 - t2 * (1.0 / 7 - t2 * (1.0 / 9 - t2 * (1.0 / 11 - t2 / 13)))));
}
static inline double sf_atan2_half(const double y, const double x, const double h)
{
    const double d = h + x;
    if (d > 0.0) {
        const double t = y / d;
        if (fabs(t) <= SF_ATAN_SERIES_MAX) {
            return 2.0 * t * sf_atan_series(t * t);
        }
    }
    return atan2(y, x);
}

/* atan2(y, x) on (−π, π] without libm's atan2 (≈ 130 instructions): a quarter-turn swap (exact) brings
 * the angle within ±π/4, two half-angle steps t ← t/(1 + √(1 + t²)) bring tan of a quarter of it within
 * tan(π/16) = 0.199, and atan's series to t²¹ leaves out < t²³/23 = 3.2e-18 (×4 in the angle). The
 * roundings of the steps keep it within 2e-15 rad of atan2 (test_yaw_matches_atan2, test_attitude.c),
 * where the gyro's noise alone moves a yaw by ≈ 1e-5 rad per 100 Hz sample. Zero, infinite and NaN
 * arguments go to atan2, so its signed-zero and ±π conventions hold. */
static inline double sf_atan2(const double y, const double x)
{
    const double ax = fabs(x), ay = fabs(y);
    if (!(ax + ay > 0.0) || !isfinite(ax + ay)) {
        return atan2(y, x);
    }
    double u, v, base; /* (u, v): (x, y) turned by −base, u > 0, |v| ≤ u */
    if (ay <= x) {
        u = x, v = y, base = 0.0;
    } else if (ax <= y) {
        u = y, v = -x, base = 0.5 * SF_PI;
    } else if (ax <= -y) {
        u = -y, v = x, base = -0.5 * SF_PI;
    } else {
        u = -x, v = -y, base = signbit(y) ? -SF_PI : SF_PI;
    }
    const double t1 = v / (sqrt(u * u + v * v) + u);  /* tan(φ/2), |t1| ≤ tan(π/8) */
    const double t = t1 / (1.0 + sqrt(1.0 + t1 * t1)); /* tan(φ/4), |t| ≤ tan(π/16) */
    const double t2 = t * t;
    const double p = /* atan(t)/t = 1 − t²/3 + t⁴/5 − … + t²⁰/21 */
        1.0 - t2 * (1.0 / 3 - t2 * (1.0 / 5 - t2 * (1.0 / 7 - t2 * (1.0 / 9 - t2 * (1.0 / 11 - t2 * (1.0 / 13 -
        t2 * (1.0 / 15 - t2 * (1.0 / 17 - t2 * (1.0 / 19 - t2 / 21)))))))));
    return base + 4.0 * t * p;
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
