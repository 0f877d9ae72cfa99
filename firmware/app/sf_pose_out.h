/* sf_pose_out.h — when stridefixd writes the poses, and which: one POSE_<SCHEME> per fusion scheme
 * that has a position (a scheme waiting for its first fix has none), then the primary pose on POSE
 * (sf_publish_primary_of). Without a site there are no fixes, so only pdr_only is published (the
 * others would repeat it). Split from stridefixd.c by concern: what goes out about the position,
 * apart from how the input is read. Cannot fail; no allocation. */
#ifndef SF_POSE_OUT_H
#define SF_POSE_OUT_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_estimator.h"
#include "sf_lcm_out.h"
#include "sf_options.h"
#include "sf_params.h"

typedef struct {
    int64_t last_t_us;  /* the estimator's time at the last poses written */
    int16_t last_floor; /* and its floor then */
} sf_pose_out_t;

void sf_pose_out_init(sf_pose_out_t *po);

/* After an IMU sample that gave n_steps steps: whether the poses are due (a step, a pose
 * output.pose_period_ms newer than the last ones, or a new floor). "Newer" is the estimator's time, not
 * the sample's: a sample the gate refuses (NaN, full scale) leaves the pose as it was, and a failed IMU
 * must not repeat that pose once per sample with the same stale t_us. */
bool sf_pose_out_due(const sf_pose_out_t *po, const sf_estimator_t *est, const sf_params_t *p, int n_steps);

/* The poses, each stamped log_t_us in the log, on the channels opt lets through. */
void sf_pose_out_write(sf_pose_out_t *po, sf_lcm_out_t *out, int64_t log_t_us, const sf_estimator_t *est,
                       const sf_params_t *p, const sf_options_t *opt);

#endif
