/* test_board_time_stuck.c — a BOARD_TIME that stops advancing while the samples go on
 * (sf_board_time.h), through sf_board_rx_frame with frames packed by the generated board_*_pack
 * functions.
 *
 * The story: a board whose BOARD_TIME register froze for 60 s sent the same time_ms every second
 * while its IMU kept sampling at 100 Hz with seq and t_lo advancing. Each frozen value was held (it
 * trails the samples), the next frozen frame agreed with the held one and confirmed it as a board
 * restart (time gone back): 29 false restarts, every stream restarted, samples out of order, and
 * when BOARD_TIME was sane again its forward jump was believed as an outage, leaving every later
 * output time 57 s ahead. A confirming BOARD_TIME must advance with the host time since the held
 * one; a frozen one never does, so it is counted as not believed and the streams keep following
 * their own seq and t_lo.
 *
 * The simulated board: sample k at board time T0 + 10 k ms, seq k mod 256, t_lo = time mod 256,
 * received 300 µs after it is sent (host time = board time + a fixed offset); a BOARD_TIME before
 * every sample at a whole second. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdlib.h>

#include "sf_board_rx.h"
#include "sf_board_time.h"
#include "sf_error.h"
#include "sf_test_frames.h"

#define T0_MS 1000000LL
#define HOST_US(t_ms) (1700000000000000LL + (int64_t)(t_ms) * 1000 + 300)

typedef struct {
    sf_board_rx_t *rx;
    int64_t base_ms;   /* board time of sample 0 of the current boot */
    int64_t host0_ms;  /* host ms (minus the fixed offset) of sample 0 of the current boot */
    uint8_t boot;
    int64_t out0_us;   /* expected output time of sample 0 of the current boot */
    int64_t last_t_us; /* output time of the last sample */
    int64_t worst_off_us; /* largest |output − expected| of a sample */
    int out_of_order;  /* samples whose output time was not after the previous one */
    int samples;
} board_t;

static void send(board_t *const b, sf_can_frame_t f, const int64_t host_ms, sf_rx_event_t *const ev, const int want)
{
    f.host_t_us = HOST_US(host_ms);
    assert_int_equal(sf_board_rx_frame(b->rx, &f, ev), want);
}

/* Samples k = from..to-1 of the current boot; BOARD_TIME before every whole second, carrying
 * frozen_ms instead of the board time for samples k in [stuck_from, stuck_to). */
static void run(board_t *const b, const int from, const int to, const int stuck_from, const int stuck_to,
                const uint32_t frozen_ms)
{
    sf_rx_event_t ev;
    for (int k = from; k < to; k++) {
        const int64_t t = b->base_ms + 10LL * k;
        const int64_t host = b->host0_ms + 10LL * k;
        if (k % 100 == 0) {
            const bool stuck = k >= stuck_from && k < stuck_to;
            send(b, tf_board_time(stuck ? frozen_ms : (uint32_t)t, b->boot), host, &ev, 0);
        }
        send(b, tf_accel((uint8_t)k, (uint8_t)t, 0.1, -0.2, 9.81), host, &ev, 0);
        send(b, tf_gyro((uint8_t)k, (uint8_t)t, 0.0, 0.0, 1.0), host, &ev, 1);
        assert_int_equal(ev.kind, sf_rx_imu);
        const int64_t want_us = b->out0_us + 10000LL * k;
        const int64_t off = llabs(ev.u.imu.t_us - want_us);
        b->worst_off_us = off > b->worst_off_us ? off : b->worst_off_us;
        b->out_of_order += ev.u.imu.t_us <= b->last_t_us;
        b->last_t_us = ev.u.imu.t_us;
        b->samples++;
    }
}

static board_t *new_board(void)
{
    board_t *const b = calloc(1, sizeof *b);
    assert_non_null(b);
    b->rx = malloc(sizeof *b->rx);
    assert_non_null(b->rx);
    sf_board_rx_init(b->rx);
    b->base_ms = T0_MS;
    b->host0_ms = T0_MS;
    b->boot = 7;
    b->out0_us = T0_MS * 1000;
    b->last_t_us = INT64_MIN;
    return b;
}

static void free_board(board_t *const b)
{
    free(b->rx);
    free(b);
}

