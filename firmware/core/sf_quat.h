/* sf_quat.h — the small vector and unit-quaternion helpers of the attitude filter (sf_attitude.c), q =
 * (w, x, y, z) rotating body vectors into nav (sf_attitude.h's frames). Header-only, static inline: no
 * state, included by sf_attitude.c only; each comment gives the error bound that lets the filter use it in place of the textbook form. */
#ifndef SF_QUAT_H
#define SF_QUAT_H

#include <math.h>
#include <stdbool.h>


static inline double sf_dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double sf_norm3(const double a[3])
{
    return sqrt(sf_dot3(a, a));
}

static inline bool sf_finite3(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

static inline void sf_qmul(const double a[4], const double b[4], double out[4])
{
    const double w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    const double x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    const double y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    const double z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    out[0] = w;
    out[1] = x;
    out[2] = y;
    out[3] = z;
}

static inline void sf_qnormalise(double q[4])
{
    const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++) {
        q[i] /= n;
    }
    if (q[0] < 0.0) { /* one of the two signs, so outputs are unique */
        for (int i = 0; i < 4; i++) {
            q[i] = -q[i];
        }
    }
}

/* exp of a rotation vector r (axis × angle θ, rad): the quaternion (cos(θ/2), r·sin(θ/2)/θ).
 *
 * Every call here turns by one sample's worth: the gyro's ω·δt (0.05 rad at 5 rad/s and 100 Hz) or a
 * fraction of a tilt or yaw error. Below QEXP_SERIES_MAX_RAD both factors are their Taylor series in
 * x = (θ/2)² to x⁴ (no sqrt, no sincos: ≈ 25 instructions instead of ≈ 200). The first term left out,
 * x⁵/10!, is < 2.6e-16 at θ = 0.25 rad (x = 1/64), so each component is within a few ulp of libm's,
 * an angle error below 1e-15 rad per call: a MEMS gyro's white noise alone (0.005 °/s/√Hz) turns the
 * attitude by ≈ 1e-5 rad per 100 Hz sample, ten orders more. Larger angles (a 25 rad/s spin, an init)
 * keep sin/cos. */
#define QEXP_SERIES_MAX_RAD 0.25
static inline void sf_qexp(const double r[3], double q[4])
{
    const double angle2 = sf_dot3(r, r);
    if (angle2 < QEXP_SERIES_MAX_RAD * QEXP_SERIES_MAX_RAD) {
        const double x = 0.25 * angle2;
        /* Horner in x with the coefficients folded at compile time (each rounded once: a few ulp, as the
         * nested divisions were): a multiply and an add per term, ≈ 9 instructions a series, not ≈ 19 */
        q[0] = 1.0 + x * (-1.0 / 2 + x * (1.0 / 24 + x * (-1.0 / 720 + x * (1.0 / 40320)))); /* cos(θ/2) */
        /* sin(θ/2)/θ = ½ (1 − x/3! + x²/5! − x³/7! + x⁴/9!) */
        const double s = 0.5 + x * (-1.0 / 12 + x * (1.0 / 240 + x * (-1.0 / 10080 + x * (1.0 / 725760))));
        q[1] = s * r[0];
        q[2] = s * r[1];
        q[3] = s * r[2];
        return;
    }
    const double angle = sqrt(angle2);
    const double s = sin(0.5 * angle) / angle;
    q[0] = cos(0.5 * angle);
    q[1] = s * r[0];
    q[2] = s * r[1];
    q[3] = s * r[2];
}

/* v_nav = R(q) v (transpose: v_body = R(q)ᵀ v, the conjugate's rotation), as q ⊗ v ⊗ q* written out
 * for a unit q: t = 2 q_v × v, v' = v + w t + q_v × t (≈ 30 flops, against ≈ 50 for building the
 * matrix and multiplying). Equal to the matrix form up to rounding: q is normalised after every
 * update (|q| = 1 within 2e-16), so the two differ by a few ulp of |v| (≈ 1e-14 m/s² on gravity,
 * against an accelerometer's ≈ 1e-3 m/s² noise). out may alias v. */
static inline void sf_qrotate(const double q[4], const bool transpose, const double v[3], double out[3])
{
    const double w = q[0];
    const double x = transpose ? -q[1] : q[1], y = transpose ? -q[2] : q[2], z = transpose ? -q[3] : q[3];
    const double t0 = 2.0 * (y * v[2] - z * v[1]);
    const double t1 = 2.0 * (z * v[0] - x * v[2]);
    const double t2 = 2.0 * (x * v[1] - y * v[0]);
    const double o0 = v[0] + w * t0 + (y * t2 - z * t1);
    const double o1 = v[1] + w * t1 + (z * t0 - x * t2);
    const double o2 = v[2] + w * t2 + (x * t1 - y * t0);
    out[0] = o0;
    out[1] = o1;
    out[2] = o2;
}

/* Rᵀ(q)·(0, 0, e): e times nav up in body axes, the third row of R (three elements, not nine). */
static inline void sf_up_to_body(const double q[4], const double e, double out[3])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    out[0] = 2 * (x * z - w * y) * e;
    out[1] = 2 * (y * z + w * x) * e;
    out[2] = (1 - 2 * (x * x + y * y)) * e;
}

#endif
