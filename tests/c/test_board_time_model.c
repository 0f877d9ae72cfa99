/* test_board_time_model.c — sf_board_time.c's inline rounding and division-free seq turns against
 * a dumb reference model: the implementation they replaced (libm llround, two divisions a sample),
 * kept here verbatim with its names prefixed ref_. Seeded board sessions — three streams, BOARD_TIME
 * every second, drift and host jitter and bursts, lost, repeated, swapped and bit-flipped frames,
 * long outages, time jumps and board restarts near the 32-bit wrap — go through both, which must
 * agree on every verdict, output and the whole state after every frame. Intrusive: it includes
 * sf_board_time.c to hold round_i64 and seq_turns to llround on their edges. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../firmware/board/sf_board_time.c"
#include "sf_test_rng.h"

/* ---- the reference: sf_board_time.c before the inline rounding (commit 2911159) ---- */

/* A BOARD_TIME agrees when it lies in [newest - EARLY, newest + elapsed · (1 + DRIFT) + LATE]: frames
 * are sent as sampled, so the board time never trails its newest sample by much; host receive times
 * jitter (USB adapters deliver in bursts) and the two clocks drift. */
#define REF_AGREE_EARLY_MS 500
#define REF_AGREE_LATE_MS 1000
#define REF_AGREE_DRIFT 0.1
/* A sample's Δseq is believed when it claims at most this much more time than the host saw pass. */
#define REF_SEQ_SLACK_MS 250.0
/* Within this many samples behind the stream, a sample that is not believed arrived late. */
#define REF_LATE_MAX_SAMPLES 32u
/* A sample fits a stream when its t_lo is this close to the stream's prediction, and confirms a
 * held BOARD_TIME when its seq restarted below REF_RESTART_SEQ_MAX within REF_FIRST_SAMPLE_MS of it. */
#define REF_FIT_MS 3
#define REF_FIT_MAX_SAMPLES 16u
#define REF_RESTART_SEQ_MAX 16u
#define REF_FIRST_SAMPLE_MS 160
/* After REF_LOCK_SAMPLES samples in a row within REF_FIT_MS of the prediction, a t_lo more than REF_STRAY_MS from
 * it is corrupt (sampling jitter of a board is a millisecond or two). */
#define REF_LOCK_SAMPLES 8u
#define REF_STRAY_MS 16

/* The value ≡ low (mod 2^bits) nearest to predicted. */
static int64_t ref_snap(const int64_t predicted, const uint64_t low, const unsigned bits)
{
    const int64_t mod = (int64_t)1 << bits;
    int64_t diff = (int64_t)((low - (uint64_t)predicted) & (uint64_t)(mod - 1));
    if (diff >= mod / 2) {
        diff -= mod;
    }
    return predicted + diff;
}

static int64_t ref_elapsed_ms(const int64_t from_host_us, const int64_t to_host_us)
{
    return to_host_us > from_host_us ? (to_host_us - from_host_us) / 1000 : 0;
}

/* Whether a 32-bit time received at host_us agrees with a reference (ref_ms seen at ref_host_us);
 * *t_ms is its unwrapped value. */
static bool ref_agrees(const int64_t ref_ms, const int64_t ref_host_us, const uint32_t time_ms, const int64_t host_us,
                   int64_t *const t_ms)
{
    const int64_t t = ref_snap(ref_ms, time_ms, 32);
    const int64_t e = ref_elapsed_ms(ref_host_us, host_us);
    *t_ms = t;
    return t >= ref_ms - REF_AGREE_EARLY_MS && t <= ref_ms + e + (int64_t)(REF_AGREE_DRIFT * (double)e) + REF_AGREE_LATE_MS;
}

static void ref_note(sf_board_clock_t *const c, const int64_t t_ms, const int64_t host_us)
{
    if (t_ms >= c->latest_ms) {
        c->latest_ms = t_ms;
        c->latest_host_us = host_us;
    }
}

/* A BOARD_TIME believed: the new anchor of every stream. */
static void ref_anchor(sf_board_clock_t *const c, const int64_t t_ms, const int64_t host_us)
{
    c->board_ms = t_ms;
    ref_note(c, t_ms, host_us);
    c->generation++;
}

