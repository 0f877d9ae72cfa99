/* sf_gap_bridge.c — see sf_gap_bridge.h. */
#include "sf_gap_bridge.h"

#include <math.h>

/* Weight of the newest step in the recent means: about the last five steps. */
#define RECENT_WEIGHT 0.2
/* Step periods a walker's gait has (0.5 .. 4 steps a second); others do not enter the recent mean. */
#define PERIOD_MIN_S 0.25
#define PERIOD_MAX_S 2.0

void sf_gap_bridge_on_imu(sf_gap_bridge_t *const gb, const sf_params_t *const p, const int64_t prev_t_us,
                          const int64_t t_us)
{
    const double gap_s = (double)(t_us - prev_t_us) * 1e-6;
    if (p->gap_bridge == 0 || prev_t_us == 0 || gap_s < p->gap_min_s) {
        return;
    }
    const bool walking_before =
        gb->last_step_t_us != 0 && (double)(prev_t_us - gb->last_step_t_us) * 1e-6 <= p->gap_walking_s;
    /* a second gap before any step: what happened in the first is unknown, nothing is guessed */
    gb->pending = walking_before && gap_s <= p->gap_max_s && !gb->pending;
    gb->gap_end_us = t_us;
}

bool sf_gap_bridge_on_step(sf_gap_bridge_t *const gb, const sf_params_t *const p, const int64_t t_us,
                           const double heading_rad, double *const distance_m, double *const bridge_heading_rad)
{
    if (!gb->pending) {
        return false;
    }
    gb->pending = false;
    if ((double)(t_us - gb->gap_end_us) * 1e-6 > p->gap_walking_s || gb->period_s <= 0.0) {
        return false; /* the walk did not go on right after the gap */
    }
    const double span_s = (double)(t_us - gb->last_step_t_us) * 1e-6;
    const double missing = round(span_s / gb->period_s) - 1.0;
    if (missing < 1.0) {
        return false;
    }
    *distance_m = missing * gb->length_m;
    *bridge_heading_rad = atan2(sin(gb->heading_rad) + sin(heading_rad), cos(gb->heading_rad) + cos(heading_rad));
    gb->bridged++;
    return true;
}

/* A recent mean with x added (x itself for the first). */
static double recent(const double mean, const double x, const bool first)
{
    return first ? x : mean + RECENT_WEIGHT * (x - mean);
}

void sf_gap_bridge_note_step(sf_gap_bridge_t *const gb, const int64_t t_us, const double period_s,
                             const double length_m, const double heading_rad)
{
    if (period_s >= PERIOD_MIN_S && period_s <= PERIOD_MAX_S) {
        gb->period_s = recent(gb->period_s, period_s, gb->period_s <= 0.0);
    }
    gb->length_m = recent(gb->length_m, length_m, gb->last_step_t_us == 0);
    gb->last_step_t_us = t_us;
    gb->heading_rad = heading_rad;
}
