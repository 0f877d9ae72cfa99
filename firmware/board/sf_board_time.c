/* sf_board_time.c — see sf_board_time.h for the reconstruction rule. */
#include "sf_board_time.h"

#include <math.h>

#include "sf_error.h"

/* The value ≡ low (mod 2^bits) nearest to predicted. */
static int64_t snap(const int64_t predicted, const uint64_t low, const unsigned bits)
{
    const int64_t mod = (int64_t)1 << bits;
    int64_t diff = (int64_t)((low - (uint64_t)predicted) & (uint64_t)(mod - 1));
    if (diff >= mod / 2) {
        diff -= mod;
    }
    return predicted + diff;
}

void sf_board_clock_init(sf_board_clock_t *const clock)
{
    *clock = (sf_board_clock_t){0};
}

void sf_board_clock_on_time(sf_board_clock_t *const clock, const uint32_t time_ms, const uint8_t boot_id)
{
    if (clock->synced && boot_id != clock->boot_id) {
        clock->restarts++;
        clock->synced = false;
    }
    clock->board_ms = clock->synced ? snap(clock->board_ms, time_ms, 32) : (int64_t)time_ms;
    clock->boot_id = boot_id;
    clock->synced = true;
    clock->generation++;
}

int sf_board_clock_unwrap(const sf_board_clock_t *const clock, const uint32_t time_ms, int64_t *const t_ms)
{
    if (!clock->synced) {
        return SF_ENOTSYNC;
    }
    *t_ms = snap(clock->board_ms, time_ms, 32);
    return SF_OK;
}

void sf_stream_time_init(sf_stream_time_t *const stream, const double nominal_period_ms)
{
    *stream = (sf_stream_time_t){0};
    stream->nominal_period_ms = nominal_period_ms;
    stream->period_ms = nominal_period_ms;
}

int sf_stream_time_resolve(sf_stream_time_t *const s, const sf_board_clock_t *const clock, const uint8_t seq,
                           const uint8_t t_lo_ms, int64_t *const t_ms, int64_t *const seq_unwrapped,
                           uint32_t *const lost)
{
    if (!clock->synced) {
        return SF_ENOTSYNC;
    }
    if (s->started && s->clock_restarts != clock->restarts) {
        sf_stream_time_init(s, s->nominal_period_ms); /* the board restarted: old times mean nothing */
    }
    const unsigned dseq = (unsigned)(uint8_t)(seq - s->last_seq);
    if (s->started && dseq == 0) {
        return SF_EDUPLICATE;
    }
    int64_t t = snap(clock->board_ms, t_lo_ms, 8);
    if (s->started) {
        const int64_t by_seq = snap(s->last_t_ms + (int64_t)llround((double)dseq * s->period_ms), t_lo_ms, 8);
        /* Trust the sequence unless a newer BOARD_TIME proves it wrapped: a sample is never sent
         * long before the BOARD_TIME that precedes it on the bus. */
        const bool new_anchor = s->generation != clock->generation;
        if (!new_anchor || by_seq >= clock->board_ms - 128) {
            t = by_seq;
        }
    }

    uint32_t missing = 0;
    int64_t useq = seq;
    if (s->started) {
        const double steps = (double)(t - s->last_t_ms) / s->period_ms;
        /* Unwrapped seq: the advance k ≡ dseq (mod 256) nearest to the elapsed time in periods. */
        const int64_t k = (int64_t)dseq + 256 * (int64_t)llround((steps - (double)dseq) / 256.0);
        useq = s->seq + (k > 0 ? k : (int64_t)dseq);
        missing = (uint32_t)(useq - s->seq - 1);
        if (dseq == 1 && t > s->last_t_ms) {
            /* Learn the period from consecutive samples, slowly, bounded to ±50 % of nominal. */
            const double dt = (double)(t - s->last_t_ms);
            if (dt > 0.5 * s->nominal_period_ms && dt < 1.5 * s->nominal_period_ms) {
                s->period_ms += 0.05 * (dt - s->period_ms);
            }
        }
    }
    s->started = true;
    s->last_seq = seq;
    s->last_t_ms = t;
    s->seq = useq;
    s->generation = clock->generation;
    s->clock_restarts = clock->restarts;
    *t_ms = t;
    *seq_unwrapped = useq;
    *lost = missing;
    return SF_OK;
}
