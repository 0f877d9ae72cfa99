/* sf_heading.c — see sf_heading.h for the model. */
#include "sf_heading.h"

#include <math.h>

#include "sf_assert.h"
#include "sf_math.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define MAX_GAP_US 500000
#define WINDOW_MIN_US 200000
#define WINDOW_MAX_US 2000000
#define WINDOW_MIN_SAMPLES 4

static void restart_window(sf_heading_t *const h, const int64_t t_us)
{
    h->window = (sf_heading_moments_t){0};
    h->window_start_t_us = t_us;
    h->window_samples = 0;
}

void sf_heading_init(sf_heading_t *const h, const sf_params_t *const p)
{
    *h = (sf_heading_t){0};
    h->offset_rad = sf_wrap_pi(p->heading_mount_offset_deg * DEG);
}

void sf_heading_update(sf_heading_t *const h, const sf_params_t *const p, const int64_t t_us,
                       const double accel_nav_mps2[3], const double device_yaw_rad)
{
    sf_heading_update_dir(h, p, t_us, accel_nav_mps2, cos(device_yaw_rad), sin(device_yaw_rad));
}

void sf_heading_update_dir(sf_heading_t *const h, const sf_params_t *const p, const int64_t t_us,
                           const double accel_nav_mps2[3], const double c, const double s)
{
    SF_ASSERT(h != NULL && p != NULL && accel_nav_mps2 != NULL);
    if (!isfinite(accel_nav_mps2[0]) || !isfinite(accel_nav_mps2[1]) || !isfinite(accel_nav_mps2[2]) ||
        !isfinite(c) || !isfinite(s)) {
        h->invalid++;
        return;
    }
    if (!h->started) {
        h->started = true;
        h->last_t_us = t_us;
        h->up_mean_mps2 = accel_nav_mps2[2];
        h->v_up_mps = 0.0;
        restart_window(h, t_us);
        return;
    }
    const int64_t dt_us = t_us - h->last_t_us;
    if (dt_us <= 0) {
        h->time_errors++;
        return;
    }
    h->last_t_us = t_us;
    if (dt_us > MAX_GAP_US) {
        h->gaps++;
        h->up_mean_mps2 = accel_nav_mps2[2];
        h->v_up_mps = 0.0;
        restart_window(h, t_us);
        return;
    }
    const double dt_s = (double)dt_us * 1e-6;

    /* vertical: remove the slow mean, then leaky integration to velocity */
    const double tau_v = p->heading_vz_tau_s;
    h->up_mean_mps2 += dt_s / (2.0 * tau_v + dt_s) * (accel_nav_mps2[2] - h->up_mean_mps2);
    const double a_up = accel_nav_mps2[2] - h->up_mean_mps2;
    h->v_up_mps = (h->v_up_mps + a_up * dt_s) * (tau_v / (tau_v + dt_s));

    /* horizontal, turned by −yaw into the device-yaw frame */
    const double x = c * accel_nav_mps2[0] + s * accel_nav_mps2[1];
    const double y = -s * accel_nav_mps2[0] + c * accel_nav_mps2[1];
    const double z = h->v_up_mps;
    sf_heading_moments_t *const m = &h->window;
    m->w_s += dt_s;
    m->sx += dt_s * x;
    m->sy += dt_s * y;
    m->sz += dt_s * z;
    m->sxx += dt_s * x * x;
    m->syy += dt_s * y * y;
    m->sxy += dt_s * x * y;
    m->szz += dt_s * z * z;
    m->sxz += dt_s * x * z;
    m->syz += dt_s * y * z;
    h->window_samples++;
}

