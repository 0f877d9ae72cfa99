/* sf_board_time.h — each sample's time, to 1 ms, through lost frames, counter wrap, corrupt frames
 * and board resets.
 *
 * What the board sends (firmware/board.dbc): BOARD_TIME with the full 32-bit board time in ms and the
 * boot id (at start and every second), and on every sensor frame an 8-bit sequence number `seq` and
 * the low 8 bits of the sample's board time `t_lo_ms`. Every frame also has the host's receive time.
 *
 * Reconstruction, per stream: predict the sample's time, then take the one time that has the
 * received low 8 bits and lies within ±128 ms of the prediction. The prediction is
 *   - previous time + k · period, with k ≡ Δseq (mod 256) the advance nearest to the host time
 *     elapsed since the previous sample (so a gap longer than the seq wrap is still exact), and the
 *     period learnt from consecutive samples;
 *   - the latest BOARD_TIME for a stream's first sample, and whenever the sequence prediction
 *     falls more than 128 ms before a BOARD_TIME that arrived since the previous sample.
 * A sample whose Δseq claims more time than the host saw pass is not believed: within 32 samples
 * behind it arrived late (reordered, SF_ELATE), else its seq is corrupt (SF_ESEQ); either way it is
 * skipped and the stream's state is untouched. Once eight samples in a row have matched the
 * prediction, a t_lo more than 16 ms from it is corrupt and skipped (SF_ESEQ); a second in a row is
 * believed.
 *
 * The clock believes a BOARD_TIME that agrees with what it knows (the same boot id, and a time
 * between 500 ms before the newest board time seen and the host time elapsed since, +10 %, +1 s).
 * Any other BOARD_TIME is held, not believed on one frame (a bit flip would otherwise move every
 * stream): the next BOARD_TIME that agrees with the held one and has moved on from it by the host
 * time since (less 10 % and 500 ms), or (for a new boot id) a stream sample that restarts its
 * sequence (seq < 16) at the held time and does not fit its old stream, confirms it. A stuck
 * BOARD_TIME (one value repeated while the samples go on) therefore never confirms itself: each
 * frame is held, counted as not believed when the next replaces it, and the streams go on by their
 * seq and t_lo, so output time keeps following the samples through it and after. A confirmed
 * new boot id, or a same-boot time that went backwards, is a board restart: a new epoch begins,
 * every stream restarts, and the output time base is re-anchored so that output time goes on from
 * the last output time plus the host time that passed (output = board time + offset_ms; the offset
 * is 0 until the first restart). A same-boot jump forwards keeps the board's time (a long outage).
 * The 32-bit board time is unwrapped into int64, so 49.7-day wrap is invisible downstream.
 * Lost samples are counted from the time step (round(Δt/period) − 1).
 * Cost: O(1) per sample; no heap. */
#ifndef SF_BOARD_TIME_H
#define SF_BOARD_TIME_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    bool valid;
    uint32_t time_ms;
    uint8_t boot_id;
    int64_t host_t_us;
} sf_board_time_held_t;

typedef struct {
    bool synced;
    int64_t board_ms;       /* latest believed BOARD_TIME, unwrapped, in this epoch's board time */
    uint32_t generation;    /* increments with every believed BOARD_TIME */
    uint8_t boot_id;
    int64_t offset_ms;      /* output time = board time + offset_ms */
    int64_t latest_ms;      /* newest board time known (BOARD_TIME or sample), this epoch */
    int64_t latest_host_us; /* host receive time of latest_ms */
    sf_board_time_held_t held; /* a BOARD_TIME not believed yet */
    uint32_t restarts;      /* board restarts believed (new boot id, or time went back): the epoch,
                             * streams start again when it changes */
    uint32_t time_jumps;    /* same boot id, time jumped forwards (believed after confirmation) */
    uint32_t time_rejected; /* BOARD_TIME frames held and never confirmed */
} sf_board_clock_t;

typedef struct {
    bool started;
    uint8_t last_seq;
    int64_t last_t_ms;
    int64_t last_host_us;
    int64_t seq;            /* unwrapped sequence number of the last sample */
    uint32_t generation;    /* clock generation seen at the last sample */
    uint32_t epoch;         /* clock restarts seen at the last sample */
    uint32_t fits;          /* samples in a row whose t_lo matched the prediction (to LOCK) */
    bool strayed;           /* the previous sample's t_lo strayed from a locked stream */
    double period_ms;       /* learnt sample period */
    double nominal_period_ms;
} sf_stream_time_t;

/* What a BOARD_TIME did to the clock. */
typedef enum {
    sf_board_time_believed, /* agreed: the clock moved on */
    sf_board_time_held,     /* disagreed: held until confirmed */
    sf_board_time_restart,  /* confirmed a held one: a new epoch began (streams restart) */
} sf_board_time_verdict_t;

void sf_board_clock_init(sf_board_clock_t *clock);

/* A BOARD_TIME frame, received at host_t_us. */
sf_board_time_verdict_t sf_board_clock_on_time(sf_board_clock_t *clock, uint32_t time_ms, uint8_t boot_id,
                                               int64_t host_t_us);

/* A full 32-bit board time carried by another frame (Wi-Fi scan start, GNSS), unwrapped to the one
 * nearest the clock, in board time (add offset_ms for output). SF_ENOTSYNC before the first
 * BOARD_TIME. */
int sf_board_clock_unwrap(const sf_board_clock_t *clock, uint32_t time_ms, int64_t *t_ms);

/* A full 32-bit board time carried by another frame, received at host_t_us, checked: SF_ERANGE when
 * it lies more than 60 s before the newest board time or more than 10 s after it plus the host time
 * since (a corrupt time: scans and fixes report when they started, seconds back; a flip of any bit
 * above bit 13 is caught, lower ones cannot be told from a true time). SF_ENOTSYNC before the first
 * BOARD_TIME. */
int sf_board_clock_carried(const sf_board_clock_t *clock, uint32_t time_ms, int64_t host_t_us, int64_t *t_ms);

/* The board time of a frame that carries t_lo_ms but no seq (BLE_ADV, LANDMARK: events, not a
 * periodic stream), received at host_t_us: the time with those low 8 bits nearest to the newest board
 * time known plus the host time since (within ±128 ms of it; the bus delivers a frame within
 * milliseconds of the samples around it). Such a frame never moves the clock: without a seq nothing
 * could tell a corrupt t_lo from a true one. SF_ENOTSYNC before the first BOARD_TIME. */
int sf_board_clock_event(const sf_board_clock_t *clock, uint8_t t_lo_ms, int64_t host_t_us, int64_t *t_ms);

/* Output time [µs] of a board time of the clock's current epoch. */
int64_t sf_board_clock_output_us(const sf_board_clock_t *clock, int64_t board_ms);

void sf_stream_time_init(sf_stream_time_t *stream, double nominal_period_ms);

/* Resolves one sample received at host_t_us. On SF_OK fills *t_ms (board time of the clock's
 * current epoch), *seq (unwrapped) and *lost (samples missing since the previous one). SF_ENOTSYNC
 * before the first BOARD_TIME; SF_EDUPLICATE when seq repeats the previous one; SF_ELATE / SF_ESEQ
 * as above. Skipped samples leave the stream as it was. May confirm a held BOARD_TIME (the clock's
 * epoch then changes). */
int sf_stream_time_resolve(sf_stream_time_t *stream, sf_board_clock_t *clock, uint8_t seq, uint8_t t_lo_ms,
                           int64_t host_t_us, int64_t *t_ms, int64_t *seq_unwrapped, uint32_t *lost);

#endif
