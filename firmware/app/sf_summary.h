/* sf_summary.h — stridefixd's exit summary: the input, fault, sample, source, controller and log
 * counters of the run in a few lines of text (the same numbers as the last HEALTH). Split from
 * stridefixd.c by concern: what a run reports, apart from how it runs. Cannot fail. */
#ifndef SF_SUMMARY_H
#define SF_SUMMARY_H

#include <stdio.h>

#include "sf_estimator.h"
#include "sf_input.h"
#include "sf_lcm_out.h"
#include "sf_publish.h"

/* log_path NULL: no log was written. */
void sf_summary_print(FILE *f, const sf_input_counters_t *in, const sf_estimator_status_t *est,
                      const sf_publish_sources_t *sources, const sf_lcm_out_counters_t *oc, const char *log_path,
                      double wall_s);

#endif
