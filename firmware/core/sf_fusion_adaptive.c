/* sf_fusion_adaptive.c — the adaptive scheme's gain law, α = sf_clamp(accuracy(fix) + drift(Δt), 0, 1)
 * (Jäger, Süß, Becker eq. 9; tables and knots in sf_fusion.h), apart from the control in sf_fusion.c. */
#include <math.h>

#include "sf_fusion.h"
#include "sf_math.h"

/* Piecewise-linear over four knots, flat outside. Reaching segment i means xs[i] < x ≤ xs[i+1], so the
 * width is positive: badly ordered knots make a jump, never a division by zero. NaN gives vs[0]. */
static double interp4(const double xs[4], const double vs[4], const double x)
{
    if (!(x > xs[0])) {
        return vs[0];
    }
    for (int i = 0; i < 3; i++) {
        if (x <= xs[i + 1]) {
            return vs[i] + (x - xs[i]) / (xs[i + 1] - xs[i]) * (vs[i + 1] - vs[i]);
        }
    }
    return vs[3];
}

double sf_fusion_accuracy_factor(const sf_params_t *const p, const sf_fix_t *const fix)
{
    switch (fix->method) {
    case sf_fix_wifi: {
        const double xs[4] = {p->fusion_acc_wifi_ap1, p->fusion_acc_wifi_ap2, p->fusion_acc_wifi_ap3,
                              p->fusion_acc_wifi_ap4};
        const double vs[4] = {p->fusion_acc_wifi_val1, p->fusion_acc_wifi_val2, p->fusion_acc_wifi_val3,
                              p->fusion_acc_wifi_val4};
        return p->fusion_acc_wifi_scale * interp4(xs, vs, (double)fix->n_ap_used);
    }
    case sf_fix_gnss: /* the paper's GPS factor, falling with the reported accuracy */
    case sf_fix_ble: { /* a BLE fix states its accuracy in metres too: the same law (no paper figure) */
        const double xs[4] = {p->fusion_acc_gnss_m1, p->fusion_acc_gnss_m2, p->fusion_acc_gnss_m3,
                              p->fusion_acc_gnss_m4};
        const double vs[4] = {p->fusion_acc_gnss_val1, p->fusion_acc_gnss_val2, p->fusion_acc_gnss_val3,
                              p->fusion_acc_gnss_val4};
        return interp4(xs, vs, fix->accuracy_m);
    }
    case sf_fix_landmark:
    case sf_fix_port: /* a staircase endpoint is a known position, like a landmark */
        return p->fusion_acc_landmark;
    default:
        return 0.0;
    }
}

double sf_fusion_drift(const sf_params_t *const p, const double dt_s)
{
    return dt_s > 0.0 ? fmin(p->fusion_drift_per_s * dt_s, p->fusion_drift_max) : 0.0;
}

double sf_fusion_adaptive_alpha(const sf_params_t *const p, const sf_fix_t *const fix, const double dt_s)
{
    return sf_clamp(sf_fusion_accuracy_factor(p, fix) + sf_fusion_drift(p, dt_s), 0.0, 1.0);
}

