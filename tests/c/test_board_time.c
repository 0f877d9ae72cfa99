/* test_board_time.c — sample time reconstruction (sf_board_time.h), directly and through
 * sf_board_rx_frame with frames packed by the generated board_*_pack functions.
 *
 * The simulated board samples at 100 Hz: sample k has board time t0 + 10 k ms, seq = k mod 256 and
 * t_lo_ms = time mod 256, and a BOARD_TIME frame goes out just before every sample whose time is a
 * whole second after t0. Lost frames are marked per sample and per BOARD_TIME. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_board_rx.h"
#include "sf_board_time.h"
#include "sf_error.h"
#include "sf_test_frames.h"

#define PERIOD_MS 10
/* Host receive time of a frame sent at board time t_ms: the board sends as it samples. */
#define HOST_US(t_ms) (1700000000000000LL + (int64_t)(t_ms) * 1000)
#define MAX_SAMPLES 2000

typedef struct {
    int64_t t0_ms;        /* board time of sample 0 (may be beyond 32 bits: sent modulo 2^32) */
    int n;                /* samples simulated */
    bool drop[MAX_SAMPLES];      /* sample k is lost */
    bool drop_time[MAX_SAMPLES]; /* the BOARD_TIME before sample k (if any) is lost */
    bool no_check[MAX_SAMPLES];  /* sample k's time cannot be recovered: do not check it */
} scenario_t;

typedef struct {
    int delivered;
    int64_t dropped;    /* samples lost after the first delivered one */
    int64_t lost_total; /* sum of the `lost` outputs */
} totals_t;

static bool is_time_frame(const int k)
{
    return (k * PERIOD_MS) % 1000 == 0;
}

static scenario_t *new_scenario(const int64_t t0_ms, const int n)
{
    scenario_t *const s = calloc(1, sizeof *s);
    assert_non_null(s);
    assert_true(n <= MAX_SAMPLES);
    s->t0_ms = t0_ms;
    s->n = n;
    return s;
}

/* Loses samples [from, from + count), and the BOARD_TIMEs among them when with_time is false. */
static void lose(scenario_t *const s, const int from, const int count, const bool lose_time_frames_too)
{
    for (int k = from; k < from + count; k++) {
        s->drop[k] = true;
        s->drop_time[k] = lose_time_frames_too;
    }
}

/* Runs the scenario through sf_stream_time_resolve and checks every recoverable sample's time,
 * its lost count and its unwrapped seq. */
static totals_t run_direct(const scenario_t *const s)
{
    sf_board_clock_t clock;
    sf_stream_time_t st;
    sf_board_clock_init(&clock);
    sf_stream_time_init(&st, PERIOD_MS);
    totals_t tot = {0};
    int last_k = -1;
    int64_t first_useq = 0;
    int first_k = -1;
    for (int k = 0; k < s->n; k++) {
        const int64_t t = s->t0_ms + (int64_t)k * PERIOD_MS;
        if (is_time_frame(k) && !s->drop_time[k]) {
            sf_board_clock_on_time(&clock, (uint32_t)t, 7, HOST_US(t));
        }
        if (s->drop[k]) {
            if (last_k >= 0) {
                tot.dropped++;
            }
            continue;
        }
        int64_t t_ms = -1;
        int64_t useq = -1;
        uint32_t lost = 12345;
        const int rc = sf_stream_time_resolve(&st, &clock, (uint8_t)k, (uint8_t)t, HOST_US(t), &t_ms, &useq, &lost);
        assert_int_equal(rc, SF_OK);
        if (first_k < 0) {
            first_k = k;
            first_useq = useq;
            assert_int_equal(useq, k % 256);
        }
        if (!s->no_check[k]) {
            if (t_ms != t) {
                fail_msg("sample %d: time %lld ms, want %lld (off by %lld)", k, (long long)t_ms, (long long)t,
                         (long long)(t_ms - t));
            }
            if (last_k >= 0 && !s->no_check[last_k] && lost != (uint32_t)(k - last_k - 1)) {
                fail_msg("sample %d: lost %u, want %d", k, lost, k - last_k - 1);
            }
            if (useq != first_useq + (k - first_k)) {
                fail_msg("sample %d: unwrapped seq %lld, want %lld", k, (long long)useq,
                         (long long)(first_useq + (k - first_k)));
            }
        }
        tot.lost_total += lost;
        tot.delivered++;
        last_k = k;
    }
    return tot;
}

