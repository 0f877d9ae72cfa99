/* test_board_ble.c — sf_board_rx on BLE_ADV and LANDMARK frames: advertisements grouped into one BLE
 * scan per ble.window_ms window (the mean in dBm per beacon), closed by an advertisement past the
 * window or a BOARD_TIME past it, never by host time alone; repeated, late, corrupt and surplus
 * advertisements counted and skipped; the open window handed back at the end; a window across a
 * board restart; LANDMARK decoded to the DBC's resolution with landmark.accuracy_m. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sf_board_rx.h"
#include "sf_error.h"
#include "sf_params.h"
#include "sf_test_frames.h"

#define T0_MS 10000u
#define HOST0_US 1700000000000000LL
#define BEACON_A 0xE078A33DB49CULL
#define BEACON_B 0xE078A33DB573ULL

typedef struct {
    sf_board_rx_t rx;
    sf_params_t p;
    int64_t host_us; /* host receive time of the next frame */
} fixture_t;

/* Frames are received as if sent at board time: host time = HOST0_US + (board ms - T0_MS). */
static int64_t host_at(const uint32_t board_ms)
{
    return HOST0_US + ((int64_t)board_ms - (int64_t)T0_MS) * 1000;
}

static int feed_at(fixture_t *const fx, sf_can_frame_t f, const uint32_t board_ms, sf_rx_event_t *const ev)
{
    f.host_t_us = host_at(board_ms);
    return sf_board_rx_frame(&fx->rx, &f, ev);
}

static int adv_at(fixture_t *const fx, const uint64_t beacon, const int8_t rssi, const uint32_t board_ms,
                  sf_rx_event_t *const ev)
{
    return feed_at(fx, tf_ble_adv(beacon, rssi, (uint8_t)(board_ms & 0xFFu)), board_ms, ev);
}

/* A receiver with the params table's defaults that has seen BOARD_TIME(T0_MS). */
static int setup(void **state)
{
    fixture_t *const fx = calloc(1, sizeof *fx);
    if (fx == NULL) {
        return -1;
    }
    sf_params_default(&fx->p);
    sf_board_rx_init(&fx->rx);
    sf_board_rx_configure(&fx->rx, &fx->p);
    sf_rx_event_t ev;
    if (feed_at(fx, tf_board_time(T0_MS, 1), T0_MS, &ev) != 0) {
        free(fx);
        return -1;
    }
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    free(*state);
    return 0;
}

/* GIVEN advertisements of two beacons within one window, WHEN one past the window arrives, THEN the
 * window comes out with each beacon once at its mean level, timed at its first advertisement, and
 * the late one opens the next window. */
static void test_window_groups_and_averages(void **state)
{
    fixture_t *const fx = *state;
    const uint32_t w = (uint32_t)fx->p.ble_window_ms;
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 100, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_B, -90, T0_MS + 150, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_A, -75, T0_MS + 400, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_A, -80, T0_MS + 99 + w, &ev), 0); /* 1 ms before the end */
    assert_int_equal(adv_at(fx, BEACON_B, -60, T0_MS + 100 + w, &ev), 1); /* the first past it */
    assert_int_equal(ev.kind, sf_rx_ble);
    assert_int_equal(ev.u.ble.t_us, (int64_t)(T0_MS + 100) * 1000);
    assert_int_equal(ev.u.ble.n, 2);
    assert_int_equal(ev.u.ble.beacon_id[0], (int64_t)BEACON_A);
    assert_float_equal(ev.u.ble.rssi_dbm[0], -75.0, 1e-5); /* (-70 - 75 - 80) / 3 */
    assert_int_equal(ev.u.ble.beacon_id[1], (int64_t)BEACON_B);
    assert_float_equal(ev.u.ble.rssi_dbm[1], -90.0, 1e-5);
    assert_int_equal(fx->rx.counters.ble, 1);
    assert_int_equal(fx->rx.counters.ble_adverts, 5);
    /* the next window holds B at -60 from T0 + 100 + w */
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 1);
    assert_int_equal(ev.u.ble.t_us, (int64_t)(T0_MS + 100 + w) * 1000);
    assert_int_equal(ev.u.ble.n, 1);
    assert_float_equal(ev.u.ble.rssi_dbm[0], -60.0, 1e-5);
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 0); /* nothing left */
    assert_int_equal(ev.kind, sf_rx_none);
    assert_int_equal(fx->rx.counters.ble, 2);
}

/* The window follows ble.window_ms from the params table. */
static void test_window_length_is_the_parameter(void **state)
{
    fixture_t *const fx = *state;
    fx->p.ble_window_ms = 250;
    sf_board_rx_configure(&fx->rx, &fx->p);
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 10, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_A, -72, T0_MS + 259, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_A, -74, T0_MS + 260, &ev), 1);
    assert_int_equal(ev.u.ble.n, 1);
    assert_float_equal(ev.u.ble.rssi_dbm[0], -71.0, 1e-5);
}

