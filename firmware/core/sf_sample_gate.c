/* sf_sample_gate.c — see sf_sample_gate.h. */
#include "sf_sample_gate.h"

#include <math.h>
#include <float.h>
#include <string.h>

void sf_sample_gate_init(sf_sample_gate_t *const gate)
{
    memset(gate, 0, sizeof *gate);
}

/* The limits, inline: sf_sample_gate_stream below builds them in registers, not as a returned struct. */
static inline sf_sample_limits_t limits_of(const sf_params_t *const p, const sf_gate_stream_t stream)
{
    switch (stream) { /* no default: a new stream needs its limits (-Wswitch) */
    case sf_gate_accel:
        return (sf_sample_limits_t){-p->gate_accel_full_scale_mps2, p->gate_accel_full_scale_mps2,
                                    p->gate_accel_jump_floor_mps2, p->gate_accel_rate_max_mps3};
    case sf_gate_gyro:
        return (sf_sample_limits_t){-p->gate_gyro_full_scale_radps, p->gate_gyro_full_scale_radps,
                                    p->gate_gyro_jump_floor_radps, p->gate_gyro_rate_max_radps2};
    case sf_gate_mag:
        return (sf_sample_limits_t){-p->gate_mag_full_scale_ut, p->gate_mag_full_scale_ut, p->gate_mag_jump_floor_ut,
                                    p->gate_mag_rate_max_ut_s};
    case sf_gate_baro:
        return (sf_sample_limits_t){p->gate_baro_min_pa, p->gate_baro_max_pa, p->gate_baro_jump_floor_pa,
                                    p->gate_baro_rate_max_pa_s};
    case sf_gate_stream_count: break;
    }
    return (sf_sample_limits_t){0.0, -1.0, 0.0, 0.0}; /* an empty range: nothing passes */
}

sf_sample_limits_t sf_sample_limits(const sf_params_t *const p, const sf_gate_stream_t stream)
{
    return limits_of(p, stream);
}

/* Every axis of b within the jump bound of a over dt_us. The axes are written out (n ≤ 3: a constant
 * at every call below, so the tests fold away): gcc -O2 does not unroll the loop, whose counter cost
 * as much as the test (callgrind). */
static inline bool within(const sf_sample_limits_t *const lim, const double *const a, const double *const b,
                          const int64_t dt_us, const int n)
{
    const double bound = lim->jump_floor + lim->rate_max * (double)dt_us * 1e-6;
    return fabs(b[0] - a[0]) <= bound && (n < 2 || fabs(b[1] - a[1]) <= bound) &&
           (n < 3 || fabs(b[2] - a[2]) <= bound);
}

static inline void copy_axes(double *const to, const double *const v, const int n)
{
    to[0] = v[0];
    if (n > 1) {
        to[1] = v[1];
    }
    if (n > 2) {
        to[2] = v[2];
    }
}

static inline void accept(sf_sample_gate_t *const g, const int64_t t_us, const double *const v, const int n)
{
    g->started = true;
    g->last_rejected = false;
    g->t_us = t_us;
    copy_axes(g->value, v, n);
}

/* finite and within full scale (the negation of "not finite, or below min, or above max") */
static inline bool in_range(const sf_sample_limits_t *const lim, const double x)
{
    return isfinite(x) && x >= lim->min && x <= lim->max;
}

static inline sf_gate_verdict_t check_ordered(sf_sample_gate_t *g, const sf_sample_limits_t *lim, int64_t t_us,
                                              const double *v, int n);

/* The check for n axes; inlined below with n a constant (3: accel, gyro, mag; 1: baro), so its loops
 * unroll: ≈ 11 instructions less per call (callgrind) than looping over a run-time n. n is 1..3
 * (SF_SAMPLE_GATE_MAX_AXES). */
static inline sf_gate_verdict_t check(sf_sample_gate_t *const g, const sf_sample_limits_t *const lim,
                                      const int64_t t_us, const double *const v, const int n)
{
    if (!in_range(lim, v[0]) || (n > 1 && !in_range(lim, v[1])) || (n > 2 && !in_range(lim, v[2]))) {
        return sf_gate_out_of_range;
    }
    return check_ordered(g, lim, t_us, v, n);
}

