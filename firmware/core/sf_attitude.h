/* sf_attitude.h — device attitude from gyroscope, accelerometer and magnetometer, two filters
 * selectable by attitude_mode, with magnetic-disturbance rejection.
 *
 * Frames. Navigation frame n: x = magnetic east, y = magnetic north, z = up (ENU on magnetic north).
 * Body frame b: the sensor axes. The attitude is the unit quaternion q = (w, x, y, z) that rotates body
 * vectors into nav: v_n = q ⊗ v_b ⊗ q*. At rest the accelerometer measures the specific force, which
 * points up (+g along nav z); the undisturbed field is m_n = F·(0, cos δ, −sin δ), F = field strength,
 * δ = dip (positive downwards, 60° in central Europe). Yaw (sf_attitude_yaw_rad) is the heading of the
 * body x axis projected on the horizontal plane, counter-clockwise from nav +x (east), in (−π, π]; it
 * is ill-conditioned when body x is within a few degrees of vertical.
 *
 * Propagation (both modes). The gyro rate, minus the bias estimate, is averaged over the interval
 * (trapezoid of the previous and the current sample) and integrated exactly as a rotation over δt from
 * the sample times: q ← q ⊗ exp(ω̄ δt) (exp of a rotation vector). The accelerometer's correction
 * below joins the same step: one exp, one quaternion product and one normalisation per sample,
 * q ← q ⊗ exp(ω̄ δt + k·e_b), e_b the tilt error in body axes measured with the attitude before the
 * sample (as Mahony's ω − b̂ + Kp·e; to first order the separate gyro step, then correction in nav,
 * that this filter did before: the two differ by a commutator of the step and the correction,
 * ≈ ½·|ω δt|·k·|e|, and by the one-sample-older attitude the error is measured with). Any rate 20–200 Hz with jitter works; an interval ≤ 0 or
 * longer than attitude_max_gap_ms is not integrated (counted in imu_time_errors / imu_gaps), the
 * accelerometer still corrects tilt. The accelerometer corrections below use δt clamped to 0.1 s, and
 * the Mahony integral skips the sample after a gap, so a gap never turns into one large step.
 *
 * Complementary (attitude_mode 0; Ramadhan 2016 Eq. 2.15–2.16, τ = attitude_tau_s = 0.75 s). The
 * absolute references are the accelerometer (roll/pitch) and the tilt-compensated magnetometer (yaw),
 * each blended with the gyro-integrated attitude as θ̂ = α(θ̂ + ω δt) + (1−α) θ_ref, α = τ/(τ+δt).
 * Written as θ̂_gyro + (1−α)(θ_ref − θ̂_gyro), it is applied geometrically instead of on Euler angles:
 * the tilt error is the rotation that takes the measured up direction (accelerometer, rotated into nav)
 * onto nav z, about a horizontal axis; the yaw error is the angle about nav z between the measured
 * horizontal field and magnetic north. Each is corrected by the fraction (1−α) of its angle, δt being
 * the interval of its own sensor. This removes the thesis' two flaws (body rates added to Euler angles,
 * no ±180° wrap; notes §2 [FLAG]) and has no gimbal lock: any fixed device orientation works. The
 * complementary filter has no bias state (as in the thesis): a gyro bias b leaves an error ≈ b·τ.
 *
 * Mahony (attitude_mode 1; Mahony, Hamel, Pflimlin 2008, explicit complementary filter). Body-frame
 * errors e (axis × angle) feed the gyro: ω = ω_gyro − b̂ + Kp·e, and b̂ ← b̂ − Ki·e·δt (the integral
 * term). The gravity error uses attitude_mahony_kp on each IMU sample; the magnetometer error is the
 * yaw angle of the horizontal field only (rotation about nav z, mapped into body), so a magnetometer
 * error never tilts the attitude; it uses attitude_mahony_kp_mag at each accepted mag sample, and feeds
 * the bias with its own integral gain attitude_mahony_ki_mag, 0 by default: indoors most of that error
 * is a disturbance that passed the gates (steel bends the field by 10–40° over metres), and integrating
 * it taught the bias a drift of its own (ipin2023, 25 hand-held walks, truth-initialised PDR: 7.55 →
 * 5.90 m mean with it off, the 0.1 of the gravity integral before). Rest:
 * when |ω − b̂| < attitude_rest_gyro_radps and | |a| − g | < attitude_rest_accel_mps2 have both held
 * for attitude_rest_time_s, b̂ also low-passes the raw gyro (time constant attitude_rest_bias_tau_s),
 * much faster than the integral term. Each bias component is bounded by attitude_gyro_bias_max_radps,
 * and an error above 10° (a wrong start, a fast manoeuvre) does not feed the integral (anti-windup).
 *
 * Accelerometer gating (both modes): a sample with | |a| − g | > attitude_accel_gate_mps2 does not
 * correct tilt (counted in accel_gated); g = 9.80665 m/s².
 *
 * Magnetometer control (both modes), separate from the fusion above. For each sample, field strength
 * |m| and dip δ = asin(−m·û/|m|) (û = up in body, from the current attitude) are compared with the
 * references. Verdicts (sf_mag_verdict_t, one audit record per sample in last_mag):
 *   - no_tilt: the sample came before any accelerometer sample; it is held (one slot, the newest) and
 *     judged when the first IMU sample has set roll/pitch (so mag and IMU may come in either order);
 *   - degenerate: zero or non-finite vector, or horizontal component < 1 % of |m|;
 *   - field / dip: outside attitude_mag_field_tol_ut / attitude_mag_dip_tol_deg: disturbed;
 *   - settling: within tolerance, but not yet for attitude_mag_settle_s since the last disturbed
 *     sample (hysteresis: accept again only after the field has been consistent for a while);
 *   - accepted: fused. The first accepted sample sets yaw outright and sets yaw_absolute; until then
 *     yaw starts at 0 (body x towards east) and yaw_absolute is false.
 * References start at attitude_mag_field_ut / attitude_mag_dip_deg. Acquisition: the references
 * follow the *quiet* samples (|ω − b̂| < attitude_mag_acquire_gyro_radps: the dip needs the
 * accelerometer's tilt, which a waved device does not give; exponential average over 2 s, the first
 * quiet sample sets them; before it the acquisition's first sample sets them and the next ones are
 * followed, so a device that never rests still gets its field) until those cover attitude_mag_acquire_s; what they reach is the anchor. When
 * attitude_mag_learn_tau_s > 0 they then follow the accepted samples with that time constant, bounded
 * to the anchor ± tolerance, so a slow local difference is learned but a disturbance can never walk
 * the reference away. A field out of tolerance for attitude_mag_reacquire_s without one sample inside
 * starts the acquisition again (counted in mag_reacquisitions): steel disturbs over metres, seconds of
 * walking, so that long is a changed field or sensor calibration — a phone's OS refits its hard iron
 * during the calibration gestures a walk starts with (51 → 40 µT within a minute on an IPIN 2023 log,
 * which the first 10 s of acquisition took as the site's field, rejecting every later sample).
 * Time for the mag blend is the interval since the previous mag sample, clamped to [0, 0.2] s.
 *
 * Counters never decrease. Cost (callgrind, x86-64 -O3, `stridefix bench perf`'s sensors walk): ≈ 385
 * instructions per sf_attitude_update_imu_finite (sf_attitude_update_imu's finiteness check ≈ 22
 * more) and ≈ 500 per sf_attitude_update_mag (the dip's asin ≈ 75, the yaw correction's rotation
 * ≈ 80), ≈ 636 per IMU sample with MAG at 50 Hz, where x-io Fusion's FusionAhrsUpdate (in float)
 * takes 331 (× 1.9; the cost budget asks ≤ 1.5×, ≈ 500).
 * No sincos and mostly no atan2: rotation steps below 0.25 rad and tilt/yaw errors below 11.4° are
 * series, and sf_attitude_yaw_rad's atan2 is replaced by one (error bounds at sf_qexp in sf_quat.h,
 * sf_atan2_half and sf_atan2 in sf_math.h); libm keeps a few sqrt per call and the dip's asin. Memory
 * sizeof(sf_attitude_t) = 376 B on x86-64 (< 400 B, checked). No heap, no I/O, no clock, no
 * hidden state: the same inputs give bit-identical outputs. Functions cannot fail (void); NULL arguments are
 * a contract violation (SF_ASSERT). */
