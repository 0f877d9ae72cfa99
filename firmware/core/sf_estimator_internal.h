/* sf_estimator_internal.h — what the estimator's two files share (not a public API): the controller's
 * step of sf_estimator.c, which every fix input of sf_estimator_fix.c ends with (sf_estimator.h). */
#ifndef SF_ESTIMATOR_INTERNAL_H
#define SF_ESTIMATOR_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_estimator.h"

/* The controller steps on the motion of the scheme it follows at time t_us (after a credited step or
 * a source input); a switch to another floor renumbers the shared floor. */
void sf_estimator_run_controller(sf_estimator_t *e, const sf_params_t *p, int64_t t_us);

#endif