/* A BOARD_TIME past the window closes it; one inside it, or a held (disbelieved) one, does not. Host
 * time passing without frames closes nothing. */
static void test_board_time_closes_the_window(void **state)
{
    fixture_t *const fx = *state;
    const uint32_t w = (uint32_t)fx->p.ble_window_ms;
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 500, &ev), 0);
    assert_int_equal(feed_at(fx, tf_board_time(T0_MS + 1000, 1), T0_MS + 1000, &ev), 0); /* inside */
    /* a BOARD_TIME of another boot id is held, not believed: no close */
    assert_int_equal(feed_at(fx, tf_board_time(T0_MS + 1600, 7), T0_MS + 1600, &ev), 0);
    assert_int_equal(fx->rx.counters.ble, 0);
    assert_int_equal(feed_at(fx, tf_board_time(T0_MS + 500 + w, 1), T0_MS + 500 + w, &ev), 1);
    assert_int_equal(ev.kind, sf_rx_ble);
    assert_int_equal(ev.u.ble.t_us, (int64_t)(T0_MS + 500) * 1000);
    assert_int_equal(fx->rx.counters.ble, 1);
    /* an advertisement from before the closed window's end arrived late */
    assert_int_equal(adv_at(fx, BEACON_B, -80, T0_MS + 499 + w, &ev), SF_ELATE);
    assert_int_equal(fx->rx.counters.late, 1);
}

/* The bus repeating one advertisement (same beacon, same millisecond) is a duplicate, not averaged. */
static void test_repeated_advertisement_is_a_duplicate(void **state)
{
    fixture_t *const fx = *state;
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 100, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 100, &ev), SF_EDUPLICATE);
    assert_int_equal(adv_at(fx, BEACON_A, -90, T0_MS + 200, &ev), 0);
    assert_int_equal(fx->rx.counters.duplicates, 1);
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 1);
    assert_float_equal(ev.u.ble.rssi_dbm[0], -80.0, 1e-5); /* -70 once, -90 once */
    assert_int_equal(fx->rx.counters.ble_adverts, 2);
}

/* An advertisement before the open window's start (reordered) is late; a corrupt one (MAC 0, or a
 * level at or above 0 dBm) a decode error; one before the first BOARD_TIME unsynced. */
static void test_late_corrupt_and_unsynced(void **state)
{
    fixture_t *const fx = *state;
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 300, &ev), 0);
    assert_int_equal(adv_at(fx, BEACON_B, -70, T0_MS + 290, &ev), SF_ELATE);
    assert_int_equal(adv_at(fx, 0, -70, T0_MS + 310, &ev), SF_ERANGE);
    assert_int_equal(adv_at(fx, BEACON_B, 0, T0_MS + 320, &ev), SF_ERANGE);
    assert_int_equal(adv_at(fx, BEACON_B, 5, T0_MS + 330, &ev), SF_ERANGE);
    assert_int_equal(fx->rx.counters.late, 1);
    assert_int_equal(fx->rx.counters.decode_errors, 3);
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 1);
    assert_int_equal(ev.u.ble.n, 1);

    sf_board_rx_t *const fresh = malloc(sizeof *fresh);
    assert_non_null(fresh);
    sf_board_rx_init(fresh);
    sf_can_frame_t f = tf_ble_adv(BEACON_A, -70, 5);
    assert_int_equal(sf_board_rx_frame(fresh, &f, &ev), SF_ENOTSYNC);
    f = tf_landmark(1.0, 2.0, 0, 5);
    assert_int_equal(sf_board_rx_frame(fresh, &f, &ev), SF_ENOTSYNC);
    assert_int_equal(fresh->counters.unsynced, 2);
    free(fresh);
}

/* More distinct beacons than SF_BLE_MAX_BEACONS in one window: the surplus is counted and dropped,
 * the beacons already in it are still averaged. */
static void test_full_window_drops_and_counts(void **state)
{
    fixture_t *const fx = *state;
    sf_rx_event_t ev;
    for (uint32_t i = 0; i < SF_BLE_MAX_BEACONS + 3; i++) {
        const int want = i < SF_BLE_MAX_BEACONS ? 0 : SF_EFULL;
        assert_int_equal(adv_at(fx, BEACON_A + i, -60, T0_MS + 10 + 10 * i, &ev), want);
    }
    assert_int_equal(adv_at(fx, BEACON_A, -80, T0_MS + 900, &ev), 0);
    assert_int_equal(fx->rx.counters.ble_dropped, 3);
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 1);
    assert_int_equal(ev.u.ble.n, SF_BLE_MAX_BEACONS);
    assert_float_equal(ev.u.ble.rssi_dbm[0], -70.0, 1e-5);
}

/* t_lo_ms is resolved against the clock: 300 ms after a BOARD_TIME (past a t_lo wrap) the frame's
 * full time is found again. */
