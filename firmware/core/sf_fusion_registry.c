/* sf_fusion_registry.c — the scheme registry: one row per pose_t.SCHEME_* (its mode and gain law), the
 * names from sf_schemes.h and the gain laws of the blending schemes (sf_fusion.h; the reasons' texts:
 * sf_fix_reason.c).
 * Split from sf_fusion.c by concern: what each scheme is, apart from how fixes are judged. */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sf_assert.h"
#include "sf_error.h"
#include "sf_fusion_internal.h"
#include "sf_math.h"

static double us_to_s(const int64_t dt_us)
{
    return (double)dt_us / 1e6; /* correctly rounded: whole seconds come out exact */
}

static double alpha_one(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                        const double r_m2, sf_fix_audit_t *const audit)
{
    (void)f, (void)p, (void)fix, (void)r_m2, (void)audit;
    return 1.0;
}

/* A landmark (or a port recalibration) is where the walker is: α = 1 (the paper's NFC), whatever the fixed gain. */
static double alpha_static(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                           const double r_m2, sf_fix_audit_t *const audit)
{
    (void)f, (void)r_m2, (void)audit;
    return sf_fix_is_known_position(fix->method) ? 1.0 : p->fusion_static_alpha;
}

/* Records the adaptive terms in the audit (FIX.accuracy_factor, FIX.drift). */
static double alpha_adaptive(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                             const double r_m2, sf_fix_audit_t *const audit)
{
    (void)r_m2;
    const double dt_s = us_to_s(fix->t_us - f->last_fix_t_us);
    audit->accuracy_factor = sf_fusion_accuracy_factor(p, fix);
    audit->drift = sf_fusion_drift(p, dt_s);
    return sf_clamp(audit->accuracy_factor + audit->drift, 0.0, 1.0);
}

static double alpha_kalman(const sf_fusion_t *const f, const sf_params_t *const p, const sf_fix_t *const fix,
                           const double r_m2, sf_fix_audit_t *const audit)
{
    (void)p, (void)fix, (void)audit;
    return f->var_m2 / (f->var_m2 + r_m2);
}

/* Adding a scheme: its SCHEME_* constant in pose_t.lcm (which makes sf_scheme_<name>) and one row. */
static const sf_scheme_row_t scheme_rows[] = {
    [sf_scheme_pdr_only] = {mode_dead_reckoning, NULL, false},
    [sf_scheme_wifi_only] = {mode_follow_fixes, NULL, false},
    [sf_scheme_overwrite] = {mode_blend, alpha_one, false},
    [sf_scheme_static] = {mode_blend, alpha_static, false},
    [sf_scheme_adaptive] = {mode_blend, alpha_adaptive, false},
    [sf_scheme_kalman] = {mode_blend, alpha_kalman, true},
    [sf_scheme_ekf] = {mode_ekf, NULL, false},
    [sf_scheme_particle] = {mode_particle, NULL, false},
};
_Static_assert(sizeof scheme_rows / sizeof scheme_rows[0] == sf_scheme_count,
               "one scheme_rows entry per pose_t.SCHEME_* (sf_schemes.h)");

static const char *const scheme_names[] = {
#define SF_SCHEME_NAME(name, id) [id] = #name,
    SF_SCHEMES(SF_SCHEME_NAME)
#undef SF_SCHEME_NAME
};

const sf_scheme_row_t *sf_fusion_row(const int scheme)
{
    SF_ASSERT(scheme >= 0 && scheme < sf_scheme_count); /* sf_fusion_init refuses any other */
    return &scheme_rows[scheme];
}


const char *sf_fusion_scheme_name(const int scheme)
{
    return scheme >= 0 && scheme < sf_scheme_count ? scheme_names[scheme] : NULL;
}

int sf_fusion_scheme_from_name(const char *const name)
{
    for (int s = 0; name != NULL && s < sf_scheme_count; s++) {
        if (strcmp(name, scheme_names[s]) == 0) {
            return s;
        }
    }
    return SF_EINVAL;
}

bool sf_fusion_scheme_is_registered(const int scheme)
{
    return scheme >= 0 && scheme < sf_scheme_count && scheme_rows[scheme].mode != 0 &&
           (scheme_rows[scheme].mode != mode_blend || scheme_rows[scheme].alpha != NULL);
}
