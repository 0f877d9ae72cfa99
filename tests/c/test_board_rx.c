/* test_board_rx.c — sf_board_rx_frame beyond timing: Wi-Fi scan reassembly, GNSS pairing, and the
 * frames it must refuse and count (unknown id, short frame, extended or remote frame). */
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
#include "sf_test_frames.h"

#define T0_MS 10000u

/* A receiver that has seen BOARD_TIME(T0_MS); freed by teardown. */
static int setup_rx(void **state)
{
    sf_board_rx_t *const rx = malloc(sizeof *rx);
    if (rx == NULL) {
        return -1;
    }
    sf_board_rx_init(rx);
    sf_rx_event_t ev;
    const sf_can_frame_t bt = tf_board_time(T0_MS, 1);
    if (sf_board_rx_frame(rx, &bt, &ev) != 0) {
        free(rx);
        return -1;
    }
    *state = rx;
    return 0;
}

static int teardown_rx(void **state)
{
    free(*state);
    return 0;
}

/* Feeds one frame and checks the return code. */
static void feed(sf_board_rx_t *const rx, const sf_can_frame_t f, sf_rx_event_t *const ev, const int want)
{
    const int rc = sf_board_rx_frame(rx, &f, ev);
    if (rc != want) {
        fail_msg("frame 0x%03X: got %d (%s), want %d", (unsigned)f.id, rc, sf_strerror(rc), want);
    }
}

static void test_channel_to_mhz(void **state)
{
    (void)state;
    assert_int_equal(sf_wifi_channel_to_mhz(1), 2412);
    assert_int_equal(sf_wifi_channel_to_mhz(6), 2437);
    assert_int_equal(sf_wifi_channel_to_mhz(11), 2462);
    assert_int_equal(sf_wifi_channel_to_mhz(13), 2472);
    assert_int_equal(sf_wifi_channel_to_mhz(14), 2484);
    assert_int_equal(sf_wifi_channel_to_mhz(36), 5180);
    assert_int_equal(sf_wifi_channel_to_mhz(165), 5825);
    assert_int_equal(sf_wifi_channel_to_mhz(0), 0);
    assert_int_equal(sf_wifi_channel_to_mhz(15), 0);
    assert_int_equal(sf_wifi_channel_to_mhz(31), 0);
    assert_int_equal(sf_wifi_channel_to_mhz(178), 0);
    assert_int_equal(sf_wifi_channel_to_mhz(255), 0);
}

static void test_wifi_scan_complete(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    feed(rx, tf_scan_begin(3, T0_MS - 10), &ev, 0);
    feed(rx, tf_scan_ap(0x001122334455u, -40, 1), &ev, 0);
    feed(rx, tf_scan_ap(0xAABBCCDDEEFFu, -67, 6), &ev, 0);
    feed(rx, tf_scan_ap(0x0000000000F1u, -90, 36), &ev, 0);
    assert_int_equal(ev.kind, sf_rx_none);
    feed(rx, tf_scan_end(3, 3), &ev, 1);
    assert_int_equal(ev.kind, sf_rx_wifi);
    const sf_rx_wifi_t *const w = &ev.u.wifi;
    assert_true(w->complete);
    assert_int_equal(w->n_ap, 3);
    assert_int_equal(w->t_us, (int64_t)(T0_MS - 10) * 1000);
    assert_int_equal(w->scan_id, 3);
    assert_int_equal(w->bssid[0], 0x001122334455LL);
    assert_int_equal(w->bssid[1], 0xAABBCCDDEEFFLL);
    assert_int_equal(w->bssid[2], 0xF1);
    assert_true(w->rssi_dbm[0] == -40.0f && w->rssi_dbm[1] == -67.0f && w->rssi_dbm[2] == -90.0f);
    assert_int_equal(w->freq_mhz[0], 2412);
    assert_int_equal(w->freq_mhz[1], 2437);
    assert_int_equal(w->freq_mhz[2], 5180);
    assert_int_equal(rx->counters.wifi, 1);
    assert_int_equal(rx->counters.wifi_incomplete, 0);
    assert_int_equal(rx->counters.decode_errors, 0);

    /* a second scan, channel 11 */
    feed(rx, tf_scan_begin(4, T0_MS + 500), &ev, 0);
    feed(rx, tf_scan_ap(0x1, -50, 11), &ev, 0);
    feed(rx, tf_scan_end(4, 1), &ev, 1);
    assert_int_equal(ev.u.wifi.freq_mhz[0], 2462);
    assert_int_equal(ev.u.wifi.scan_id, 4);
    assert_int_equal(ev.u.wifi.n_ap, 1); /* the previous scan's APs are gone */
    assert_int_equal(rx->counters.wifi, 2);
}

