/* sf_gap_bridge.h — dead reckoning across a gap in the IMU stream (a bus silence, a board reset's
 * down time) while the person walks through it.
 *
 * Steps taken while no sample came in cannot be detected, and PDR alone would lose the distance for
 * good (a 10 s silence of the SIL walk: 18 steps, pdr_only mean error 4.7 -> 8.3 m). When the walk
 * was going right before the gap (a step within gap.walking_s of its start) and goes on right after
 * it (the first step after it within gap.walking_s of its end), the walker kept walking: the missing
 * steps are the span between the last step before and the first step after, in recent step periods,
 * less one, each of the recent mean length, along the circular mean of the headings before and
 * after. The displacement is credited once, at the first step after the gap, with no STEP records
 * (steps are what was detected). A gap of more than gap.max_s is not guessed; nor is a gap when the
 * walker stood before it or after it. The assumption is a constant velocity through the gap, the same
 * a Kalman filter's prediction makes; the gaps bridged are counted in HEALTH.
 * Cost: O(1) per sample and per step; no heap. Memory: sizeof(sf_gap_bridge_t) = 56 B. */
#ifndef SF_GAP_BRIDGE_H
#define SF_GAP_BRIDGE_H

#include <stdbool.h>
#include <stdint.h>

#include "sf_params.h"

typedef struct {
    int64_t last_step_t_us; /* latest credited step (0: none yet) */
    double period_s;        /* recent step period (EMA) */
    double length_m;        /* recent step length (EMA) */
    double heading_rad;     /* heading of the latest step */
    bool pending;           /* a gap while walking waits for the next step */
    int64_t gap_end_us;
    uint32_t bridged;       /* gaps bridged */
} sf_gap_bridge_t;

_Static_assert(sizeof(sf_gap_bridge_t) <= 56, "sf_gap_bridge.h promises 56 B");

/* An IMU sample at t_us whose predecessor came at prev_t_us (0: none). */
void sf_gap_bridge_on_imu(sf_gap_bridge_t *gb, const sf_params_t *p, int64_t prev_t_us, int64_t t_us);

/* A step about to be credited (detection time t_us, heading). True when it ends a gap bridged: then
 * *distance_m along *heading_rad is the walk the gap hid. */
bool sf_gap_bridge_on_step(sf_gap_bridge_t *gb, const sf_params_t *p, int64_t t_us, double heading_rad,
                           double *distance_m, double *bridge_heading_rad);

/* The step once credited: its period and length feed the recent means. */
void sf_gap_bridge_note_step(sf_gap_bridge_t *gb, int64_t t_us, double period_s, double length_m,
                             double heading_rad);

#endif
