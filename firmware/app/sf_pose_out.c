/* sf_pose_out.c — when and which poses stridefixd writes (see sf_pose_out.h). */
#include "sf_pose_out.h"

#include "sf_publish.h"

void sf_pose_out_init(sf_pose_out_t *const po)
{
    po->last_t_us = INT64_MIN / 2;
    po->last_floor = 0;
}

bool sf_pose_out_due(const sf_pose_out_t *const po, const sf_estimator_t *const est, const sf_params_t *const p,
                     const int n_steps)
{
    sf_estimator_status_t st;
    sf_estimator_status(est, &st);
    return n_steps > 0 || st.t_us - po->last_t_us >= (int64_t)p->output_pose_period_ms * 1000 ||
           st.floor != po->last_floor;
}

void sf_pose_out_write(sf_pose_out_t *const po, sf_lcm_out_t *const out, const int64_t log_t_us,
                       const sf_estimator_t *const est, const sf_params_t *const p, const sf_options_t *const opt)
{
    sf_estimator_status_t st;
    sf_estimator_status(est, &st);
    const int n_schemes = st.has_site ? sf_scheme_count : sf_scheme_pdr_only + 1;
    const int only = p->output_scheme;
    for (int scheme = 0; scheme < n_schemes; scheme++) {
        sf_pose_t pose;
        if ((only < 0 || scheme == only) && sf_options_channel_on(opt, sf_publish_pose_channel(scheme)) &&
            sf_estimator_scheme_pose(est, p, scheme, &pose)) {
            sf_publish_pose(out, log_t_us, &pose);
        }
    }
    sf_pose_t pose;
    if (SF_OPTIONS_WRITES(opt, POSE) && sf_publish_primary_of(est, p, st.has_site, &pose)) {
        sf_publish_primary_pose(out, log_t_us, &pose);
    }
    po->last_t_us = st.t_us;
    po->last_floor = st.floor;
}