static void ref_board_clock_init(sf_board_clock_t *const clock)
{
    *clock = (sf_board_clock_t){0};
}

/* Believes the held BOARD_TIME. A new boot id, or time gone back, starts a new epoch whose output
 * time goes on from the last output time plus the host time that passed. */
static sf_board_time_verdict_t ref_believe_held(sf_board_clock_t *const c)
{
    const sf_board_time_held_t h = c->held;
    c->held.valid = false;
    const int64_t t_same = ref_snap(c->latest_ms, h.time_ms, 32);
    if (h.boot_id == c->boot_id && t_same > c->latest_ms) {
        c->time_jumps++; /* same board, later time: an outage the host clock did not see */
        ref_anchor(c, t_same, h.host_t_us);
        return sf_board_time_believed;
    }
    const int64_t gap_ms = ref_elapsed_ms(c->latest_host_us, h.host_t_us);
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

static sf_board_time_verdict_t ref_board_clock_on_time(sf_board_clock_t *const c, const uint32_t time_ms,
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
    if (boot_id == c->boot_id && ref_agrees(c->latest_ms, c->latest_host_us, time_ms, host_t_us, &t)) {
        if (c->held.valid) {
            c->held.valid = false;
            c->time_rejected++;
        }
        ref_anchor(c, t, host_t_us);
        return sf_board_time_believed;
    }
    if (c->held.valid && boot_id == c->held.boot_id &&
        ref_agrees((int64_t)c->held.time_ms, c->held.host_t_us, time_ms, host_t_us, &t)) {
        const sf_board_time_verdict_t v = ref_believe_held(c);
        ref_anchor(c, v == sf_board_time_restart ? t : ref_snap(c->latest_ms, time_ms, 32), host_t_us); /* and this frame */
        return v;
    }
    if (c->held.valid) {
        c->time_rejected++; /* replaced by another that disagrees with it */
    }
    c->held = (sf_board_time_held_t){true, time_ms, boot_id, host_t_us};
    return sf_board_time_held;
}

static int ref_board_clock_unwrap(const sf_board_clock_t *const clock, const uint32_t time_ms, int64_t *const t_ms)
{
    if (!clock->synced) {
        return SF_ENOTSYNC;
    }
    *t_ms = ref_snap(clock->board_ms, time_ms, 32);
    return SF_OK;
}

#define REF_CARRIED_AGE_MAX_MS 60000
#define REF_CARRIED_AHEAD_MAX_MS 10000

static int ref_board_clock_carried(const sf_board_clock_t *const c, const uint32_t time_ms, const int64_t host_t_us,
                           int64_t *const t_ms)
{
    const int rc = ref_board_clock_unwrap(c, time_ms, t_ms);
    if (rc != SF_OK) {
        return rc;
    }
    const int64_t since_ms = ref_elapsed_ms(c->latest_host_us, host_t_us);
    if (*t_ms < c->latest_ms - REF_CARRIED_AGE_MAX_MS || *t_ms > c->latest_ms + since_ms + REF_CARRIED_AHEAD_MAX_MS) {
        return SF_ERANGE;
    }
    return SF_OK;
}

static int ref_board_clock_event(const sf_board_clock_t *const c, const uint8_t t_lo_ms, const int64_t host_t_us,
                         int64_t *const t_ms)
{
    if (!c->synced) {
        return SF_ENOTSYNC;
    }
    *t_ms = ref_snap(c->latest_ms + ref_elapsed_ms(c->latest_host_us, host_t_us), t_lo_ms, 8);
    return SF_OK;
}

static int64_t ref_board_clock_output_us(const sf_board_clock_t *const clock, const int64_t board_ms)
{
    return (board_ms + clock->offset_ms) * 1000;
}

static void ref_stream_time_init(sf_stream_time_t *const stream, const double nominal_period_ms)
{
    *stream = (sf_stream_time_t){0};
    stream->nominal_period_ms = nominal_period_ms;
    stream->period_ms = nominal_period_ms;
}

/* The sample continues its stream: a small Δseq and t_lo where the period puts it. */
static bool ref_fits_stream(const sf_stream_time_t *const s, const unsigned dseq, const uint8_t t_lo_ms)
{
    if (!s->started || dseq == 0 || dseq > REF_FIT_MAX_SAMPLES) {
        return false;
    }
    const int64_t predicted = s->last_t_ms + (int64_t)llround((double)dseq * s->period_ms);
    return llabs(ref_snap(predicted, t_lo_ms, 8) - predicted) <= REF_FIT_MS;
}

/* The sample is a restarted stream's first at the held BOARD_TIME of a new boot (a same-boot time
 * jump waits for the next BOARD_TIME). */
static bool ref_starts_at_held(const sf_board_clock_t *const c, const uint8_t seq, const uint8_t t_lo_ms)
{
    if (!c->held.valid || c->held.boot_id == c->boot_id || seq >= REF_RESTART_SEQ_MAX) {
        return false;
    }
    const int64_t held_ms = (int64_t)c->held.time_ms;
    const int64_t t = ref_snap(held_ms, t_lo_ms, 8);
    return t >= held_ms - REF_FIT_MS && t <= held_ms + REF_FIRST_SAMPLE_MS;
}

static int ref_stream_time_resolve(sf_stream_time_t *const s, sf_board_clock_t *const clock, const uint8_t seq,
                           const uint8_t t_lo_ms, const int64_t host_t_us, int64_t *const t_ms,
                           int64_t *const seq_unwrapped, uint32_t *const lost)
{
    if (!clock->synced) {
        return SF_ENOTSYNC;
    }
    const unsigned dseq = (unsigned)(uint8_t)(seq - s->last_seq);
    if (s->epoch == clock->restarts && ref_starts_at_held(clock, seq, t_lo_ms) && !ref_fits_stream(s, dseq, t_lo_ms)) {
        (void)ref_believe_held(clock);
    }
    if (s->started && s->epoch != clock->restarts) {
        ref_stream_time_init(s, s->nominal_period_ms); /* the board restarted: old times mean nothing */
    }
    if (s->started && dseq == 0) {
        return SF_EDUPLICATE;
    }
    int64_t t = ref_snap(clock->board_ms, t_lo_ms, 8);
    if (s->started) {
        const double host_ms = (double)ref_elapsed_ms(s->last_host_us, host_t_us);
        if ((double)dseq * s->period_ms > host_ms * (1.0 + REF_AGREE_DRIFT) + REF_SEQ_SLACK_MS) {
            return 256u - dseq <= REF_LATE_MAX_SAMPLES ? SF_ELATE : SF_ESEQ;
        }
        /* The advance ≡ Δseq (mod 256) nearest to the host time that passed: exact past the wrap. */
        const double wraps = (double)llround((host_ms / s->period_ms - (double)dseq) / 256.0);
        const double advance = (double)dseq + 256.0 * (wraps > 0 ? wraps : 0);
        const int64_t predicted = s->last_t_ms + (int64_t)llround(advance * s->period_ms);
        const int64_t by_seq = ref_snap(predicted, t_lo_ms, 8);
        /* A locked stream's t_lo that strays from the prediction is corrupt, not the board's timing:
         * skipped once; a second in a row is believed (the timing really changed). */
        const int64_t stray_ms = llabs(by_seq - predicted);
        if (s->fits >= REF_LOCK_SAMPLES && stray_ms > REF_STRAY_MS && !s->strayed) {
            s->strayed = true;
            return SF_ESEQ;
        }
        s->strayed = false;
        s->fits = stray_ms <= REF_FIT_MS ? (s->fits < REF_LOCK_SAMPLES ? s->fits + 1 : s->fits) : 0;
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
    s->last_host_us = host_t_us;
    s->seq = useq;
    s->generation = clock->generation;
    s->epoch = clock->restarts;
    ref_note(clock, t, host_t_us);
    *t_ms = t;
    *seq_unwrapped = useq;
    *lost = missing;
    return SF_OK;
}

/* ---- round_i64 and seq_turns on their edges ---- */

static void check_round(const double x)
{
    if (round_i64(x) != (int64_t)llround(x)) {
        fail_msg("round_i64(%.17g) = %lld, llround %lld", x, (long long)round_i64(x), (long long)llround(x));
    }
}

static void test_round_is_llround(void **state)
{
    (void)state;
    const double edges[] = {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                            0x1p52, 0x1p52 + 1, 0x1p52 - 0.5, -0x1p52 + 0.5, 0x1p53 - 1, 0x1p62 - 1024, -0x1p62 + 1024,
                            0x1p62, -0x1p62, 0x1p63 * 0.75, DBL_MIN, -DBL_MIN, 4503599627370495.5,
                            -4503599627370495.5};
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++) {
        check_round(edges[i]);
        check_round(nextafter(edges[i], INFINITY));
        check_round(nextafter(edges[i], -INFINITY));
    }
    rng_t rng = {0x0ddba11ULL};
    for (int i = 0; i < 1000000; i++) {
        const double m = rng_pm1(&rng) * ldexp(1.0, (int)(rng_uniform01(&rng) * 64.0) - 2);
        check_round(m);
        const double half = floor(m) + 0.5; /* the ties, and their neighbours */
        check_round(half);
        check_round(nextafter(half, INFINITY));
        check_round(nextafter(half, -INFINITY));
    }
}

static void test_seq_turns_is_the_division(void **state)
{
    (void)state;
    rng_t rng = {0x7e57ab1eULL};
    for (int i = 0; i < 1000000; i++) {
        const double period = (i % 7 == 0) ? 10.0 : 2.0 + 100.0 * rng_uniform01(&rng);
        const unsigned dseq = (unsigned)(rng_uniform01(&rng) * 256.0);
        double span = floor(rng_pm1(&rng) * 300.0 * period);
        if (i % 5 == 0) {
            span = 64.0 * period; /* the bound, and next to it */
            span = i % 10 == 0 ? nextafter(span, INFINITY) : span;
        }
        const int64_t want = (int64_t)llround((span / period - (double)dseq) / 256.0);
        if (seq_turns(span, period, dseq) != want) {
            fail_msg("seq_turns(%.17g, %.17g, %u) = %lld, the division %lld", span, period, dseq,
                     (long long)seq_turns(span, period, dseq), (long long)want);
        }
    }
}

/* ---- whole board sessions through both ---- */

#define N_STREAMS 3
#define N_SESSIONS 120
#define SESSION_MS 60000

typedef struct {
    bool is_time; /* a BOARD_TIME, else a sample of stream */
    int stream;
    uint8_t seq, t_lo;
    uint32_t time_ms;
    uint8_t boot_id;
    int64_t host_us;
} frame_t;

typedef struct {
    sf_board_clock_t clock;
    sf_stream_time_t st[N_STREAMS];
} side_t;

static bool same_clock(const sf_board_clock_t *const a, const sf_board_clock_t *const b)
{
    return a->synced == b->synced && a->board_ms == b->board_ms && a->generation == b->generation &&
           a->boot_id == b->boot_id && a->offset_ms == b->offset_ms && a->latest_ms == b->latest_ms &&
           a->latest_host_us == b->latest_host_us && a->held.valid == b->held.valid &&
           a->held.time_ms == b->held.time_ms && a->held.boot_id == b->held.boot_id &&
           a->held.host_t_us == b->held.host_t_us && a->restarts == b->restarts && a->time_jumps == b->time_jumps &&
           a->time_rejected == b->time_rejected;
}

static bool same_stream(const sf_stream_time_t *const a, const sf_stream_time_t *const b)
{
    return a->started == b->started && a->last_seq == b->last_seq && a->last_t_ms == b->last_t_ms &&
           a->last_host_us == b->last_host_us && a->seq == b->seq && a->generation == b->generation &&
           a->epoch == b->epoch && a->fits == b->fits && a->strayed == b->strayed &&
           memcmp(&a->period_ms, &b->period_ms, sizeof a->period_ms) == 0 &&
           memcmp(&a->nominal_period_ms, &b->nominal_period_ms, sizeof a->nominal_period_ms) == 0;
}

/* One frame into both sides; every result compared. */
static void feed_both(side_t *const a, side_t *const b, const frame_t *const f, long *const resolved)
{
    if (f->is_time) {
        const sf_board_time_verdict_t va = sf_board_clock_on_time(&a->clock, f->time_ms, f->boot_id, f->host_us);
        const sf_board_time_verdict_t vb = ref_board_clock_on_time(&b->clock, f->time_ms, f->boot_id, f->host_us);
        assert_int_equal(va, vb);
        int64_t ta = 0, tb = 0;
        assert_int_equal(sf_board_clock_carried(&a->clock, f->time_ms - 5000u, f->host_us, &ta),
                         ref_board_clock_carried(&b->clock, f->time_ms - 5000u, f->host_us, &tb));
        assert_true(ta == tb);
        assert_int_equal(sf_board_clock_unwrap(&a->clock, f->time_ms + 7u, &ta),
                         ref_board_clock_unwrap(&b->clock, f->time_ms + 7u, &tb));
        assert_true(ta == tb);
    } else {
        int64_t ta = 0, tb = 0, ua = 0, ub = 0;
        uint32_t la = 0, lb = 0;
        const int i = f->stream;
        const int ra = sf_stream_time_resolve(&a->st[i], &a->clock, f->seq, f->t_lo, f->host_us, &ta, &ua, &la);
        const int rb = ref_stream_time_resolve(&b->st[i], &b->clock, f->seq, f->t_lo, f->host_us, &tb, &ub, &lb);
        if (ra != rb || ta != tb || ua != ub || la != lb) {
            fail_msg("stream %d seq %u t_lo %u host %lld: %d t %lld useq %lld lost %u; reference %d t %lld useq %lld "
                     "lost %u", f->stream, f->seq, f->t_lo, (long long)f->host_us, ra, (long long)ta, (long long)ua,
                     la, rb, (long long)tb, (long long)ub, lb);
        }
        *resolved += ra == SF_OK;
        int64_t ea = 0, eb = 0;
        assert_int_equal(sf_board_clock_event(&a->clock, f->t_lo, f->host_us, &ea),
                         ref_board_clock_event(&b->clock, f->t_lo, f->host_us, &eb));
        assert_true(ea == eb && sf_board_clock_output_us(&a->clock, ea) == ref_board_clock_output_us(&b->clock, eb));
    }
    assert_true(same_clock(&a->clock, &b->clock));
    for (int i = 0; i < N_STREAMS; i++) {
        assert_true(same_stream(&a->st[i], &b->st[i]));
    }
}

static bool chance(rng_t *const r, const double p)
{
    return rng_uniform01(r) < p;
}

/* One session's frames, in bus order with faults, into out; their count. */
static size_t session(rng_t *const r, frame_t *const out, const size_t cap)
{
    static const double nominal[N_STREAMS] = {10.0, 20.0, 50.0};
    double period[N_STREAMS], next_ms[N_STREAMS];
    unsigned seq[N_STREAMS] = {0};
    const double rate = 1.0 + 0.02 * rng_pm1(r); /* board vs host clock */
    int64_t board0 = chance(r, 0.3) ? 0xFFFFFFFFLL - (int64_t)(rng_uniform01(r) * 30000.0)
                                    : (int64_t)(rng_uniform01(r) * 4e9);
    uint8_t boot = (uint8_t)(rng_uniform01(r) * 256.0);
    for (int i = 0; i < N_STREAMS; i++) {
        period[i] = nominal[i] * (1.0 + 0.08 * rng_pm1(r));
        next_ms[i] = rng_uniform01(r) * nominal[i];
    }
    const double jitter_ms = chance(r, 0.5) ? 0.3 : 8.0;
    int64_t host_extra_us = 0;
    size_t n = 0;
    for (int64_t ms = 0; ms < SESSION_MS && n + 8 < cap; ms++) {
        if (chance(r, 0.00005)) { /* a restart: new boot, board time from near 0, seqs from 0 */
            board0 = (int64_t)(rng_uniform01(r) * 500.0) - ms;
            boot = (uint8_t)(boot + 1 + (chance(r, 0.2) ? 0 : 1));
            for (int i = 0; i < N_STREAMS; i++) {
                seq[i] = 0;
            }
        }
        if (chance(r, 0.00003)) { /* an outage the host saw too: nothing for seconds */
            const int64_t gap = 1000 + (int64_t)(rng_uniform01(r) * 8000.0);
            ms += gap;
            for (int i = 0; i < N_STREAMS; i++) {
                while (next_ms[i] < (double)ms) {
                    next_ms[i] += period[i];
                    seq[i]++;
                }
            }
        }
        if (chance(r, 0.00002)) {
            board0 += (int64_t)(rng_uniform01(r) * 300000.0); /* a same-boot time jump */
        }
        if (chance(r, 0.0005)) {
            host_extra_us += (int64_t)(rng_uniform01(r) * 40000.0); /* a burst: the host fell behind */
        }
        const int64_t host_base = 1700000000000000LL + (int64_t)((double)ms * 1000.0 * rate) + host_extra_us;
        const uint32_t board_ms = (uint32_t)(board0 + ms);
        if (ms % 1000 == 0 && !chance(r, 0.05)) {
            frame_t f = {.is_time = true, .time_ms = board_ms, .boot_id = boot, .host_us = host_base};
            if (chance(r, 0.01)) {
                f.time_ms ^= 1u << (int)(rng_uniform01(r) * 32.0);
            }
            if (chance(r, 0.005)) {
                f.boot_id ^= (uint8_t)(1u << (int)(rng_uniform01(r) * 8.0));
            }
            out[n++] = f;
        }
        for (int i = 0; i < N_STREAMS; i++) {
            if ((double)ms < next_ms[i]) {
                continue;
            }
            next_ms[i] += period[i];
            const uint8_t s = (uint8_t)seq[i]++;
            const int64_t t = board0 + ms + (chance(r, 0.05) ? (chance(r, 0.5) ? 1 : -1) : 0);
            frame_t f = {.stream = i, .seq = s, .t_lo = (uint8_t)t,
                         .host_us = host_base + (int64_t)(fabs(rng_gauss(r)) * jitter_ms * 1000.0)};
            if (chance(r, 0.003)) {
                f.seq ^= (uint8_t)(1u << (int)(rng_uniform01(r) * 8.0));
            }
            if (chance(r, 0.003)) {
                f.t_lo ^= (uint8_t)(1u << (int)(rng_uniform01(r) * 8.0));
            }
            if (chance(r, 0.02)) {
                continue; /* lost */
            }
            out[n++] = f;
            if (chance(r, 0.005)) {
                out[n++] = f; /* repeated */
            }
            if (n >= 2 && chance(r, 0.005)) { /* swapped with the one before */
                const frame_t prev = out[n - 2];
                out[n - 2] = out[n - 1];
                out[n - 1] = prev;
            }
            if (chance(r, 0.0005)) {
                const int run = (int)(rng_uniform01(r) * 600.0); /* a long loss: past the seq wrap */
                for (int k = 0; k < run; k++) {
                    seq[i]++;
                    next_ms[i] += period[i];
                }
            }
        }
    }
    return n;
}

static void test_sessions_agree_with_the_reference(void **state)
{
    (void)state;
    const size_t cap = (size_t)SESSION_MS / 5;
    frame_t *const frames = malloc(cap * sizeof *frames);
    assert_non_null(frames);
    rng_t rng = {0xb0a2d71eULL};
    long resolved = 0, restarts = 0, jumps = 0;
    for (int k = 0; k < N_SESSIONS; k++) {
        const size_t n = session(&rng, frames, cap);
        side_t a, b;
        sf_board_clock_init(&a.clock);
        ref_board_clock_init(&b.clock);
        static const double nominal[N_STREAMS] = {10.0, 20.0, 50.0};
        for (int i = 0; i < N_STREAMS; i++) {
            sf_stream_time_init(&a.st[i], nominal[i]);
            ref_stream_time_init(&b.st[i], nominal[i]);
        }
        for (size_t i = 0; i < n; i++) {
            feed_both(&a, &b, &frames[i], &resolved);
        }
        restarts += a.clock.restarts;
        jumps += a.clock.time_jumps;
    }
    free(frames);
    print_message("%ld samples resolved, %ld restarts, %ld time jumps\n", resolved, restarts, jumps);
    assert_true(resolved > 100000 && restarts > 0 && jumps > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_is_llround),
        cmocka_unit_test(test_seq_turns_is_the_division),
        cmocka_unit_test(test_sessions_agree_with_the_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
