/* sf_estimator_internal.h — what the estimator's own files share (not a public API): the fix offer of
 * sf_estimator_fix.c and the controller hooks of sf_estimator_context.c (sf_estimator.h describes both). */
#ifndef SF_ESTIMATOR_INTERNAL_H
#define SF_ESTIMATOR_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_estimator.h"

/* Every scheme judges the fix (one audit each); the floor vote first when `votes`. Returns
 * sf_scheme_count. */
int sf_estimator_offer_fix(sf_estimator_t *e, const sf_params_t *p, const sf_fix_t *fix, bool votes,
                           sf_fix_audit_t audits[sf_scheme_count]);

/* No fix from this input: each scheme records the refusal with this reason. Returns sf_scheme_count. */
int sf_estimator_refuse(sf_estimator_t *e, int64_t t_us, int8_t method, int16_t n_used, int8_t reason,
                        sf_fix_audit_t audits[sf_scheme_count]);

/* The pose of a scheme the controller follows, with the fading hand-over offset of the last switch
 * added (sf_estimator.h); false when the scheme has no pose. */
bool sf_estimator_followed_pose(const sf_estimator_t *e, const sf_params_t *p, int scheme, sf_pose_t *pose);

/* The controller steps on the motion of the scheme it follows at time t_us (after a credited step or
 * a source input); a switch to another floor renumbers the shared floor. */
void sf_estimator_run_controller(sf_estimator_t *e, const sf_params_t *p, int64_t t_us);

/* Whether the controller keeps this source off now; if so, *n = the CONTEXT_OFF audits written. */
bool sf_estimator_context_off(sf_estimator_t *e, const sf_params_t *p, int8_t method, int64_t t_us,
                              sf_fix_audit_t audits[sf_scheme_count], int *n);

#endif
