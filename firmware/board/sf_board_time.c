/* sf_board_time.c — see sf_board_time.h for the reconstruction and belief rules. */
#include "sf_board_time.h"

#include <math.h>
#include <stdlib.h>

#include "sf_error.h"

/* A BOARD_TIME agrees when it lies in [newest - EARLY, newest + elapsed · (1 + DRIFT) + LATE]: frames
 * are sent as sampled, so the board time never trails its newest sample by much; host receive times
 * jitter (USB adapters deliver in bursts) and the two clocks drift. */
#define AGREE_EARLY_MS 500
#define AGREE_LATE_MS 1000
#define AGREE_DRIFT 0.1
/* A sample's Δseq is believed when it claims at most this much more time than the host saw pass. */
#define SEQ_SLACK_MS 250.0
/* Within this many samples behind the stream, a sample that is not believed arrived late. */
#define LATE_MAX_SAMPLES 32u
/* A sample fits a stream when its t_lo is this close to the stream's prediction, and confirms a
 * held BOARD_TIME when its seq restarted below RESTART_SEQ_MAX within FIRST_SAMPLE_MS of it. */
#define FIT_MS 3
#define FIT_MAX_SAMPLES 16u
#define RESTART_SEQ_MAX 16u
#define FIRST_SAMPLE_MS 160
/* After LOCK_SAMPLES samples in a row within FIT_MS of the prediction, a t_lo more than STRAY_MS from
 * it is corrupt (sampling jitter of a board is a millisecond or two). */
#define LOCK_SAMPLES 8u
#define STRAY_MS 16

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

/* llround(x), inline: a replay resolves 600 k samples an hour of walking, three roundings each, and
 * libm's llround was a call of ~20 instructions. Exact for |x| < 2^62 (the integer part converts
 * exactly, and x minus it is exact: the bits below the point); halves away from zero as llround;
 * anything else (never seen here) goes to llround itself. */
#define ROUND_EXACT_MAX 4611686018427387904.0 /* 2^62 */

static int64_t round_i64(const double x)
{
    if (!(fabs(x) < ROUND_EXACT_MAX)) { /* NaN too */
        return (int64_t)llround(x);
    }
    int64_t r = (int64_t)x; /* toward zero */
    const double frac = x - (double)r;
    if (frac >= 0.5) {
        r++;
    } else if (frac <= -0.5) {
        r--;
    }
    return r;
}

/* round_i64((span / period - dseq) / 256): the turns of the 8-bit seq in span, beyond dseq. Without
 * the division when the answer is surely 0: for 0 <= span <= 64 · period (64 · period exact) and
 * dseq < 128, the rounded quotient lies in [0, 64] (rounding is monotonic and 64 representable), so
 * the difference lies in [-127, 63] and its 256th (exact) within ±0.5. */
static int64_t seq_turns(const double span, const double period, const unsigned dseq)
{
    if (dseq < 128u && period > 0.0 && span >= 0.0 && span <= 64.0 * period) {
        return 0;
    }
    return round_i64((span / period - (double)dseq) / 256.0);
}

static int64_t elapsed_ms(const int64_t from_host_us, const int64_t to_host_us)
{
    return to_host_us > from_host_us ? (to_host_us - from_host_us) / 1000 : 0;
}

/* Whether a 32-bit time received at host_us agrees with a reference (ref_ms seen at ref_host_us);
 * *t_ms is its unwrapped value. */
static bool agrees(const int64_t ref_ms, const int64_t ref_host_us, const uint32_t time_ms, const int64_t host_us,
                   int64_t *const t_ms)
{
    const int64_t t = snap(ref_ms, time_ms, 32);
    const int64_t e = elapsed_ms(ref_host_us, host_us);
    *t_ms = t;
    return t >= ref_ms - AGREE_EARLY_MS && t <= ref_ms + e + (int64_t)(AGREE_DRIFT * (double)e) + AGREE_LATE_MS;
}

/* Whether a BOARD_TIME received at host_us confirms the held one: it agrees with it and has moved on
 * with the host time since, less drift and jitter. A board clock counts; a stuck BOARD_TIME repeats
 * its value second after second while the samples go on, and believing it would restart every
 * stream at a stale time (and its return as an outage). A frame the bus repeated (no host time
 * between) confirms as before. */
static bool confirms_held(const sf_board_time_held_t *const h, const uint32_t time_ms, const int64_t host_us,
                          int64_t *const t_ms)
{
    if (!agrees((int64_t)h->time_ms, h->host_t_us, time_ms, host_us, t_ms)) {
        return false;
    }
    const int64_t e = elapsed_ms(h->host_t_us, host_us);
    return *t_ms >= (int64_t)h->time_ms + e - (int64_t)(AGREE_DRIFT * (double)e) - AGREE_EARLY_MS;
}