static void test_100hz_12s_exact_through_seq_and_t_lo_wraps(void **state)
{
    (void)state;
    scenario_t *const s = new_scenario(123457, 1200); /* t0 not a multiple of 256: t_lo starts mid-way */
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.delivered, 1200);
    assert_int_equal(tot.lost_total, 0);
    free(s);
}

static void test_single_and_burst_losses_without_board_time(void **state)
{
    (void)state;
    /* Single, 5 and 50 lost samples, each burst also losing every BOARD_TIME inside it (a real
     * outage), none touching a BOARD_TIME boundary: the seq prediction alone must recover them. */
    scenario_t *const s = new_scenario(50000, 1200);
    lose(s, 150, 1, true);
    lose(s, 310, 5, true);
    lose(s, 420, 50, true); /* 420..469: no BOARD_TIME inside */
    lose(s, 510, 50, true); /* 510..559: no BOARD_TIME inside */
    lose(s, 830, 250, true); /* 250 < 256: spans boundaries 900 and 1000, all BOARD_TIMEs lost */
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.dropped, 1 + 5 + 50 + 50 + 250);
    assert_int_equal(tot.lost_total, tot.dropped);
    assert_int_equal(tot.delivered, 1200 - tot.dropped);
    free(s);
}

static void test_300_lost_with_board_time_received(void **state)
{
    (void)state;
    /* 300 samples (longer than the seq wrap) lost, but the BOARD_TIME frames in between arrive: the
     * first sample after the outage follows a BOARD_TIME closely and is exact. */
    scenario_t *const s = new_scenario(50000, 1500);
    lose(s, 700, 300, false); /* 700..999; the BOARD_TIME before sample 1000 arrives */
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.dropped, 300);
    assert_int_equal(tot.lost_total, 300);
    free(s);
}

static void test_300_lost_without_board_time(void **state)
{
    (void)state;
    /* 300 samples and their BOARD_TIMEs lost: Δseq is ambiguous (300 ≡ 44 mod 256), so the samples
     * between the outage and the next BOARD_TIME cannot be timed. From the next BOARD_TIME on every
     * time is exact again, and the total lost count is right. */
    scenario_t *const s = new_scenario(50000, 1500);
    lose(s, 650, 300, true); /* 650..949, BOARD_TIMEs before 700, 800, 900 lost */
    for (int k = 950; k < 1000; k++) {
        s->no_check[k] = true; /* up to the BOARD_TIME before sample 1000 */
    }
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.dropped, 300);
    assert_int_equal(tot.lost_total, 300);
    free(s);
}

/* Regression test for "stale BOARD_TIME anchor after a loss" (open). 50 samples are lost around a
 * second boundary whose BOARD_TIME arrives. sf_stream_time_resolve then predicts the next sample's
 * time as that BOARD_TIME (new clock generation) although the sample comes 200 ms later; 200 > 128,
 * so the t_lo snap lands 256 ms early, and every sample up to the next BOARD_TIME is 256 ms off.
 * Δseq = 51 < 256 made the time recoverable (the header promises exactness for gaps up to 255
 * samples). Any outage that takes the sample right after a BOARD_TIME and the next 12+ samples
 * triggers it. */
static void test_50_lost_across_a_received_board_time(void **state)
{
    (void)state;
    scenario_t *const s = new_scenario(50000, 400);
    lose(s, 170, 50, false); /* 170..219; BOARD_TIME before 200 arrives; next sample 220 */
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.dropped, 50);
    assert_int_equal(tot.lost_total, 50);
    free(s);
}

