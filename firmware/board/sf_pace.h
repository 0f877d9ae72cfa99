/* sf_pace.h — stridefixd --speed X: a replay published at X times the pace its input was recorded at.
 *
 * Model: each input item carries the time it was recorded at (the candump line's or the LCM event's
 * host timestamp, µs). The first item fixes the origin: input time t0 at wall time w0 (a monotonic
 * clock). Item t is due at wall time w0 + (t − t0) / X; the caller waits until then, then handles it.
 * An item that is already due (the estimator fell behind) waits 0: the replay catches up at full speed
 * and stays on the input's timeline, so the total time is the input's span / X however the work is
 * spread. Input time that goes backwards (a board restart's new host clock, concatenated recordings)
 * starts a new origin at that item, so the rest is paced and not published in one burst; a forward
 * jump (a silence in the recording) is waited out like any other time: it is the input's pace.
 *
 * Only *when* an item is handled depends on this, never what is computed: the estimator sees the same
 * items in the same order, and the log's event timestamps are the input's, so a log written with and
 * without --speed is the same (a file replay writes its log from the reading thread either way:
 * sf_lcm_out.h caller_writes, so even HEALTH's log counters agree). sf_pace_wait_us is the arithmetic,
 * pure (no clock: the test drives it with its own); sf_pace_sleep reads CLOCK_MONOTONIC and sleeps.
 * Cost: O(1) per item, no heap. */
#ifndef SF_PACE_H
#define SF_PACE_H

#include <stdbool.h>
#include <stdint.h>

/* The longest wait one item is given [µs]: a day, far beyond any silence of a walk at any --speed,
 * and a bound that keeps the arithmetic inside int64 for any speed. */
#define SF_PACE_WAIT_MAX_US (86400LL * 1000000LL)

typedef struct {
    double speed;           /* X > 0; 0: off (every item due at once) */
    bool started;           /* the origin is set */
    int64_t origin_input_us; /* t0: input time of the origin item */
    int64_t origin_wall_us;  /* w0: wall time at which the origin item was handled */
    int64_t last_input_us;   /* the previous item's input time (a backwards jump re-anchors) */
    uint32_t restarts;       /* origins set again because input time went backwards */
} sf_pace_t;

/* Pacing at `speed` times the input's pace; speed <= 0 (or not finite) is off. Cannot fail. */
void sf_pace_init(sf_pace_t *pace, double speed);

/* Whether pace publishes at a speed (sf_pace_init with speed > 0). */
bool sf_pace_on(const sf_pace_t *pace);

/* The wall time [µs, >= 0] to wait, from wall time now_wall_us, before handling the item recorded at
 * input_t_us: 0 when pacing is off, for the first item (which sets the origin at now_wall_us), for an
 * item whose input time went backwards (a new origin) and for one that is already due; at most
 * SF_PACE_WAIT_MAX_US. Cannot fail. */
int64_t sf_pace_wait_us(sf_pace_t *pace, int64_t input_t_us, int64_t now_wall_us);

/* Sleeps (CLOCK_MONOTONIC) until the item recorded at input_t_us is due: SF_OK once it is (at once
 * when pacing is off), or SF_EINTR when a signal woke the sleep and stop_requested() (non-zero: the
 * run ends) says so; any other signal (SIGHUP's rotation) only wakes it, and it sleeps on to the same
 * instant. */
int sf_pace_sleep(sf_pace_t *pace, int64_t input_t_us, int (*stop_requested)(void));

#endif
