/* sf_sample_gate.h — refuses sensor samples that no body-worn sensor produces, before they reach a
 * filter: not finite, beyond the sensor's full scale, not later than the last accepted sample of
 * their stream, or a jump from the last accepted sample faster than a body moves.
 *
 * Why: one corrupt accelerometer sample (a flipped sign bit: −147 m/s² inside the int16 range) used
 * to stop step detection for a minute and one corrupt gyro sample turns the heading for good. A
 * jump is judged per axis against floor + rate_max · Δt (Δt since the last accepted sample), so a
 * long gap allows a large change. A genuine step change of the signal (the sensor really moved) is
 * two rejected samples in a row that agree with each other by the same bound: the second is then
 * accepted and becomes the reference, so a rejection never latches.
 * The limits are physics and sensor specifications (sf_params.h, section `gate`), not tuned.
 * Cost: O(axes) per sample: sf_sample_gate_stream ≈ 65 instructions per 3-axis sample in `stridefix
 * bench perf`'s sensors walk (callgrind, x86-64 -O3; sf_sample_limits + sf_sample_gate_check ≈ 120
 * at -O2), sf_sample_gate_imu ≈ 114 for both of an IMU sample's (two stream calls: 133); no heap. Memory: sizeof(sf_sample_gate_t) = 72 B. */
#ifndef SF_SAMPLE_GATE_H
#define SF_SAMPLE_GATE_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"

#define SF_SAMPLE_GATE_MAX_AXES 3

typedef enum {
    sf_gate_accepted,
    sf_gate_out_of_range, /* not finite, or beyond full scale */
    sf_gate_jump,         /* faster than a body moves */
    sf_gate_out_of_order, /* not later than the last accepted sample */
} sf_gate_verdict_t;

typedef struct {
    double min;          /* full scale, per axis */
    double max;
    double jump_floor;   /* a change this large is always possible (noise, timing jitter) */
    double rate_max;     /* fastest change a body produces [unit/s] */
} sf_sample_limits_t;

/* The streams a gate guards, each with its limits in the params table (section gate). */
typedef enum { sf_gate_accel, sf_gate_gyro, sf_gate_mag, sf_gate_baro, sf_gate_stream_count } sf_gate_stream_t;

typedef struct {
    bool started;
    bool last_rejected; /* the previous sample was a jump */
    int64_t t_us;       /* last accepted */
    double value[SF_SAMPLE_GATE_MAX_AXES];
    int64_t rejected_t_us;
    double rejected[SF_SAMPLE_GATE_MAX_AXES];
} sf_sample_gate_t;

_Static_assert(sizeof(sf_sample_gate_t) <= 72, "sf_sample_gate.h promises 72 B");

void sf_sample_gate_init(sf_sample_gate_t *gate);

/* A stream's limits from the params table. */
sf_sample_limits_t sf_sample_limits(const sf_params_t *p, sf_gate_stream_t stream);

/* Judges one sample of n_axes (1..SF_SAMPLE_GATE_MAX_AXES) values at t_us; an accepted one becomes
 * the reference. */
sf_gate_verdict_t sf_sample_gate_check(sf_sample_gate_t *gate, const sf_sample_limits_t *limits, int64_t t_us,
                                       const double *value, int n_axes);

/* sf_sample_gate_check with the stream's limits from the params table and its axes (baro 1, the
 * others 3): the same verdict and reference, cheaper (the estimator's per-sample call). */
sf_gate_verdict_t sf_sample_gate_stream(sf_sample_gate_t *gate, const sf_params_t *p, sf_gate_stream_t stream,
                                        int64_t t_us, const double *value);

/* An IMU sample's two gates in one call: sf_sample_gate_stream for the accelerometer, then, only when
 * it accepted, for the gyroscope (the same verdicts and references as the two calls). Returns the first
 * verdict that is not accepted, or accepted. */
sf_gate_verdict_t sf_sample_gate_imu(sf_sample_gate_t *accel_gate, sf_sample_gate_t *gyro_gate, const sf_params_t *p,
                                     int64_t t_us, const double accel_mps2[3], const double gyro_radps[3]);

#endif