/* The rest of the check for a sample within range: order, then the jump bound. */
static inline sf_gate_verdict_t check_ordered(sf_sample_gate_t *const g, const sf_sample_limits_t *const lim,
                                              const int64_t t_us, const double *const v, const int n)
{
    if (!g->started) {
        accept(g, t_us, v, n);
        return sf_gate_accepted;
    }
    if (t_us <= g->t_us) {
        return sf_gate_out_of_order;
    }
    if (within(lim, g->value, v, t_us - g->t_us, n) ||
        (g->last_rejected && t_us > g->rejected_t_us && within(lim, g->rejected, v, t_us - g->rejected_t_us, n))) {
        accept(g, t_us, v, n);
        return sf_gate_accepted;
    }
    g->last_rejected = true;
    g->rejected_t_us = t_us;
    copy_axes(g->rejected, v, n);
    return sf_gate_jump;
}

sf_gate_verdict_t sf_sample_gate_check(sf_sample_gate_t *const g, const sf_sample_limits_t *const lim,
                                       const int64_t t_us, const double *const v, const int n)
{
    if (n == 3) {
        return check(g, lim, t_us, v, 3);
    }
    if (n == 1) {
        return check(g, lim, t_us, v, 1);
    }
    return check(g, lim, t_us, v, n);
}

static inline sf_gate_verdict_t stream_check(sf_sample_gate_t *const g, const sf_params_t *const p,
                                             const sf_gate_stream_t stream, const int64_t t_us, const double *const v)
{
    /* accel, gyro and mag: three axes and a symmetric full scale ±fs, so "finite and within [−fs, fs]"
     * is one test, |x| ≤ min(fs, DBL_MAX) (exact: −fs is exact; an infinite fs still refuses ±inf and
     * NaN fails every comparison); baro: one axis, its own range. One check per kind, inlined
     * (≈ 55 instructions a 3-axis call less than sf_sample_limits + sf_sample_gate_check, callgrind). */
    double fs;
    sf_sample_limits_t lim;
    switch (stream) {
    case sf_gate_accel:
        fs = p->gate_accel_full_scale_mps2;
        lim = (sf_sample_limits_t){-fs, fs, p->gate_accel_jump_floor_mps2, p->gate_accel_rate_max_mps3};
        break;
    case sf_gate_gyro:
        fs = p->gate_gyro_full_scale_radps;
        lim = (sf_sample_limits_t){-fs, fs, p->gate_gyro_jump_floor_radps, p->gate_gyro_rate_max_radps2};
        break;
    case sf_gate_mag:
        fs = p->gate_mag_full_scale_ut;
        lim = (sf_sample_limits_t){-fs, fs, p->gate_mag_jump_floor_ut, p->gate_mag_rate_max_ut_s};
        break;
    case sf_gate_baro:
        lim = limits_of(p, sf_gate_baro);
        return check(g, &lim, t_us, v, 1);
    case sf_gate_stream_count:
    default: return sf_gate_out_of_range; /* no such stream: nothing passes (as its empty limits would) */
    }
    const double m = fs < DBL_MAX ? fs : DBL_MAX;
    if (!(fabs(v[0]) <= m && fabs(v[1]) <= m && fabs(v[2]) <= m)) {
        return sf_gate_out_of_range;
    }
    return check_ordered(g, &lim, t_us, v, 3);
}

sf_gate_verdict_t sf_sample_gate_stream(sf_sample_gate_t *const g, const sf_params_t *const p,
                                        const sf_gate_stream_t stream, const int64_t t_us, const double *const v)
{
    return stream_check(g, p, stream, t_us, v);
}

sf_gate_verdict_t sf_sample_gate_imu(sf_sample_gate_t *const accel_gate, sf_sample_gate_t *const gyro_gate,
                                     const sf_params_t *const p, const int64_t t_us, const double accel_mps2[3],
                                     const double gyro_radps[3])
{
    /* the streams are constants here, so each check's switch folds away (one call, not two) */
    const sf_gate_verdict_t v = stream_check(accel_gate, p, sf_gate_accel, t_us, accel_mps2);
    return v != sf_gate_accepted ? v : stream_check(gyro_gate, p, sf_gate_gyro, t_us, gyro_radps);
}