static void test_board_time_stuck_60s_is_not_believed(void **state)
{
    (void)state;
    /* GIVEN 30 s of a sane board, WHEN BOARD_TIME repeats its 30 s value for 60 s while the samples
     * go on, THEN no restart is believed, every frozen frame after the first is counted as not
     * believed, and every sample keeps its true time (0 out of order, 0 ms off), also after. */
    board_t *const b = new_board();
    run(b, 0, 12000, 3000, 9000, (uint32_t)(T0_MS + 30000));
    const sf_rx_counters_t *const c = &b->rx->counters;
    assert_int_equal(c->board_restarts, 0);
    assert_int_equal(c->board_time_jumps, 0);
    assert_int_equal(c->board_time_rejected, 59); /* 31 s .. 89 s; the one at 30 s was true */
    assert_int_equal(c->seq_gaps, 0);
    assert_int_equal(b->out_of_order, 0);
    assert_int_equal(b->samples, 12000);
    assert_true(b->worst_off_us < 10000);
    assert_int_equal(b->last_t_us, (T0_MS + 119990) * 1000); /* final offset 0 */
    free_board(b);
}

static void test_board_time_stuck_repeating_an_older_value(void **state)
{
    (void)state;
    /* The frozen value is 5 s old already at the first frozen frame (a register that stopped
     * updating before the fault showed): held and never confirmed alike. */
    board_t *const b = new_board();
    run(b, 0, 12000, 3000, 9000, (uint32_t)(T0_MS + 25000));
    assert_int_equal(b->rx->counters.board_restarts, 0);
    assert_int_equal(b->rx->counters.board_time_rejected, 60);
    assert_int_equal(b->out_of_order, 0);
    assert_true(b->worst_off_us < 10000);
    free_board(b);
}

static void test_real_restart_after_a_stuck_board_time_is_believed(void **state)
{
    (void)state;
    /* GIVEN a board whose BOARD_TIME was stuck for 60 s and then sane again for 10 s, WHEN it
     * restarts (new boot id, board time and seq from 0, 500 ms down), THEN the restart is believed
     * once, and output time goes on from the last output time plus the host time that passed. */
    board_t *const b = new_board();
    run(b, 0, 10000, 3000, 9000, (uint32_t)(T0_MS + 30000));
    assert_int_equal(b->rx->counters.board_restarts, 0);
    const int64_t down_ms = 500;
    b->host0_ms = T0_MS + 99990 + down_ms; /* host ms of the new boot's sample 0 */
    b->base_ms = 0;
    b->boot = 8;
    b->out0_us = (T0_MS + 99990 + down_ms) * 1000;
    run(b, 0, 3000, 0, 0, 0);
    assert_int_equal(b->rx->counters.board_restarts, 1);
    assert_int_equal(b->out_of_order, 0);
    assert_true(b->worst_off_us < 10000);
    free_board(b);
}

static void test_same_boot_restart_is_still_confirmed_by_an_advancing_board_time(void **state)
{
    (void)state;
    /* Board time restarts under the same boot id: the next BOARD_TIME, one second later and one
     * second on, confirms it; a second BOARD_TIME with the held value does not. */
    sf_board_clock_t clock;
    sf_board_clock_init(&clock);
    assert_int_equal(sf_board_clock_on_time(&clock, 70000, 4, HOST_US(70000)), sf_board_time_believed);
    assert_int_equal(sf_board_clock_on_time(&clock, 71000, 4, HOST_US(71000)), sf_board_time_believed);
    assert_int_equal(sf_board_clock_on_time(&clock, 1000, 4, HOST_US(72000)), sf_board_time_held);
    assert_int_equal(sf_board_clock_on_time(&clock, 1000, 4, HOST_US(73000)), sf_board_time_held);
    assert_int_equal(clock.restarts, 0);
    assert_int_equal(clock.time_rejected, 1);
    assert_int_equal(sf_board_clock_on_time(&clock, 2000, 4, HOST_US(74000)), sf_board_time_restart);
    assert_int_equal(clock.restarts, 1);
    assert_int_equal(clock.board_ms, 2000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_board_time_stuck_60s_is_not_believed),
        cmocka_unit_test(test_board_time_stuck_repeating_an_older_value),
        cmocka_unit_test(test_real_restart_after_a_stuck_board_time_is_believed),
        cmocka_unit_test(test_same_boot_restart_is_still_confirmed_by_an_advancing_board_time),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