static void test_wifi_lost_ap(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    feed(rx, tf_scan_begin(9, T0_MS), &ev, 0);
    feed(rx, tf_scan_ap(0x10, -40, 1), &ev, 0);
    feed(rx, tf_scan_ap(0x11, -41, 6), &ev, 0); /* the third AP is lost */
    feed(rx, tf_scan_end(9, 3), &ev, 1);
    assert_int_equal(ev.kind, sf_rx_wifi);
    assert_false(ev.u.wifi.complete);
    assert_int_equal(ev.u.wifi.n_ap, 2);
    assert_int_equal(rx->counters.wifi_incomplete, 1);
    assert_int_equal(rx->counters.wifi, 1);
}

static void test_wifi_lost_end_then_new_begin(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    feed(rx, tf_scan_begin(20, T0_MS + 100), &ev, 0);
    feed(rx, tf_scan_ap(0x20, -40, 1), &ev, 0);
    feed(rx, tf_scan_ap(0x21, -41, 6), &ev, 0);
    /* SCAN_END 20 lost: the next BEGIN hands back scan 20, incomplete */
    feed(rx, tf_scan_begin(21, T0_MS + 2100), &ev, 1);
    assert_int_equal(ev.kind, sf_rx_wifi);
    assert_false(ev.u.wifi.complete);
    assert_int_equal(ev.u.wifi.scan_id, 20);
    assert_int_equal(ev.u.wifi.n_ap, 2);
    assert_int_equal(ev.u.wifi.t_us, (int64_t)(T0_MS + 100) * 1000);
    assert_int_equal(rx->counters.wifi_incomplete, 1);
    /* scan 21 goes on normally */
    feed(rx, tf_scan_ap(0x30, -70, 36), &ev, 0);
    feed(rx, tf_scan_end(21, 1), &ev, 1);
    assert_true(ev.u.wifi.complete);
    assert_int_equal(ev.u.wifi.scan_id, 21);
    assert_int_equal(ev.u.wifi.n_ap, 1);
    assert_int_equal(ev.u.wifi.bssid[0], 0x30);
    assert_int_equal(ev.u.wifi.t_us, (int64_t)(T0_MS + 2100) * 1000);
    assert_int_equal(rx->counters.wifi, 2);
    assert_int_equal(rx->counters.wifi_incomplete, 1);
}

static void test_wifi_ap_outside_scan_and_bad_aps(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    feed(rx, tf_scan_ap(0x40, -40, 1), &ev, SF_ERANGE); /* no scan open */
    assert_int_equal(rx->counters.decode_errors, 1);
    feed(rx, tf_scan_end(5, 0), &ev, SF_ERANGE); /* END without BEGIN */
    assert_int_equal(rx->counters.decode_errors, 2);

    feed(rx, tf_scan_begin(5, T0_MS), &ev, 0);
    feed(rx, tf_scan_ap(0x41, -40, 0), &ev, SF_ERANGE);  /* channel 0 */
    feed(rx, tf_scan_ap(0x42, -40, 200), &ev, SF_ERANGE); /* channel 200 */
    feed(rx, tf_scan_ap(0x43, 0, 1), &ev, SF_ERANGE);     /* rssi 0 dBm */
    assert_int_equal(rx->counters.decode_errors, 5);
    feed(rx, tf_scan_ap(0x44, -1, 14), &ev, 0);
    /* END of another scan id: the open scan is closed incomplete, and it is a decode error */
    feed(rx, tf_scan_end(6, 1), &ev, 1);
    assert_false(ev.u.wifi.complete);
    assert_int_equal(ev.u.wifi.n_ap, 1);
    assert_int_equal(ev.u.wifi.freq_mhz[0], 2484);
    assert_int_equal(rx->counters.decode_errors, 6);
    assert_int_equal(rx->counters.wifi_incomplete, 1);
    /* the AP after that END is outside a scan */
    feed(rx, tf_scan_ap(0x45, -40, 1), &ev, SF_ERANGE);
    assert_int_equal(rx->counters.decode_errors, 7);
}