static void test_5_lost_across_a_received_board_time(void **state)
{
    (void)state;
    scenario_t *const s = new_scenario(50000, 400);
    lose(s, 198, 5, false); /* 198..202: the sample after is 30 ms after the BOARD_TIME */
    lose(s, 300, 1, false); /* exactly the sample that follows a BOARD_TIME */
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.dropped, 6);
    assert_int_equal(tot.lost_total, 6);
    free(s);
}

static void test_32bit_board_time_wrap(void **state)
{
    (void)state;
    /* The board clock wraps at 2^32 ms (49.7 days) 3 s into the run: times keep increasing. */
    const int64_t t0 = 4294967296LL - 3000;
    scenario_t *const s = new_scenario(t0, 1000);
    lose(s, 295, 10, true); /* across the wrap, BOARD_TIME lost too */
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.lost_total, 10);

    sf_board_clock_t clock;
    sf_board_clock_init(&clock);
    sf_board_clock_on_time(&clock, (uint32_t)t0, 1, HOST_US(t0));
    assert_int_equal(clock.board_ms, t0);
    sf_board_clock_on_time(&clock, 1000, 1, HOST_US(4294967296LL + 1000)); /* 2^32 + 1000 */
    assert_int_equal(clock.board_ms, 4294967296LL + 1000);
    int64_t t_ms = 0;
    assert_int_equal(sf_board_clock_unwrap(&clock, 4294967000u, &t_ms), SF_OK);
    assert_int_equal(t_ms, 4294967000LL); /* just before the wrap */
    assert_int_equal(sf_board_clock_unwrap(&clock, 5000, &t_ms), SF_OK);
    assert_int_equal(t_ms, 4294967296LL + 5000);
    free(s);
}

static void test_duplicate_seq(void **state)
{
    (void)state;
    sf_board_clock_t clock;
    sf_stream_time_t st;
    sf_board_clock_init(&clock);
    sf_stream_time_init(&st, PERIOD_MS);
    sf_board_clock_on_time(&clock, 1000, 1, HOST_US(1000));
    int64_t t, useq;
    uint32_t lost;
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 5, (uint8_t)1000, HOST_US(1000), &t, &useq, &lost), SF_OK);
    assert_int_equal(t, 1000);
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 5, (uint8_t)1000, HOST_US(1000), &t, &useq, &lost), SF_EDUPLICATE);
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 6, (uint8_t)1010, HOST_US(1010), &t, &useq, &lost), SF_OK);
    assert_int_equal(t, 1010);
    assert_int_equal(useq, 6);
    assert_int_equal(lost, 0);
}

static void test_not_synced_before_first_board_time(void **state)
{
    (void)state;
    sf_board_clock_t clock;
    sf_stream_time_t st;
    sf_board_clock_init(&clock);
    sf_stream_time_init(&st, PERIOD_MS);
    int64_t t = -1, useq = -1;
    uint32_t lost = 0;
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 0, 0, 0, &t, &useq, &lost), SF_ENOTSYNC);
    assert_int_equal(sf_board_clock_unwrap(&clock, 1234, &t), SF_ENOTSYNC);
    sf_board_clock_on_time(&clock, 20000, 3, HOST_US(20000));
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 1, (uint8_t)20005, HOST_US(20005), &t, &useq, &lost), SF_OK);
    assert_int_equal(t, 20005);
}

/* 100 Hz samples k = from..to-1 of a stream starting at t0_ms (seq = k mod 256), each checked to
 * resolve at board time t0 + 10 k and output time out0 + 10 k. */
static void stream_exact(sf_stream_time_t *const st, sf_board_clock_t *const clock, const int64_t t0_ms,
                         const int64_t out0_ms, const int64_t host0_ms, const int from, const int to)
{
    for (int k = from; k < to; k++) {
        const int64_t want = t0_ms + 10 * k;
        int64_t t, useq;
        uint32_t lost;
        const int rc = sf_stream_time_resolve(st, clock, (uint8_t)k, (uint8_t)want, HOST_US(host0_ms + 10 * k), &t,
                                              &useq, &lost);
        if (rc != SF_OK || t != want || t + clock->offset_ms != out0_ms + 10 * k) {
            fail_msg("sample %d: rc %d, time %lld (want %lld), output %lld (want %lld)", k, rc, (long long)t,
                     (long long)want, (long long)(t + clock->offset_ms), (long long)(out0_ms + 10 * k));
        }
    }
}