static void test_time_from_t_lo_past_the_wrap(void **state)
{
    fixture_t *const fx = *state;
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 300, &ev), 0);
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 1);
    assert_int_equal(ev.u.ble.t_us, (int64_t)(T0_MS + 300) * 1000);
}

/* A board restart between two advertisements: output time goes on across it (sf_board_time.h), so
 * the window is judged in output time and still closes by the later advertisement. */
static void test_window_across_a_board_restart(void **state)
{
    fixture_t *const fx = *state;
    sf_rx_event_t ev;
    assert_int_equal(adv_at(fx, BEACON_A, -70, T0_MS + 100, &ev), 0);
    /* the board restarts: boot 2 at time 50, confirmed by a second BOARD_TIME */
    sf_can_frame_t bt = tf_board_time(50, 2);
    bt.host_t_us = host_at(T0_MS + 600);
    assert_int_equal(sf_board_rx_frame(&fx->rx, &bt, &ev), 0);
    bt = tf_board_time(1050, 2);
    bt.host_t_us = host_at(T0_MS + 1600);
    assert_int_equal(sf_board_rx_frame(&fx->rx, &bt, &ev), 1); /* 1.5 s after the first advertisement */
    assert_int_equal(fx->rx.counters.board_restarts, 1);
    assert_int_equal(ev.kind, sf_rx_ble);
    assert_int_equal(ev.u.ble.t_us, (int64_t)(T0_MS + 100) * 1000);
    sf_can_frame_t adv = tf_ble_adv(BEACON_B, -65, (uint8_t)(1060 & 0xFF));
    adv.host_t_us = host_at(T0_MS + 1610);
    assert_int_equal(sf_board_rx_frame(&fx->rx, &adv, &ev), 0);
    assert_int_equal(sf_board_rx_flush(&fx->rx, &ev), 1);
    assert_true(ev.u.ble.t_us > (int64_t)(T0_MS + 1100) * 1000); /* after the old window, in output time */
}

/* LANDMARK: x and y to the DBC's 0.01 m (negative too), floor as sent, accuracy landmark.accuracy_m,
 * id 0 (the frame has none), time from t_lo. */
static void test_landmark_event(void **state)
{
    fixture_t *const fx = *state;
    fx->p.landmark_accuracy_m = 0.5;
    sf_board_rx_configure(&fx->rx, &fx->p);
    sf_rx_event_t ev;
    assert_int_equal(feed_at(fx, tf_landmark(-1234.56, 78.9, -2, (uint8_t)((T0_MS + 40) & 0xFF)), T0_MS + 41, &ev),
                     1);
    assert_int_equal(ev.kind, sf_rx_landmark);
    assert_int_equal(ev.u.landmark.t_us, (int64_t)(T0_MS + 40) * 1000);
    assert_float_equal(ev.u.landmark.x_m, -1234.56, 1e-9);
    assert_float_equal(ev.u.landmark.y_m, 78.9, 1e-9);
    assert_int_equal(ev.u.landmark.floor, -2);
    assert_int_equal(ev.u.landmark.landmark_id, 0);
    assert_float_equal(ev.u.landmark.accuracy_m, 0.5, 1e-6);
    assert_int_equal(fx->rx.counters.landmark, 1);
    sf_can_frame_t shortf = tf_landmark(1.0, 1.0, 0, 0);
    shortf.dlc = 7;
    assert_int_equal(feed_at(fx, shortf, T0_MS + 50, &ev), SF_ELENGTH);
}

/* The params rows the decoder reads exist with their documented defaults, unit and range. */
static void test_params_rows(void **state)
{
    (void)state;
    const sf_param_desc_t *const w = sf_param_find("ble", "window_ms");
    assert_non_null(w);
    assert_string_equal(w->unit, "ms");
    assert_true(w->default_value == 1000.0 && w->min_value > 0.0);
    const sf_param_desc_t *const a = sf_param_find("landmark", "accuracy_m");
    assert_non_null(a);
    assert_string_equal(a->unit, "m");
    assert_true(a->default_value == 0.3 && a->min_value > 0.0);
}

int main(void)
{
#define FX_TEST(fn) cmocka_unit_test_setup_teardown(fn, setup, teardown)
    const struct CMUnitTest tests[] = {
        FX_TEST(test_window_groups_and_averages),
        FX_TEST(test_window_length_is_the_parameter),
        FX_TEST(test_board_time_closes_the_window),
        FX_TEST(test_repeated_advertisement_is_a_duplicate),
        FX_TEST(test_late_corrupt_and_unsynced),
        FX_TEST(test_full_window_drops_and_counts),
        FX_TEST(test_time_from_t_lo_past_the_wrap),
        FX_TEST(test_window_across_a_board_restart),
        FX_TEST(test_landmark_event),
        cmocka_unit_test(test_params_rows),
    };
#undef FX_TEST
    return cmocka_run_group_tests(tests, NULL, NULL);
}