#ifndef SF_ATTITUDE_H
#define SF_ATTITUDE_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"

enum { sf_attitude_complementary = 0, sf_attitude_mahony = 1 };

/* Verdict on one magnetometer sample, see the header comment. */
typedef enum {
    sf_mag_accepted = 0,
    sf_mag_no_tilt = 1,
    sf_mag_degenerate = 2,
    sf_mag_field = 3,
    sf_mag_dip = 4,
    sf_mag_settling = 5,
    sf_mag_verdict_count = 6
} sf_mag_verdict_t;

/* Audit record of the last magnetometer sample (the FIX habit: innovation, gain, verdict). */
typedef struct {
    int64_t t_us;
    double field_ut;       /* measured |m| */
    double dip_rad;        /* measured dip, NaN when not computed */
    double ref_field_ut;   /* reference used for the test */
    double ref_dip_rad;
    double yaw_innov_rad;  /* magnetic yaw minus predicted yaw, wrapped; 0 when not computed */
    double gain;           /* fraction of the innovation applied this sample (1 = yaw set outright) */
    sf_mag_verdict_t verdict;
} sf_attitude_mag_audit_t;

typedef struct {
    double q[4]; /* body → nav, (w, x, y, z), unit */
    bool tilt_initialised; /* an accelerometer sample set roll/pitch */
    bool yaw_absolute;     /* a magnetometer sample set yaw */
    bool at_rest;
    double gyro_bias_radps[3];

    /* IMU propagation */
    bool imu_started;
    int64_t last_imu_t_us;
    double last_gyro_radps[3]; /* previous raw sample, for the trapezoid */
    int64_t rest_since_t_us;   /* start of the current rest candidate; valid when rest_candidate */
    bool rest_candidate;

    /* magnetometer control */
    bool mag_pending; /* held sample from before the first IMU sample */
    int64_t mag_pending_t_us;
    double mag_pending_ut[3];
    bool mag_seen;
    int64_t last_mag_t_us;
    bool mag_disturbed;          /* since the last out-of-tolerance sample, not yet settled */
    bool mag_consistent;         /* mag_consistent_t_us is valid */
    int64_t mag_consistent_t_us; /* first in-tolerance sample after the last disturbed one */
    bool mag_ref_set;
    double mag_ref_field_ut;
    double mag_ref_dip_rad;
    /* acquisition of the site's field (attitude_mag_acquire_s): the references follow the data,
     * then the bounded learning stays within ± tolerance of what was acquired */
    int64_t mag_acquire_start_t_us;
    double mag_anchor_field_ut;
    double mag_anchor_dip_rad;
    bool mag_acquiring;          /* the references follow the quiet samples */
    int32_t mag_acquire_n;       /* quiet samples taken by this acquisition */
    double mag_acquired_s;       /* their time (sum of mag intervals) */
    int64_t mag_last_ok_t_us;    /* last sample within tolerance (or the acquisition's start) */
    uint32_t mag_reacquisitions; /* acquisitions restarted by attitude_mag_reacquire_s */

    /* health: counters never decrease */
    uint32_t mag_accepted;
    uint32_t mag_rejected; /* all verdicts but accepted; no_tilt counted only when a held sample is replaced */
    uint32_t mag_by_verdict[sf_mag_verdict_count];
    uint32_t imu_gaps;
    uint32_t imu_time_errors; /* interval ≤ 0 */
    uint32_t imu_invalid;     /* non-finite accel or gyro: sample skipped */
    uint32_t accel_gated;
    sf_attitude_mag_audit_t last_mag;
} sf_attitude_t;
_Static_assert(sizeof(sf_attitude_t) < 400, "sf_attitude.h promises less than 400 B");

