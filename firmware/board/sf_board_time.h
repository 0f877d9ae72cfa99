/* sf_board_time.h — each sample's board time, to 1 ms, through lost frames and counter wrap.
 *
 * What the board sends (firmware/board.dbc): BOARD_TIME with the full 32-bit board time in ms (at
 * start and every second), and on every sensor frame an 8-bit sequence number `seq` and the low 8
 * bits of the sample's board time `t_lo_ms`.
 *
 * Reconstruction, per stream: predict the sample's time, then take the one time that has the
 * received low 8 bits and lies within ±128 ms of the prediction. The prediction is
 *   - previous time + Δseq · period, with Δseq = (seq − previous seq) mod 256 and the period
 *     learnt from consecutive samples (exact for gaps up to 255 samples);
 *   - the latest BOARD_TIME for a stream's first sample, and whenever the sequence prediction
 *     falls more than 128 ms before a BOARD_TIME that arrived since the previous sample: frames
 *     are sent as they are sampled, so that only happens when the sequence wrapped during a long
 *     outage; the BOARD_TIME then recovers the time, however long the outage.
 * The 32-bit board time itself is unwrapped into int64, so 49.7-day wrap is invisible downstream.
 * Lost samples are counted from the time step (round(Δt/period) − 1), which stays right past a
 * seq wrap. A board restart (new boot_id) resets every stream.
 * Cost: O(1) per sample; no heap. */
#ifndef SF_BOARD_TIME_H
#define SF_BOARD_TIME_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    bool synced;
    int64_t board_ms;    /* latest BOARD_TIME, unwrapped */
    uint32_t generation; /* increments with every BOARD_TIME frame */
    uint8_t boot_id;
    uint32_t restarts; /* boot_id changes seen */
} sf_board_clock_t;

typedef struct {
    bool started;
    uint8_t last_seq;
    int64_t last_t_ms;
    int64_t seq;            /* unwrapped sequence number of the last sample */
    uint32_t generation;    /* clock generation seen at the last sample */
    double period_ms;       /* learnt sample period */
    double nominal_period_ms;
    uint32_t clock_restarts; /* clock restarts seen at the last sample */
} sf_stream_time_t;

void sf_board_clock_init(sf_board_clock_t *clock);

/* A BOARD_TIME frame. */
void sf_board_clock_on_time(sf_board_clock_t *clock, uint32_t time_ms, uint8_t boot_id);

/* A full 32-bit board time carried by another frame (Wi-Fi scan start, GNSS), unwrapped to the one
 * nearest the clock. SF_ENOTSYNC before the first BOARD_TIME. */
int sf_board_clock_unwrap(const sf_board_clock_t *clock, uint32_t time_ms, int64_t *t_ms);

void sf_stream_time_init(sf_stream_time_t *stream, double nominal_period_ms);

/* Resolves one sample. On SF_OK fills *t_ms, *seq (unwrapped) and *lost (samples missing since the
 * previous one). SF_ENOTSYNC before the first BOARD_TIME; SF_EDUPLICATE when seq repeats the
 * previous one (the sample is skipped). */
int sf_stream_time_resolve(sf_stream_time_t *stream, const sf_board_clock_t *clock, uint8_t seq, uint8_t t_lo_ms,
                           int64_t *t_ms, int64_t *seq_unwrapped, uint32_t *lost);

#endif