/* A clock synced at t0_ms (boot id boot) and a 100 Hz stream from t0 with its first n samples exact
 * (board time = output time = host time). */
static void start_stream(sf_board_clock_t *const clock, sf_stream_time_t *const st, const int64_t t0_ms,
                         const uint8_t boot, const int n)
{
    sf_board_clock_init(clock);
    sf_stream_time_init(st, PERIOD_MS);
    assert_int_equal(sf_board_clock_on_time(clock, (uint32_t)t0_ms, boot, HOST_US(t0_ms)), sf_board_time_believed);
    stream_exact(st, clock, t0_ms, t0_ms, t0_ms, 0, n);
}

static void test_boot_id_change_restarts_and_reanchors(void **state)
{
    (void)state;
    sf_board_clock_t clock;
    sf_stream_time_t st;
    start_stream(&clock, &st, 3000000, 1, 300); /* last sample at 3 002 990 */
    /* The board restarts 510 ms after its last sample: clock near 0, new boot id, seq from 0. The
     * BOARD_TIME alone is held; the first sample, which restarts its sequence at that time and does not
     * fit the old stream, confirms it. Output time goes on by the host time that passed. */
    assert_int_equal(sf_board_clock_on_time(&clock, 500, 2, HOST_US(3003500)), sf_board_time_held);
    assert_int_equal(clock.restarts, 0);
    stream_exact(&st, &clock, 500, 3003500, 3003500 - 500, 0, 200);
    assert_int_equal(clock.restarts, 1);
    assert_int_equal(clock.boot_id, 2);
    assert_int_equal(clock.time_rejected, 0);
    /* The same boot id again is believed and no restart. */
    assert_int_equal(sf_board_clock_on_time(&clock, 2500, 2, HOST_US(3005500)), sf_board_time_believed);
    assert_int_equal(clock.restarts, 1);
}

static void test_restart_confirmed_by_the_next_board_time(void **state)
{
    (void)state;
    /* Board time restarts under the same boot id (no sample can tell: same-boot jumps wait for the
     * next BOARD_TIME, which confirms it). Samples in between are not believed. */
    sf_board_clock_t clock;
    sf_stream_time_t st;
    start_stream(&clock, &st, 70000, 4, 100); /* last sample 70 990 at host 70 990 */
    assert_int_equal(sf_board_clock_on_time(&clock, 1000, 4, HOST_US(71000)), sf_board_time_held);
    int rejected = 0;
    for (int k = 0; k < 100; k++) { /* 1 s of samples of the restarted board, before its next BOARD_TIME */
        int64_t t, useq;
        uint32_t lost;
        const int rc = sf_stream_time_resolve(&st, &clock, (uint8_t)k, (uint8_t)(1000 + 10 * k),
                                              HOST_US(71000 + 10 * k), &t, &useq, &lost);
        rejected += rc != SF_OK;
        assert_true(rc == SF_OK || rc == SF_ESEQ || rc == SF_ELATE || rc == SF_EDUPLICATE);
    }
    assert_true(rejected > 0);
    assert_int_equal(sf_board_clock_on_time(&clock, 2000, 4, HOST_US(72000)), sf_board_time_restart);
    assert_int_equal(clock.restarts, 1);
    assert_int_equal(clock.board_ms, 2000);
    stream_exact(&st, &clock, 1000, 71000, 71000, 100, 300); /* board 1000 = output 71 000 */
}

