/* sf_pdr.c — see sf_pdr.h for the model. */
#include "sf_pdr.h"

#include <math.h>

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* First-order low-pass gain for step dt and time constant tau. */
static double lowpass_gain(const double dt_s, const double tau_s)
{
    return dt_s / (tau_s + dt_s);
}

static double wrap_pi(const double a)
{
    return atan2(sin(a), cos(a));
}

void sf_pdr_init(sf_pdr_t *const pdr, const sf_params_t *const params)
{
    *pdr = (sf_pdr_t){0};
    pdr->heading_rad = params->init_heading_rad;
    pdr->x_m = params->init_x_m;
    pdr->y_m = params->init_y_m;
    pdr->last_step_t_us = INT64_MIN / 2;
}

static void restart_filters(sf_pdr_t *const pdr, const sf_imu_sample_t *const s)
{
    for (int i = 0; i < 3; i++) {
        pdr->gravity_mps2[i] = s->accel_mps2[i];
    }
    pdr->accel_v_mps2 = 0.0;
    pdr->above = false;
    pdr->started = true;
    pdr->last_t_us = s->t_us;
}

bool sf_pdr_update(sf_pdr_t *const pdr, const sf_params_t *const params, const sf_imu_sample_t *const s,
                   sf_step_t *const step)
{
    if (!pdr->started) {
        restart_filters(pdr, s);
        return false;
    }
    const int64_t dt_us = s->t_us - pdr->last_t_us;
    if (dt_us <= 0 || dt_us > (int64_t)params->pdr_max_gap_ms * 1000) {
        pdr->gaps++;
        restart_filters(pdr, s);
        return false;
    }
    const double dt_s = (double)dt_us * 1e-6;
    pdr->last_t_us = s->t_us;

    const double kg = lowpass_gain(dt_s, params->pdr_gravity_tau_s);
    for (int i = 0; i < 3; i++) {
        pdr->gravity_mps2[i] += kg * (s->accel_mps2[i] - pdr->gravity_mps2[i]);
    }
    const double g_norm = sqrt(dot3(pdr->gravity_mps2, pdr->gravity_mps2));
    if (g_norm < 1e-3) {
        return false; /* free fall or garbage: no vertical to speak of */
    }
    const double up[3] = {pdr->gravity_mps2[0] / g_norm, pdr->gravity_mps2[1] / g_norm,
                          pdr->gravity_mps2[2] / g_norm};

    /* Heading: rate about the vertical (specific force points up at rest, so ω·up is CCW yaw). */
    pdr->heading_rad = wrap_pi(pdr->heading_rad + dot3(s->gyro_radps, up) * dt_s);

    const double tau_v = 1.0 / (2.0 * 3.14159265358979323846 * params->pdr_accel_cutoff_hz);
    const double a_v = dot3(s->accel_mps2, up) - g_norm;
    pdr->accel_v_mps2 += lowpass_gain(dt_s, tau_v) * (a_v - pdr->accel_v_mps2);

    pdr->step_max_mps2 = fmax(pdr->step_max_mps2, pdr->accel_v_mps2);
    pdr->step_min_mps2 = fmin(pdr->step_min_mps2, pdr->accel_v_mps2);
    const double thr = params->pdr_step_threshold_mps2;
    if (pdr->accel_v_mps2 > thr) {
        if (!pdr->above || pdr->accel_v_mps2 > pdr->peak_mps2) {
            pdr->peak_mps2 = pdr->accel_v_mps2;
            pdr->peak_t_us = s->t_us;
        }
        pdr->above = true;
        return false;
    }
    if (!pdr->above) {
        return false;
    }
    /* The excursion ended: its peak is a step unless it falls inside the refractory time. */
    pdr->above = false;
    if (pdr->peak_t_us - pdr->last_step_t_us < (int64_t)params->pdr_step_min_interval_ms * 1000) {
        return false;
    }
    const double period_s = (double)(pdr->peak_t_us - pdr->last_step_t_us) * 1e-6;
    pdr->last_step_t_us = pdr->peak_t_us;
    pdr->step_count++;
    pdr->x_m += params->pdr_stride_m * cos(pdr->heading_rad);
    pdr->y_m += params->pdr_stride_m * sin(pdr->heading_rad);
    step->t_us = s->t_us; /* published when known: causal, not back-dated to the peak */
    step->index = pdr->step_count;
    step->length_m = params->pdr_stride_m;
    step->accel_range_mps2 = pdr->step_max_mps2 - pdr->step_min_mps2;
    step->period_s = pdr->step_count > 1 ? period_s : 0.0;
    step->heading_rad = pdr->heading_rad;
    step->activity = sf_activity_walking;
    step->floor = (int16_t)params->init_floor;
    pdr->step_max_mps2 = pdr->step_min_mps2 = pdr->accel_v_mps2;
    return true;
}

void sf_pdr_pose(const sf_pdr_t *const pdr, const sf_params_t *const params, sf_pose_t *const pose)
{
    pose->t_us = pdr->last_t_us;
    pose->x_m = pdr->x_m;
    pose->y_m = pdr->y_m;
    pose->floor = (int16_t)params->init_floor;
    pose->heading_rad = pdr->heading_rad;
    /* Fixed-stride PDR error grows with distance; 5 % of the path is the usual rule of thumb. */
    pose->sigma_m = 0.05 * params->pdr_stride_m * (double)pdr->step_count;
    pose->step_count = pdr->step_count;
    pose->scheme = sf_scheme_pdr_only;
}