/* Identity attitude, nothing initialised, bias 0, counters 0. */
void sf_attitude_init(sf_attitude_t *att);

/* One accelerometer + gyroscope sample (sensor axes). The first sample sets roll/pitch (yaw 0). */
void sf_attitude_update_imu(sf_attitude_t *att, const sf_params_t *p, int64_t t_us, const double accel_mps2[3],
                            const double gyro_radps[3]);

/* sf_attitude_update_imu for a caller whose samples are finite already (sf_estimator_imu: its sample
 * gates refuse the others), without the check that counts imu_invalid (≈ 22 instructions); a
 * non-finite sample is a contract violation (SF_ASSERT). */
void sf_attitude_update_imu_finite(sf_attitude_t *att, const sf_params_t *p, int64_t t_us, const double accel_mps2[3],
                                   const double gyro_radps[3]);

/* One magnetometer sample (sensor axes, calibrated: hard/soft iron removed). Sets the counters and
 * last_mag; see the header comment for the verdicts. */
void sf_attitude_update_mag(sf_attitude_t *att, const sf_params_t *p, int64_t t_us, const double field_ut[3]);

/* v_nav = R(q) v_body. v_body and v_nav may alias. */
void sf_attitude_body_to_nav(const sf_attitude_t *att, const double v_body[3], double v_nav[3]);

/* v_body = R(q)ᵀ v_nav. May alias. */
void sf_attitude_nav_to_body(const sf_attitude_t *att, const double v_nav[3], double v_body[3]);

/* Heading of body x projected on the horizontal plane, CCW from nav +x (magnetic east), (−π, π]. */
double sf_attitude_yaw_rad(const sf_attitude_t *att);

/* sf_attitude_yaw_rad of the attitude q (a copy of sf_attitude_t's q; the same double). */
double sf_attitude_q_yaw_rad(const double q[4]);

/* cos and sin of sf_attitude_yaw_rad from the quaternion (the horizontal projection of body x,
 * normalised: a sqrt and two divisions, not a sincos; within a few ulp of cos/sin of the yaw). A body
 * x exactly vertical has no projection: then cos/sin of atan2's answer there. */
void sf_attitude_yaw_dir(const sf_attitude_t *att, double *cos_yaw, double *sin_yaw);

/* Angle between body "up" as estimated and the nav z axis image: the tilt of the body z axis from
 * vertical, [0, π]. Handy for tests and health. */
double sf_attitude_tilt_rad(const sf_attitude_t *att);

#endif