static void note(sf_board_clock_t *const c, const int64_t t_ms, const int64_t host_us)
{
    if (t_ms >= c->latest_ms) {
        c->latest_ms = t_ms;
        c->latest_host_us = host_us;
    }
}

/* A BOARD_TIME believed: the new anchor of every stream. */
static void anchor(sf_board_clock_t *const c, const int64_t t_ms, const int64_t host_us)
{
    c->board_ms = t_ms;
    note(c, t_ms, host_us);
    c->generation++;
}

void sf_board_clock_init(sf_board_clock_t *const clock)
{
    *clock = (sf_board_clock_t){0};
}

/* Believes the held BOARD_TIME. A new boot id, or time gone back, starts a new epoch whose output
 * time goes on from the last output time plus the host time that passed. */
static sf_board_time_verdict_t believe_held(sf_board_clock_t *const c)
{
    const sf_board_time_held_t h = c->held;
    c->held.valid = false;
    const int64_t t_same = snap(c->latest_ms, h.time_ms, 32);
    if (h.boot_id == c->boot_id && t_same > c->latest_ms) {
        c->time_jumps++; /* same board, later time: an outage the host clock did not see */
        anchor(c, t_same, h.host_t_us);
        return sf_board_time_believed;
    }
    const int64_t gap_ms = elapsed_ms(c->latest_host_us, h.host_t_us);
    const int64_t out_ms = c->latest_ms + c->offset_ms + (gap_ms > 1 ? gap_ms : 1);
    c->board_ms = (int64_t)h.time_ms;
    c->offset_ms = out_ms - c->board_ms;
    c->latest_ms = c->board_ms;
    c->latest_host_us = h.host_t_us;
    c->boot_id = h.boot_id;
    c->restarts++;
    c->generation++;
    return sf_board_time_restart;
}

sf_board_time_verdict_t sf_board_clock_on_time(sf_board_clock_t *const c, const uint32_t time_ms,
                                               const uint8_t boot_id, const int64_t host_t_us)
{
    if (!c->synced) {
        c->synced = true;
        c->board_ms = (int64_t)time_ms;
        c->boot_id = boot_id;
        c->latest_ms = c->board_ms;
        c->latest_host_us = host_t_us;
        c->generation++;
        return sf_board_time_believed;
    }
    int64_t t;
    if (boot_id == c->boot_id && agrees(c->latest_ms, c->latest_host_us, time_ms, host_t_us, &t)) {
        if (c->held.valid) {
            c->held.valid = false;
            c->time_rejected++;
        }
        anchor(c, t, host_t_us);
        return sf_board_time_believed;
    }
    if (c->held.valid && boot_id == c->held.boot_id && confirms_held(&c->held, time_ms, host_t_us, &t)) {
        const sf_board_time_verdict_t v = believe_held(c);
        anchor(c, v == sf_board_time_restart ? t : snap(c->latest_ms, time_ms, 32), host_t_us); /* and this frame */
        return v;
    }
    if (c->held.valid) {
        c->time_rejected++; /* replaced by another that disagrees with it */
    }
    c->held = (sf_board_time_held_t){true, time_ms, boot_id, host_t_us};
    return sf_board_time_held;
}

int sf_board_clock_unwrap(const sf_board_clock_t *const clock, const uint32_t time_ms, int64_t *const t_ms)
{
    if (!clock->synced) {
        return SF_ENOTSYNC;
    }
    *t_ms = snap(clock->board_ms, time_ms, 32);
    return SF_OK;
}

#define CARRIED_AGE_MAX_MS 60000
#define CARRIED_AHEAD_MAX_MS 10000

int sf_board_clock_carried(const sf_board_clock_t *const c, const uint32_t time_ms, const int64_t host_t_us,
                           int64_t *const t_ms)
{
    const int rc = sf_board_clock_unwrap(c, time_ms, t_ms);
    if (rc != SF_OK) {
        return rc;
    }
    const int64_t since_ms = elapsed_ms(c->latest_host_us, host_t_us);
    if (*t_ms < c->latest_ms - CARRIED_AGE_MAX_MS || *t_ms > c->latest_ms + since_ms + CARRIED_AHEAD_MAX_MS) {
        return SF_ERANGE;
    }
    return SF_OK;
}

int sf_board_clock_event(const sf_board_clock_t *const c, const uint8_t t_lo_ms, const int64_t host_t_us,
                         int64_t *const t_ms)
{
    if (!c->synced) {
        return SF_ENOTSYNC;
    }
    *t_ms = snap(c->latest_ms + elapsed_ms(c->latest_host_us, host_t_us), t_lo_ms, 8);
    return SF_OK;
}

int64_t sf_board_clock_output_us(const sf_board_clock_t *const clock, const int64_t board_ms)
{
    return (board_ms + clock->offset_ms) * 1000;
}

