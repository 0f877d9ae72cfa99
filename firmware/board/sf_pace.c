/* sf_pace.c — the wall time each input item of a --speed replay is due at, and the wait (sf_pace.h). */
#define _POSIX_C_SOURCE 200809L /* clock_nanosleep */
#include "sf_pace.h"

#include <errno.h>
#include <math.h>
#include <time.h>

#include "sf_error.h"

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

int sf_pace_sleep(sf_pace_t *const pace, const int64_t input_t_us, int (*const stop_requested)(void))
{
    if (!sf_pace_on(pace)) {
        return SF_OK;
    }
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const int64_t now_us = (int64_t)now.tv_sec * 1000000 + now.tv_nsec / 1000;
    const int64_t due_us = now_us + sf_pace_wait_us(pace, input_t_us, now_us);
    if (due_us == now_us) {
        return SF_OK;
    }
    const struct timespec due = {.tv_sec = (time_t)(due_us / 1000000), .tv_nsec = (long)(due_us % 1000000) * 1000};
    /* absolute: each wake-up by a signal sleeps on to the same instant, no drift */
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &due, NULL) == EINTR) {
        if (stop_requested() != 0) {
            return SF_EINTR;
        }
    }
    return SF_OK;
}
