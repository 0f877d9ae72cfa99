/* sf_sample_gate.c — see sf_sample_gate.h. */
#include "sf_sample_gate.h"

#include <math.h>
#include <string.h>

void sf_sample_gate_init(sf_sample_gate_t *const gate)
{
    memset(gate, 0, sizeof *gate);
}

sf_sample_limits_t sf_sample_limits(const sf_params_t *const p, const sf_gate_stream_t stream)
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

/* Every axis of b within the jump bound of a over dt_us. */
static inline bool within(const sf_sample_limits_t *const lim, const double *const a, const double *const b,
                   const int64_t dt_us, const int n)
{
    const double bound = lim->jump_floor + lim->rate_max * (double)dt_us * 1e-6;
    for (int i = 0; i < n; i++) {
        if (fabs(b[i] - a[i]) > bound) {
            return false;
        }
    }
    return true;
}

static inline void accept(sf_sample_gate_t *const g, const int64_t t_us, const double *const v, const int n)
{
    g->started = true;
    g->last_rejected = false;
    g->t_us = t_us;
    for (int i = 0; i < n; i++) { /* 1–3 doubles: a loop, not a libc memcpy call (≈ 15 instructions) */
        g->value[i] = v[i];
    }
}

/* The check for n axes; inlined below with n a constant (3: accel, gyro, mag; 1: baro), so its loops
 * unroll: ≈ 11 instructions less per call (callgrind) than looping over a run-time n. */
static inline sf_gate_verdict_t check(sf_sample_gate_t *const g, const sf_sample_limits_t *const lim,
                                      const int64_t t_us, const double *const v, const int n)
{
    for (int i = 0; i < n; i++) {
        if (!isfinite(v[i]) || v[i] < lim->min || v[i] > lim->max) {
            return sf_gate_out_of_range;
        }
    }
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
    memcpy(g->rejected, v, (size_t)n * sizeof v[0]);
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