void sf_stream_time_init(sf_stream_time_t *const stream, const double nominal_period_ms)
{
    *stream = (sf_stream_time_t){0};
    stream->nominal_period_ms = nominal_period_ms;
    stream->period_ms = nominal_period_ms;
}

/* The sample continues its stream: a small Δseq and t_lo where the period puts it. */
static bool fits_stream(const sf_stream_time_t *const s, const unsigned dseq, const uint8_t t_lo_ms)
{
    if (!s->started || dseq == 0 || dseq > FIT_MAX_SAMPLES) {
        return false;
    }
    const int64_t predicted = s->last_t_ms + round_i64((double)dseq * s->period_ms);
    return llabs(snap(predicted, t_lo_ms, 8) - predicted) <= FIT_MS;
}

/* The sample is a restarted stream's first at the held BOARD_TIME of a new boot (a same-boot time
 * jump waits for the next BOARD_TIME). */
static bool starts_at_held(const sf_board_clock_t *const c, const uint8_t seq, const uint8_t t_lo_ms)
{
    if (!c->held.valid || c->held.boot_id == c->boot_id || seq >= RESTART_SEQ_MAX) {
        return false;
    }
    const int64_t held_ms = (int64_t)c->held.time_ms;
    const int64_t t = snap(held_ms, t_lo_ms, 8);
    return t >= held_ms - FIT_MS && t <= held_ms + FIRST_SAMPLE_MS;
}

int sf_stream_time_resolve(sf_stream_time_t *const s, sf_board_clock_t *const clock, const uint8_t seq,
                           const uint8_t t_lo_ms, const int64_t host_t_us, int64_t *const t_ms,
                           int64_t *const seq_unwrapped, uint32_t *const lost)
{
    if (!clock->synced) {
        return SF_ENOTSYNC;
    }
    const unsigned dseq = (unsigned)(uint8_t)(seq - s->last_seq);
    if (s->epoch == clock->restarts && starts_at_held(clock, seq, t_lo_ms) && !fits_stream(s, dseq, t_lo_ms)) {
        (void)believe_held(clock);
    }
    if (s->started && s->epoch != clock->restarts) {
        sf_stream_time_init(s, s->nominal_period_ms); /* the board restarted: old times mean nothing */
    }
    if (s->started && dseq == 0) {
        return SF_EDUPLICATE;
    }
    int64_t t = snap(clock->board_ms, t_lo_ms, 8);
    if (s->started) {
        const double host_ms = (double)elapsed_ms(s->last_host_us, host_t_us);
        if ((double)dseq * s->period_ms > host_ms * (1.0 + AGREE_DRIFT) + SEQ_SLACK_MS) {
            return 256u - dseq <= LATE_MAX_SAMPLES ? SF_ELATE : SF_ESEQ;
        }
        /* The advance ≡ Δseq (mod 256) nearest to the host time that passed: exact past the wrap. */
        const double wraps = (double)seq_turns(host_ms, s->period_ms, dseq);
        const double advance = (double)dseq + 256.0 * (wraps > 0 ? wraps : 0);
        const int64_t predicted = s->last_t_ms + round_i64(advance * s->period_ms);
        const int64_t by_seq = snap(predicted, t_lo_ms, 8);
        /* A locked stream's t_lo that strays from the prediction is corrupt, not the board's timing:
         * skipped once; a second in a row is believed (the timing really changed). */
        const int64_t stray_ms = llabs(by_seq - predicted);
        if (s->fits >= LOCK_SAMPLES && stray_ms > STRAY_MS && !s->strayed) {
            s->strayed = true;
            return SF_ESEQ;
        }
        s->strayed = false;
        s->fits = stray_ms <= FIT_MS ? (s->fits < LOCK_SAMPLES ? s->fits + 1 : s->fits) : 0;
        /* Trust the sequence unless a newer BOARD_TIME proves it wrong: a sample is never sent
         * long before the BOARD_TIME that precedes it on the bus. */
        const bool new_anchor = s->generation != clock->generation;
        if (!new_anchor || by_seq >= clock->board_ms - 128) {
            t = by_seq;
        }
    }

    uint32_t missing = 0;
    int64_t useq = seq;
    if (s->started) {
        /* Unwrapped seq: the advance k ≡ dseq (mod 256) nearest to the elapsed time in periods. */
        const int64_t k = (int64_t)dseq + 256 * seq_turns((double)(t - s->last_t_ms), s->period_ms, dseq);
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
    s->last_host_us = host_t_us;
    s->seq = useq;
    s->generation = clock->generation;
    s->epoch = clock->restarts;
    note(clock, t, host_t_us);
    *t_ms = t;
    *seq_unwrapped = useq;
    *lost = missing;
    return SF_OK;
}