static void test_wifi_scan_id_unwraps(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    const uint8_t ids[] = {254, 255, 0, 1};
    const int64_t want[] = {254, 255, 256, 257};
    for (int i = 0; i < 4; i++) {
        feed(rx, tf_scan_begin(ids[i], T0_MS + 100u * (uint32_t)i), &ev, 0);
        feed(rx, tf_scan_end(ids[i], 0), &ev, 1);
        assert_true(ev.u.wifi.complete);
        assert_int_equal(ev.u.wifi.n_ap, 0);
        assert_int_equal(ev.u.wifi.scan_id, want[i]);
    }
}

static void test_wifi_scan_before_board_time(void **state)
{
    (void)state;
    sf_board_rx_t *const rx = malloc(sizeof *rx);
    assert_non_null(rx);
    sf_board_rx_init(rx);
    sf_rx_event_t ev;
    feed(rx, tf_scan_begin(1, 500), &ev, SF_ENOTSYNC);
    assert_int_equal(rx->counters.unsynced, 1);
    feed(rx, tf_scan_ap(0x1, -50, 1), &ev, 0);
    feed(rx, tf_scan_end(1, 1), &ev, 0); /* no event: the scan has no time */
    assert_int_equal(rx->counters.wifi, 0);
    free(rx);
}

static void test_gnss_pairing(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    feed(rx, tf_gnss_info(T0_MS + 200, 523.4, 3.7), &ev, 0);
    assert_int_equal(ev.kind, sf_rx_none);
    feed(rx, tf_gnss_position(48.1372543, -11.5754321), &ev, 1);
    assert_int_equal(ev.kind, sf_rx_gnss);
    const sf_rx_gnss_t *const g = &ev.u.gnss;
    assert_int_equal(g->t_us, (int64_t)(T0_MS + 200) * 1000);
    assert_true(fabs(g->lat_deg - 48.1372543) <= 0.5e-7);
    assert_true(fabs(g->lon_deg - -11.5754321) <= 0.5e-7);
    assert_true(fabs(g->alt_m - 523.4) <= 0.05);
    assert_true(fabs(g->accuracy_m - 3.7) <= 0.05);
    assert_int_equal(rx->counters.gnss, 1);

    /* a POSITION without its INFO (INFO lost) */
    feed(rx, tf_gnss_position(48.0, 11.0), &ev, SF_ERANGE);
    assert_int_equal(rx->counters.decode_errors, 1);

    /* two INFOs: the POSITION goes with the newer */
    feed(rx, tf_gnss_info(T0_MS + 1200, 1.0, 1.0), &ev, 0);
    feed(rx, tf_gnss_info(T0_MS + 2200, -12.5, 20.0), &ev, 0);
    feed(rx, tf_gnss_position(-33.8688, 151.2093), &ev, 1);
    assert_int_equal(ev.u.gnss.t_us, (int64_t)(T0_MS + 2200) * 1000);
    assert_true(fabs(ev.u.gnss.alt_m - -12.5) <= 0.05);
    assert_true(fabs(ev.u.gnss.lon_deg - 151.2093) <= 0.5e-7);

    /* latitude outside ±90° */
    feed(rx, tf_gnss_info(T0_MS + 3200, 0.0, 1.0), &ev, 0);
    feed(rx, tf_gnss_position(95.0, 0.0), &ev, SF_ERANGE);
    assert_int_equal(rx->counters.decode_errors, 2);
    assert_int_equal(rx->counters.gnss, 2);
}

static void test_gnss_before_board_time(void **state)
{
    (void)state;
    sf_board_rx_t *const rx = malloc(sizeof *rx);
    assert_non_null(rx);
    sf_board_rx_init(rx);
    sf_rx_event_t ev;
    feed(rx, tf_gnss_info(100, 1.0, 1.0), &ev, SF_ENOTSYNC);
    assert_int_equal(rx->counters.unsynced, 1);
    feed(rx, tf_gnss_position(1.0, 1.0), &ev, SF_ERANGE); /* its INFO was refused */
    free(rx);
}

