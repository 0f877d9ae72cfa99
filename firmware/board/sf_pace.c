/* sf_pace.c — the wall time each input item of a --speed replay is due at (see sf_pace.h). */
#include "sf_pace.h"

#include <math.h>

void sf_pace_init(sf_pace_t *const pace, const double speed)
{
    *pace = (sf_pace_t){.speed = isfinite(speed) && speed > 0.0 ? speed : 0.0};
}

bool sf_pace_on(const sf_pace_t *const pace)
{
    return pace->speed > 0.0;
}

int64_t sf_pace_wait_us(sf_pace_t *const pace, const int64_t input_t_us, const int64_t now_wall_us)
{
    if (!sf_pace_on(pace)) {
        return 0;
    }
    if (!pace->started || input_t_us < pace->last_input_us) {
        pace->restarts += pace->started ? 1u : 0u;
        pace->started = true;
        pace->origin_input_us = input_t_us;
        pace->origin_wall_us = now_wall_us;
        pace->last_input_us = input_t_us;
        return 0;
    }
    pace->last_input_us = input_t_us;
    /* in double: (t - t0) / X of a long recording at a small X stays far inside int64 and exact to
     * well under a microsecond for any walk (2^53 µs is 285 years) */
    const double due_wall_us = (double)pace->origin_wall_us + (double)(input_t_us - pace->origin_input_us) / pace->speed;
    const double wait_us = due_wall_us - (double)now_wall_us;
    if (!(wait_us > 0.0)) {
        return 0;
    }
    return wait_us < (double)SF_PACE_WAIT_MAX_US ? (int64_t)ceil(wait_us) : SF_PACE_WAIT_MAX_US;
}