void sf_heading_on_step(sf_heading_t *const h, const sf_params_t *const p, const int64_t t_us)
{
    h->steps++;
    sf_heading_step_audit_t *const a = &h->last_step;
    *a = (sf_heading_step_audit_t){.t_us = t_us};
    if (!h->started) {
        return;
    }
    const int64_t len_us = t_us - h->window_start_t_us;
    a->window_ok = len_us >= WINDOW_MIN_US && len_us <= WINDOW_MAX_US && h->window_samples >= WINDOW_MIN_SAMPLES;
    if (!a->window_ok) {
        h->windows_rejected++;
        restart_window(h, t_us);
        return;
    }

    /* sum of recent windows with forgetting */
    const double keep = 1.0 - 1.0 / p->heading_window_steps;
    sf_heading_moments_t *const s = &h->sum;
    const sf_heading_moments_t *const w = &h->window;
    s->w_s = keep * s->w_s + w->w_s;
    s->sx = keep * s->sx + w->sx;
    s->sy = keep * s->sy + w->sy;
    s->sz = keep * s->sz + w->sz;
    s->sxx = keep * s->sxx + w->sxx;
    s->syy = keep * s->syy + w->syy;
    s->sxy = keep * s->sxy + w->sxy;
    s->szz = keep * s->szz + w->szz;
    s->sxz = keep * s->sxz + w->sxz;
    s->syz = keep * s->syz + w->syz;
    restart_window(h, t_us);

    /* PCA of the horizontal covariance */
    const double n = s->w_s;
    const double mx = s->sx / n, my = s->sy / n, mz = s->sz / n;
    const double cxx = s->sxx / n - mx * mx;
    const double cyy = s->syy / n - my * my;
    const double cxy = s->sxy / n - mx * my;
    const double czz = s->szz / n - mz * mz;
    const double cxz = s->sxz / n - mx * mz;
    const double cyz = s->syz / n - my * mz;
    const double half_diff = 0.5 * (cxx - cyy);
    const double root = sqrt(half_diff * half_diff + cxy * cxy);
    const double l1 = 0.5 * (cxx + cyy) + root;
    const double l2 = 0.5 * (cxx + cyy) - root;
    /* The forward axis is the direction of −cov(a_h, v_up): forward acceleration is anti-correlated
     * with vertical velocity (inverted pendulum), while the lateral sway (half the step rate, its sign
     * alternating step by step) and turns (centripetal) are not correlated with v_up at all. The
     * principal axis of a_h alone is not used for the direction: with a sway as strong as the
     * fore-aft oscillation (common at the waist) it can point anywhere between the two. */
    const double axis = atan2(-cyz, -cxz);
    const double var_f = cos(axis) * cos(axis) * cxx + 2.0 * cos(axis) * sin(axis) * cxy + sin(axis) * sin(axis) * cyy;
    const double cov_fz = -hypot(cxz, cyz);
    const double denom = sqrt(fmax(var_f, 0.0) * fmax(czz, 0.0));
    a->ratio = l1 / fmax(l2, 1e-12 * fmax(l1, 1e-300));
    a->corr = denom > 0.0 ? cov_fz / denom : 0.0;
    a->offset_rad = sf_wrap_pi(axis);
    a->good = l1 > 0.0 && a->corr <= -p->heading_min_corr;
    if (!a->good) {
        return;
    }

    /* circular mean over steps */
    const double beta = 1.0 / p->heading_smooth_steps;
    h->mean_c = (1.0 - beta) * h->mean_c + beta * cos(a->offset_rad);
    h->mean_s = (1.0 - beta) * h->mean_s + beta * sin(a->offset_rad);
    h->mean_w = (1.0 - beta) * h->mean_w + beta;
    h->good_steps++;
    const double resultant = sqrt(h->mean_c * h->mean_c + h->mean_s * h->mean_s) / h->mean_w;
    if (h->good_steps >= p->heading_min_steps && resultant >= p->heading_min_resultant) {
        h->confident = true; /* stays: a later scattered spell holds the last estimate */
        h->offset_rad = atan2(h->mean_s, h->mean_c);
    }
}

void sf_heading_discard_step(sf_heading_t *const h, const int64_t t_us)
{
    SF_ASSERT(h != NULL);
    h->windows_discarded++;
    restart_window(h, t_us);
}

double sf_heading_offset_rad(const sf_heading_t *const h, const sf_params_t *const p)
{
    return h->confident && p->heading_learn_offset ? h->offset_rad : sf_wrap_pi(p->heading_mount_offset_deg * DEG);
}

double sf_heading_walk_rad(const sf_heading_t *const h, const sf_params_t *const p, const double device_yaw_rad)
{
    return sf_wrap_pi(device_yaw_rad + sf_heading_offset_rad(h, p) - p->heading_map_rotation_deg * DEG);
}