static void test_corrupt_board_time_is_not_believed(void **state)
{
    (void)state;
    /* One BOARD_TIME with a flipped bit (time bit 30), and one with a flipped boot id bit: neither
     * moves the stream; both are counted when the next good BOARD_TIME contradicts them. */
    sf_board_clock_t clock;
    sf_stream_time_t st;
    start_stream(&clock, &st, 50000, 9, 100);
    assert_int_equal(sf_board_clock_on_time(&clock, 51000u ^ (1u << 30), 9, HOST_US(51000)), sf_board_time_held);
    stream_exact(&st, &clock, 50000, 50000, 50000, 100, 200);
    assert_int_equal(sf_board_clock_on_time(&clock, 52000, 9, HOST_US(52000)), sf_board_time_believed);
    assert_int_equal(clock.time_rejected, 1);
    assert_int_equal(sf_board_clock_on_time(&clock, 53000, 9 ^ 4, HOST_US(53000)), sf_board_time_held);
    stream_exact(&st, &clock, 50000, 50000, 50000, 200, 300); /* seq 44.. go on: they fit the old stream */
    assert_int_equal(sf_board_clock_on_time(&clock, 53000, 9, HOST_US(53000)), sf_board_time_believed);
    assert_int_equal(clock.time_rejected, 2);
    assert_int_equal(clock.restarts, 0);
    stream_exact(&st, &clock, 50000, 50000, 50000, 300, 400);
}

static void test_late_and_corrupt_seq_are_skipped(void **state)
{
    (void)state;
    sf_board_clock_t clock;
    sf_stream_time_t st;
    start_stream(&clock, &st, 50000, 9, 50);
    int64_t t, useq;
    uint32_t lost;
    /* sample 51 before 50 (reordered): 51 is taken, 50 arrives late */
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 51, (uint8_t)50510, HOST_US(50510), &t, &useq, &lost), SF_OK);
    assert_int_equal(t, 50510);
    assert_int_equal(lost, 1);
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 50, (uint8_t)50500, HOST_US(50511), &t, &useq, &lost),
                     SF_ELATE);
    /* sample 52 with a flipped seq bit (52 ^ 64 = 116): 64 samples in 10 ms cannot be */
    assert_int_equal(sf_stream_time_resolve(&st, &clock, 52 ^ 64, (uint8_t)50520, HOST_US(50520), &t, &useq, &lost),
                     SF_ESEQ);
    stream_exact(&st, &clock, 50000, 50000, 50000, 53, 300);
}

static void test_outage_longer_than_the_seq_wrap_is_exact_by_host_time(void **state)
{
    (void)state;
    /* 300 samples and every BOARD_TIME among them lost (Δseq = 44 mod 256): the host time that
     * passed (3 s) tells 300 from 44, so the samples before the next BOARD_TIME are exact too. */
    scenario_t *const s = new_scenario(50000, 1500);
    lose(s, 650, 300, true);
    const totals_t tot = run_direct(s);
    assert_int_equal(tot.dropped, 300);
    assert_int_equal(tot.lost_total, 300);
    free(s);
}

/* ---- through sf_board_rx_frame, IMU_ACCEL + IMU_GYRO pairs ---- */