static void test_refused_frames_are_counted(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    const uint64_t frames0 = rx->counters.frames;
    const uint64_t ok0 = rx->counters.frames_ok;

    sf_can_frame_t f = tf_frame(0x123); /* not in the DBC */
    feed(rx, f, &ev, SF_EUNKNOWN_ID);
    assert_int_equal(rx->counters.unknown_id, 1);
    assert_int_equal(ev.kind, sf_rx_none);

    f = tf_accel(1, 20, 0, 0, 9.81);
    f.dlc = 5; /* truncated */
    feed(rx, f, &ev, SF_ELENGTH);
    assert_int_equal(rx->counters.bad_length, 1);
    f.dlc = 0;
    feed(rx, f, &ev, SF_ELENGTH);
    assert_int_equal(rx->counters.bad_length, 2);

    f = tf_accel(1, 20, 0, 0, 9.81);
    f.extended = true; /* 0x100 as a 29-bit id is another id */
    feed(rx, f, &ev, SF_EUNKNOWN_ID);
    assert_int_equal(rx->counters.unknown_id, 2);

    f = tf_board_time(T0_MS + 5000, 1);
    f.remote = true;
    feed(rx, f, &ev, SF_EUNKNOWN_ID);
    assert_int_equal(rx->counters.unknown_id, 3);
    assert_int_equal(rx->clock.board_ms, T0_MS); /* the remote frame did not move the clock */

    f = tf_frame(0x7FF);
    feed(rx, f, &ev, SF_EUNKNOWN_ID);
    assert_int_equal(rx->counters.unknown_id, 4);

    assert_int_equal(rx->counters.frames, frames0 + 6);
    assert_int_equal(rx->counters.frames_ok, ok0);
    assert_int_equal(rx->counters.imu, 0);
    assert_int_equal(rx->counters.decode_errors, 0);
}

static void test_mag_and_status(void **state)
{
    sf_board_rx_t *const rx = *state;
    sf_rx_event_t ev;
    feed(rx, tf_mag(0, (uint8_t)(T0_MS + 3), 21.5, -4.25, 43.0), &ev, 1);
    assert_int_equal(ev.kind, sf_rx_mag);
    assert_int_equal(ev.u.mag.t_us, (int64_t)(T0_MS + 3) * 1000);
    assert_true(fabs(ev.u.mag.field_ut[0] - 21.5) <= 0.005);
    assert_true(fabs(ev.u.mag.field_ut[1] - -4.25) <= 0.005);
    assert_true(fabs(ev.u.mag.field_ut[2] - 43.0) <= 0.005);
    feed(rx, tf_mag(1, (uint8_t)(T0_MS + 23), 21.5, -4.25, 43.0), &ev, 1);
    assert_int_equal(ev.u.mag.t_us, (int64_t)(T0_MS + 23) * 1000);
    assert_int_equal(ev.u.mag.seq, 1);
    assert_int_equal(rx->counters.mag, 2);

    sf_can_frame_t f = tf_frame(BOARD_BOARD_STATUS_FRAME_ID);
    const struct board_board_status_t st = {.tx_overflows = 17, .board_temp = -5, .fw_major = 1, .imu_ok = 1};
    assert_int_equal(board_board_status_pack(f.data, &st, 8), 8);
    feed(rx, f, &ev, 0);
    assert_int_equal(rx->counters.board_status, 1);
    assert_int_equal(rx->counters.board_tx_overflows, 17);
}

#define RX_TEST(fn) cmocka_unit_test_setup_teardown(fn, setup_rx, teardown_rx)

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_channel_to_mhz),
        RX_TEST(test_wifi_scan_complete),
        RX_TEST(test_wifi_lost_ap),
        RX_TEST(test_wifi_lost_end_then_new_begin),
        RX_TEST(test_wifi_ap_outside_scan_and_bad_aps),
        RX_TEST(test_wifi_scan_id_unwraps),
        cmocka_unit_test(test_wifi_scan_before_board_time),
        RX_TEST(test_gnss_pairing),
        cmocka_unit_test(test_gnss_before_board_time),
        RX_TEST(test_refused_frames_are_counted),
        RX_TEST(test_mag_and_status),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