static void test_rx_imu_pairs_times_and_counters(void **state)
{
    (void)state;
    const int64_t t0 = 4294967296LL - 3000; /* through the 32-bit wrap too */
    const int n = 1200;
    sf_board_rx_t *const rx = malloc(sizeof *rx);
    assert_non_null(rx);
    sf_board_rx_init(rx);
    sf_rx_event_t ev;
    int emitted = 0;
    int64_t last_t_us = INT64_MIN;
    for (int k = 0; k < n; k++) {
        const int64_t t = t0 + 10LL * k;
        if (k % 100 == 0) {
            const sf_can_frame_t bt = tf_board_time((uint32_t)t, 9);
            assert_int_equal(sf_board_rx_frame(rx, &bt, &ev), 0);
        }
        if (k >= 500 && k < 505) {
            continue; /* both halves of 5 samples lost */
        }
        const sf_can_frame_t a = tf_accel((uint8_t)k, (uint8_t)t, 0.1, -0.2, 9.81);
        assert_int_equal(sf_board_rx_frame(rx, &a, &ev), 0);
        if (k == 700) {
            continue; /* the gyro half of sample 700 is lost: no sample 700 */
        }
        const sf_can_frame_t g = tf_gyro((uint8_t)k, (uint8_t)t, 0.0, 0.0, 5.7295779513);
        assert_int_equal(sf_board_rx_frame(rx, &g, &ev), 1);
        assert_int_equal(ev.kind, sf_rx_imu);
        assert_int_equal(ev.u.imu.t_us, t * 1000);
        assert_int_equal(ev.u.imu.seq, k);
        assert_true(ev.u.imu.t_us > last_t_us);
        /* 0.1 rad/s to half a gyro step (0.0305 deg/s = 0.00053 rad/s) */
        assert_true(ev.u.imu.gyro_radps[2] > 0.1 - 0.00054 && ev.u.imu.gyro_radps[2] < 0.1 + 0.00054);
        last_t_us = ev.u.imu.t_us;
        emitted++;
    }
    assert_int_equal(emitted, n - 6);
    assert_int_equal(rx->counters.imu, n - 6);
    assert_int_equal(rx->counters.imu_unpaired, 1);
    assert_int_equal(rx->counters.seq_gaps, 6); /* 5 lost pairs + the unpaired sample */
    assert_int_equal(rx->counters.frames, 12 + 2 * (n - 5) - 1);
    assert_int_equal(rx->counters.frames_ok, rx->counters.frames);
    assert_int_equal(rx->counters.duplicates, 0);
    assert_int_equal(rx->counters.unsynced, 0);
    assert_true(last_t_us > 4294967296LL * 1000); /* past the 32-bit wrap */
    free(rx);
}

static void test_rx_unsynced_duplicate_and_restart(void **state)
{
    (void)state;
    sf_board_rx_t *const rx = malloc(sizeof *rx);
    assert_non_null(rx);
    sf_board_rx_init(rx);
    sf_rx_event_t ev;
    sf_can_frame_t a = tf_accel(1, 10, 0, 0, 9.81);
    sf_can_frame_t g = tf_gyro(1, 10, 0, 0, 0);
    assert_int_equal(sf_board_rx_frame(rx, &a, &ev), 0);
    assert_int_equal(sf_board_rx_frame(rx, &g, &ev), SF_ENOTSYNC);
    assert_int_equal(rx->counters.unsynced, 1);
    assert_int_equal(rx->counters.imu, 0);

    sf_can_frame_t bt = tf_board_time(1000, 1);
    assert_int_equal(sf_board_rx_frame(rx, &bt, &ev), 0);
    a = tf_accel(2, (uint8_t)1000, 0, 0, 9.81);
    g = tf_gyro(2, (uint8_t)1000, 0, 0, 0);
    assert_int_equal(sf_board_rx_frame(rx, &a, &ev), 0);
    assert_int_equal(sf_board_rx_frame(rx, &g, &ev), 1);
    assert_int_equal(ev.u.imu.t_us, 1000000);
    /* the same sample again (the bus repeated both frames) */
    assert_int_equal(sf_board_rx_frame(rx, &a, &ev), SF_EDUPLICATE);
    assert_int_equal(sf_board_rx_frame(rx, &g, &ev), SF_EDUPLICATE);
    assert_int_equal(rx->counters.duplicates, 2);
    assert_int_equal(rx->counters.imu_unpaired, 0);

    /* the board restarts mid-sample: the accel half waiting is dropped with the old boot; the new
     * boot's first sample confirms the restart and goes on in output time */
    a = tf_accel(3, (uint8_t)1010, 0, 0, 9.81);
    assert_int_equal(sf_board_rx_frame(rx, &a, &ev), 0);
    bt = tf_board_time(200, 2);
    assert_int_equal(sf_board_rx_frame(rx, &bt, &ev), 0);
    assert_int_equal(rx->counters.board_restarts, 0); /* held: one frame is not believed */
    a = tf_accel(0, 200, 0, 0, 9.81);
    g = tf_gyro(0, 200, 0, 0, 0);
    assert_int_equal(sf_board_rx_frame(rx, &a, &ev), 0);
    assert_int_equal(sf_board_rx_frame(rx, &g, &ev), 1);
    assert_int_equal(rx->counters.board_restarts, 1);
    assert_true(ev.u.imu.t_us > 1000000); /* after the old boot's last sample, not back at 200 ms */
    assert_int_equal(ev.u.imu.seq, 0);
    free(rx);
}

static void test_rx_swapped_halves_still_pair(void **state)
{
    (void)state;
    sf_board_rx_t *const rx = malloc(sizeof *rx);
    assert_non_null(rx);
    sf_board_rx_init(rx);
    sf_rx_event_t ev;
    const sf_can_frame_t bt = tf_board_time(5000, 1);
    assert_int_equal(sf_board_rx_frame(rx, &bt, &ev), 0);
    /* ACCEL 0, ACCEL 1, GYRO 0, GYRO 1: the bus swapped GYRO 0 and ACCEL 1 */
    sf_can_frame_t f = tf_accel(0, (uint8_t)5000, 0, 0, 9.81);
    assert_int_equal(sf_board_rx_frame(rx, &f, &ev), 0);
    f = tf_accel(1, (uint8_t)5010, 0, 0, 9.81);
    assert_int_equal(sf_board_rx_frame(rx, &f, &ev), 0);
    f = tf_gyro(0, (uint8_t)5000, 0, 0, 0);
    assert_int_equal(sf_board_rx_frame(rx, &f, &ev), 1);
    assert_int_equal(ev.u.imu.t_us, 5000000);
    f = tf_gyro(1, (uint8_t)5010, 0, 0, 0);
    assert_int_equal(sf_board_rx_frame(rx, &f, &ev), 1);
    assert_int_equal(ev.u.imu.t_us, 5010000);
    assert_int_equal(rx->counters.imu_unpaired, 0);
    free(rx);
}

static void test_corrupt_t_lo_of_a_locked_stream_is_skipped(void **state)
{
    (void)state;
    sf_board_clock_t clock;
    sf_stream_time_t st;
    start_stream(&clock, &st, 50000, 9, 50);
    int64_t t, useq;
    uint32_t lost;
    /* sample 50 at 50 500 ms with t_lo bit 6 flipped: 64 ms off the prediction, inside ±128 ms */
    assert_int_equal(
        sf_stream_time_resolve(&st, &clock, 50, (uint8_t)(50500 ^ 64), HOST_US(50500), &t, &useq, &lost), SF_ESEQ);
    stream_exact(&st, &clock, 50000, 50000, 50000, 51, 200);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_100hz_12s_exact_through_seq_and_t_lo_wraps),
        cmocka_unit_test(test_single_and_burst_losses_without_board_time),
        cmocka_unit_test(test_300_lost_with_board_time_received),
        cmocka_unit_test(test_300_lost_without_board_time),
        cmocka_unit_test(test_50_lost_across_a_received_board_time),
        cmocka_unit_test(test_5_lost_across_a_received_board_time),
        cmocka_unit_test(test_32bit_board_time_wrap),
        cmocka_unit_test(test_duplicate_seq),
        cmocka_unit_test(test_not_synced_before_first_board_time),
        cmocka_unit_test(test_boot_id_change_restarts_and_reanchors),
        cmocka_unit_test(test_restart_confirmed_by_the_next_board_time),
        cmocka_unit_test(test_corrupt_board_time_is_not_believed),
        cmocka_unit_test(test_late_and_corrupt_seq_are_skipped),
        cmocka_unit_test(test_outage_longer_than_the_seq_wrap_is_exact_by_host_time),
        cmocka_unit_test(test_rx_imu_pairs_times_and_counters),
        cmocka_unit_test(test_rx_unsynced_duplicate_and_restart),
        cmocka_unit_test(test_rx_swapped_halves_still_pair),
        cmocka_unit_test(test_corrupt_t_lo_of_a_locked_stream_is_skipped),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
