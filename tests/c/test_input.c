/* test_input.c — sf_input (firmware/board/sf_input.h), the one input interface: a candump snippet of
 * every sample kind gives events; those events logged with sf_rx_lcm_write and replayed through
 * "lcmlog:" give the same events with the same log times and the same counters; so does the candump as
 * asc2log writes it (direction flags, CAN FD lines); bad lines and unknown ids are counted and worded
 * with file and line; and closing a replay leaves standard input open. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sf_can_input.h"
#include "sf_candump.h"
#include "sf_error.h"
#include "sf_input.h"
#include "sf_lcm_out.h"
#include "sf_rx_lcm.h"
#include "sf_test_frames.h"

#define MAX_EVENTS 64
#define T0_US 1700000000000000LL

typedef struct {
    int n;
    int64_t log_t_us[MAX_EVENTS];
    sf_rx_event_t ev[MAX_EVENTS];
} events_t;

static void temp_path(char *const path, const size_t size, const char *const stem)
{
    snprintf(path, size, "/tmp/sf_test_input_%s_XXXXXX", stem);
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
}

static sf_can_frame_t baro_frame(const uint8_t seq, const uint8_t t_lo_ms, const double pressure_pa)
{
    sf_can_frame_t f = tf_frame(BOARD_BARO_FRAME_ID);
    const struct board_baro_t m = {.pressure = (uint32_t)TF_RAW(baro, pressure, pressure_pa),
                                   .temperature = (int16_t)TF_RAW(baro, temperature, 21.5),
                                   .seq = seq,
                                   .t_lo_ms = t_lo_ms};
    (void)board_baro_pack(f.data, &m, sizeof f.data);
    return f;
}

/* A walk in miniature: board time, 4 IMU samples, 2 MAG, 2 BARO, one scan of 3 APs, one GNSS fix, one
 * landmark, three BLE advertisements of two beacons (one window, still open at the end: the input's
 * end hands it back), plus a garbage line and an unknown id. Returns the number of lines written. */
static int write_candump(const char *const path)
{
    sf_can_frame_t frames[32];
    int n = 0;
    frames[n++] = tf_board_time(5000, 1);
    for (uint8_t i = 0; i < 4; i++) {
        const uint8_t t_lo = (uint8_t)((5000 + 10 * (i + 1)) & 0xFF);
        frames[n++] = tf_accel(i, t_lo, 0.1 * i, -0.2, 9.81);
        frames[n++] = tf_gyro(i, t_lo, 1.0, -2.0, 0.5 * i);
    }
    frames[n++] = tf_mag(0, (uint8_t)(5020 & 0xFF), 20.0, -5.0, -40.0);
    frames[n++] = tf_mag(1, (uint8_t)(5040 & 0xFF), 21.0, -5.5, -40.5);
    frames[n++] = baro_frame(0, (uint8_t)(5050 & 0xFF), 101325.0);
    frames[n++] = tf_scan_begin(7, 5060);
    frames[n++] = tf_scan_ap(0x001122334455ULL, -60, 6);
    frames[n++] = tf_frame(0x7FF); /* unknown id */
    frames[n++] = tf_scan_ap(0x001122334466ULL, -71, 11);
    frames[n++] = tf_scan_ap(0x001122334477ULL, -80, 36);
    frames[n++] = tf_scan_end(7, 3);
    frames[n++] = baro_frame(1, (uint8_t)(5100 & 0xFF), 101320.0);
    frames[n++] = tf_gnss_info(5100, 120.0, 8.0);
    frames[n++] = tf_gnss_position(48.1, 11.5);
    frames[n++] = tf_ble_adv(0xE078A33DB49CULL, -82, (uint8_t)(5105 & 0xFF));
    frames[n++] = tf_landmark(12.34, -5.67, 1, (uint8_t)(5106 & 0xFF));
    frames[n++] = tf_ble_adv(0xE078A33DB573ULL, -87, (uint8_t)(5107 & 0xFF));
    frames[n++] = tf_ble_adv(0xE078A33DB49CULL, -78, (uint8_t)(5108 & 0xFF));
    FILE *const f = fopen(path, "w");
    assert_non_null(f);
    for (int i = 0; i < n; i++) {
        frames[i].host_t_us = T0_US + 1000LL * i;
        char line[80];
        assert_true(sf_candump_format(&frames[i], "can0", line, sizeof line) > 0);
        fputs(line, f);
        if (i == 3) {
            fputs("this is not a candump line\n", f);
        }
    }
    fclose(f);
    return n + 1;
}

/* Every event of an input, with the counters at its end. */
static void read_all(const char *const spec, events_t *const out, sf_input_counters_t *const counters)
{
    sf_input_t *in = NULL;
    char err[256];
    assert_int_equal(sf_input_open(&in, spec, err, sizeof err), SF_OK);
    sf_input_item_t *const item = malloc(sizeof *item);
    assert_non_null(item);
    out->n = 0;
    for (;;) {
        const int rc = sf_input_next(in, item);
        if (rc == 0) {
            break;
        }
        assert_true(rc == 1 || rc == SF_ESYNTAX);
        if (rc == 1 && item->status == SF_OK && item->event.kind != sf_rx_none) {
            assert_true(out->n < MAX_EVENTS);
            out->log_t_us[out->n] = item->log_t_us;
            out->ev[out->n] = item->event;
            out->n++;
        }
    }
    sf_input_counters(in, counters);
    free(item);
    sf_input_close(in);
}

static void assert_same_event(const sf_rx_event_t *const a, const sf_rx_event_t *const b)
{
    assert_int_equal(a->kind, b->kind);
    switch (a->kind) {
    case sf_rx_imu:
        assert_int_equal(a->u.imu.t_us, b->u.imu.t_us);
        assert_int_equal(a->u.imu.seq, b->u.imu.seq);
        assert_memory_equal(a->u.imu.accel_mps2, b->u.imu.accel_mps2, sizeof a->u.imu.accel_mps2);
        assert_memory_equal(a->u.imu.gyro_radps, b->u.imu.gyro_radps, sizeof a->u.imu.gyro_radps);
        break;
    case sf_rx_mag:
        assert_int_equal(a->u.mag.t_us, b->u.mag.t_us);
        assert_int_equal(a->u.mag.seq, b->u.mag.seq);
        assert_memory_equal(a->u.mag.field_ut, b->u.mag.field_ut, sizeof a->u.mag.field_ut);
        break;
    case sf_rx_baro:
        assert_int_equal(a->u.baro.t_us, b->u.baro.t_us);
        assert_int_equal(a->u.baro.seq, b->u.baro.seq);
        assert_true(a->u.baro.pressure_pa == b->u.baro.pressure_pa);
        assert_true(a->u.baro.temperature_degc == b->u.baro.temperature_degc);
        break;
    case sf_rx_wifi:
        assert_int_equal(a->u.wifi.t_us, b->u.wifi.t_us);
        assert_int_equal(a->u.wifi.scan_id, b->u.wifi.scan_id);
        assert_int_equal(a->u.wifi.complete, b->u.wifi.complete);
        assert_int_equal(a->u.wifi.n_ap, b->u.wifi.n_ap);
        for (int32_t i = 0; i < a->u.wifi.n_ap; i++) {
            assert_int_equal(a->u.wifi.bssid[i], b->u.wifi.bssid[i]);
            assert_true(a->u.wifi.rssi_dbm[i] == b->u.wifi.rssi_dbm[i]);
            assert_int_equal(a->u.wifi.freq_mhz[i], b->u.wifi.freq_mhz[i]);
        }
        break;
    case sf_rx_gnss:
        assert_int_equal(a->u.gnss.t_us, b->u.gnss.t_us);
        assert_true(a->u.gnss.lat_deg == b->u.gnss.lat_deg && a->u.gnss.lon_deg == b->u.gnss.lon_deg);
        assert_true(a->u.gnss.alt_m == b->u.gnss.alt_m && a->u.gnss.accuracy_m == b->u.gnss.accuracy_m);
        break;
    case sf_rx_ble:
        assert_int_equal(a->u.ble.t_us, b->u.ble.t_us);
        assert_int_equal(a->u.ble.n, b->u.ble.n);
        for (int32_t i = 0; i < a->u.ble.n; i++) {
            assert_int_equal(a->u.ble.beacon_id[i], b->u.ble.beacon_id[i]);
            assert_true(a->u.ble.rssi_dbm[i] == b->u.ble.rssi_dbm[i]);
        }
        break;
    case sf_rx_landmark:
        assert_int_equal(a->u.landmark.t_us, b->u.landmark.t_us);
        assert_int_equal(a->u.landmark.landmark_id, b->u.landmark.landmark_id);
        assert_true(a->u.landmark.x_m == b->u.landmark.x_m && a->u.landmark.y_m == b->u.landmark.y_m);
        assert_int_equal(a->u.landmark.floor, b->u.landmark.floor);
        assert_true(a->u.landmark.accuracy_m == b->u.landmark.accuracy_m);
        break;
    case sf_rx_none: fail_msg("an event without a kind"); break;
    }
}

/* GIVEN a candump of every kind, WHEN its events are logged as the daemon logs inputs and the log is
 * replayed, THEN the replay gives the same events at the same log times, and the same sample counts. */
static void test_candump_and_lcm_replay_give_the_same_events(void **state)
{
    (void)state;
    char candump[64], lcmlog[64], spec[80];
    temp_path(candump, sizeof candump, "candump");
    temp_path(lcmlog, sizeof lcmlog, "lcmlog");
    (void)write_candump(candump);

    static events_t can, replay;
    sf_input_counters_t cc, rc;
    read_all(candump, &can, &cc);
    assert_int_equal(can.n, 4 + 2 + 2 + 1 + 1 + 1 + 1);
    assert_int_equal(cc.bad_syntax, 1);
    assert_int_equal(cc.rx.unknown_id, 1);
    assert_int_equal(cc.frames_total, cc.rx.frames + 1);
    assert_int_equal(cc.rx.imu, 4);
    assert_int_equal(cc.rx.wifi, 1);
    assert_int_equal(cc.rx.gnss, 1);
    assert_int_equal(cc.rx.landmark, 1);
    assert_int_equal(cc.rx.ble, 1);
    assert_int_equal(cc.rx.ble_adverts, 3);
    const sf_rx_event_t *const ble = &can.ev[can.n - 1]; /* the window, handed back at the end */
    assert_int_equal(ble->kind, sf_rx_ble);
    assert_int_equal(ble->u.ble.t_us, 5105 * 1000LL);
    assert_int_equal(ble->u.ble.n, 2);
    assert_int_equal(ble->u.ble.beacon_id[0], 0xE078A33DB49CLL);
    assert_float_equal(ble->u.ble.rssi_dbm[0], -80.0, 1e-6); /* mean of -82 and -78 dBm */
    assert_float_equal(ble->u.ble.rssi_dbm[1], -87.0, 1e-6);
    const sf_rx_event_t *const lm = &can.ev[can.n - 2];
    assert_int_equal(lm->kind, sf_rx_landmark);
    assert_float_equal(lm->u.landmark.x_m, 12.34, 1e-9);
    assert_float_equal(lm->u.landmark.y_m, -5.67, 1e-9);
    assert_int_equal(lm->u.landmark.floor, 1);
    assert_float_equal(lm->u.landmark.accuracy_m, 0.3, 1e-6); /* landmark.accuracy_m's default */

    sf_lcm_out_t *out = NULL;
    char err[256];
    unlink(lcmlog); /* the log is created O_EXCL: the name only, not the file */
    assert_int_equal(sf_lcm_out_open(&out, lcmlog, NULL, 16, true, err, sizeof err), SF_OK);
    for (int i = 0; i < can.n; i++) {
        sf_rx_lcm_write(out, can.log_t_us[i], &can.ev[i]);
    }
    assert_int_equal(sf_lcm_out_close(out, NULL), SF_OK);

    snprintf(spec, sizeof spec, "%s%s", SF_INPUT_LCMLOG_PREFIX, lcmlog);
    read_all(spec, &replay, &rc);
    assert_int_equal(replay.n, can.n);
    for (int i = 0; i < can.n; i++) {
        assert_int_equal(replay.log_t_us[i], can.log_t_us[i]);
        assert_same_event(&replay.ev[i], &can.ev[i]);
    }
    assert_int_equal(rc.frames_total, (uint64_t)can.n);
    assert_int_equal(rc.rx.frames_ok, (uint64_t)can.n);
    assert_int_equal(rc.bad_syntax, 0);
    assert_true(rc.rx.imu == cc.rx.imu && rc.rx.mag == cc.rx.mag && rc.rx.baro == cc.rx.baro);
    assert_true(rc.rx.wifi == cc.rx.wifi && rc.rx.gnss == cc.rx.gnss);
    assert_true(rc.rx.ble == cc.rx.ble && rc.rx.landmark == cc.rx.landmark);
    unlink(candump);
    unlink(lcmlog);
}

/* Bad input is worded with the file and line; expected skips (before the first BOARD_TIME) are not. */
static void test_describe_names_file_and_line(void **state)
{
    (void)state;
    char candump[64];
    temp_path(candump, sizeof candump, "describe");
    FILE *const f = fopen(candump, "w");
    assert_non_null(f);
    fputs("(1700000000.000000) can0 110#0000000000000000\n", f); /* MAG before any BOARD_TIME */
    fputs("garbage\n", f);
    fputs("(1700000000.000100) can0 7FF#00\n", f);
    fclose(f);
    sf_input_t *in = NULL;
    assert_int_equal(sf_input_open(&in, candump, NULL, 0), SF_OK);
    assert_false(sf_input_is_live(in));
    static sf_input_item_t item;
    char text[512];
    assert_int_equal(sf_input_next(in, &item), 1);
    assert_int_equal(item.status, SF_ENOTSYNC);
    assert_false(sf_input_describe(in, item.status, text, sizeof text));
    assert_int_equal(sf_input_next(in, &item), SF_ESYNTAX);
    assert_true(sf_input_describe(in, SF_ESYNTAX, text, sizeof text));
    assert_non_null(strstr(text, ":2: not a candump -L line; skipped: 'garbage'"));
    assert_int_equal(sf_input_next(in, &item), 1);
    assert_int_equal(item.status, SF_EUNKNOWN_ID);
    assert_int_equal(item.event.kind, sf_rx_none);
    assert_true(sf_input_describe(in, item.status, text, sizeof text));
    assert_non_null(strstr(text, ":3: CAN id 0x7FF is not in board.dbc; skipped"));
    assert_int_equal(sf_input_next(in, &item), 0);
    sf_input_close(in);
    unlink(candump);
}

/* The candump in path as can-utils' asc2log writes it (logs converted from
 * Vector ASC files must replay too), into out: a direction flag after
 * every frame (" R", every third " T") and, after every fifth line, a CAN FD line of the same time
 * (12 bytes; extended id every other one). Returns the number of FD lines. */
static int write_asc2log(const char *const path, const char *const out)
{
    FILE *const in = fopen(path, "r");
    FILE *const f = fopen(out, "w");
    assert_true(in != NULL && f != NULL);
    char line[128];
    int n = 0, n_fd = 0;
    while (fgets(line, sizeof line, in) != NULL) {
        line[strcspn(line, "\n")] = '\0';
        fprintf(f, "%s %c\n", line, n % 3 == 2 ? 'T' : 'R');
        if (++n % 5 == 0 && line[0] == '(') {
            fprintf(f, "%.*s can0 %s##1000102030405060708090A0B R\n", (int)strcspn(line, " "), line,
                    n_fd % 2 ? "1ABCDEF0" : "123");
            n_fd++;
        }
    }
    fclose(in);
    fclose(f);
    return n_fd;
}

/* GIVEN the candump of every kind as asc2log writes it (direction flags, CAN FD lines among the
 * frames), WHEN it is read, THEN it gives the candump's events at the same log times; each FD line is
 * a frame read but not the board's (unknown id, can_fd), not bad syntax, and is worded with its line. */
static void test_asc2log_output_gives_the_same_events(void **state)
{
    (void)state;
    char candump[64], asc2log[64];
    temp_path(candump, sizeof candump, "plain");
    temp_path(asc2log, sizeof asc2log, "asc2log");
    (void)write_candump(candump);
    const int n_fd = write_asc2log(candump, asc2log);
    assert_true(n_fd >= 4);

    static events_t plain, flagged;
    sf_input_counters_t pc, fc;
    read_all(candump, &plain, &pc);
    read_all(asc2log, &flagged, &fc);
    assert_int_equal(flagged.n, plain.n);
    for (int i = 0; i < plain.n; i++) {
        assert_int_equal(flagged.log_t_us[i], plain.log_t_us[i]);
        assert_same_event(&flagged.ev[i], &plain.ev[i]);
    }
    assert_int_equal(pc.can_fd, 0);
    assert_int_equal(fc.can_fd, (uint64_t)n_fd);
    assert_int_equal(fc.rx.unknown_id, pc.rx.unknown_id + (uint64_t)n_fd);
    assert_int_equal(fc.bad_syntax, pc.bad_syntax); /* the garbage line only */
    assert_int_equal(fc.frames_total, pc.frames_total + (uint64_t)n_fd);
    assert_int_equal(fc.rx.frames_ok, pc.rx.frames_ok);
    assert_true(fc.rx.imu == pc.rx.imu && fc.rx.wifi == pc.rx.wifi && fc.rx.ble_adverts == pc.rx.ble_adverts);

    sf_input_t *in = NULL;
    assert_int_equal(sf_input_open(&in, asc2log, NULL, 0), SF_OK);
    static sf_input_item_t item;
    int rc;
    while ((rc = sf_input_next(in, &item)) != 0 && !(rc == 1 && item.status == SF_ENOTCLASSIC)) {
    }
    assert_int_equal(rc, 1);
    assert_int_equal(item.event.kind, sf_rx_none);
    char text[512];
    assert_true(sf_input_describe(in, item.status, text, sizeof text));
    /* line 11: the FD line after the tenth line (the fifth is the garbage, which gets none) */
    assert_non_null(strstr(text, ":11: CAN id 0x123 is a CAN FD frame; the board sends classic CAN only; skipped"));
    sf_input_close(in);
    unlink(candump);
    unlink(asc2log);
}

static bool stdin_open(void)
{
    return fcntl(0, F_GETFD) != -1;
}

/* Regression: `stridefixd --replay` closed file descriptor 0 at exit, because it always
 * closed the CAN input, which on a replay had never been opened (zeroed: fd 0). With stdin closed,
 * the next file the process opens becomes fd 0. Replaying, and closing a never-opened CAN input, must
 * both leave stdin open. */
static void test_replay_close_does_not_close_stdin(void **state)
{
    (void)state;
    if (!stdin_open()) { /* ctest may start us without a stdin: give ourselves one */
        const int fd = open("/dev/null", O_RDONLY);
        assert_int_equal(fd, 0);
    }
    char lcmlog[64], spec[80];
    temp_path(lcmlog, sizeof lcmlog, "stdin");
    sf_lcm_out_t *out = NULL;
    unlink(lcmlog); /* the log is created O_EXCL: the name only, not the file */
    assert_int_equal(sf_lcm_out_open(&out, lcmlog, NULL, 4, true, NULL, 0), SF_OK);
    sf_rx_event_t ev = {.kind = sf_rx_mag, .u.mag = {.t_us = 1000, .seq = 1, .field_ut = {1.0, 2.0, 3.0}}};
    sf_rx_lcm_write(out, 5, &ev);
    assert_int_equal(sf_lcm_out_close(out, NULL), SF_OK);

    snprintf(spec, sizeof spec, "%s%s", SF_INPUT_LCMLOG_PREFIX, lcmlog);
    sf_input_t *in = NULL;
    assert_int_equal(sf_input_open(&in, spec, NULL, 0), SF_OK);
    static sf_input_item_t item;
    while (sf_input_next(in, &item) != 0) {
    }
    sf_input_close(in);
    assert_true(stdin_open());

    sf_can_input_t never_opened;
    memset(&never_opened, 0, sizeof never_opened);
    sf_can_input_close(&never_opened);
    assert_true(stdin_open());
    sf_input_close(NULL);
    unlink(lcmlog);
}

static void test_missing_inputs_fail_with_a_message(void **state)
{
    (void)state;
    sf_input_t *in = NULL;
    char err[256];
    assert_int_equal(sf_input_open(&in, "/nonexistent/x.candump", err, sizeof err), SF_ENOENT);
    assert_null(in);
    assert_non_null(strstr(err, "/nonexistent/x.candump"));
    assert_int_equal(sf_input_open(&in, "lcmlog:/nonexistent/x.lcmlog", err, sizeof err), SF_ENOENT);
    assert_null(in);
    assert_int_equal(sf_input_open(&in, "", err, sizeof err), SF_EINVAL);
}

/* Regression (input hardening): --input /dev/zero hung and a directory was accepted. Devices and
 * directories are refused for candump and LCM inputs alike; a FIFO (a stream, as stdin) is not. */
static void test_devices_and_directories_are_refused(void **state)
{
    (void)state;
    static const char *const specs[] = {"/dev/zero", "/tmp", "lcmlog:/dev/zero", "lcmlog:/tmp"};
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++) {
        sf_input_t *in = NULL;
        char err[256] = "";
        assert_int_equal(sf_input_open(&in, specs[i], err, sizeof err), SF_EIO);
        assert_null(in);
        assert_non_null(strstr(err, "not a file"));
    }
    char fifo[64];
    temp_path(fifo, sizeof fifo, "fifo");
    unlink(fifo);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    const int writer = open(fifo, O_RDWR); /* keeps the FIFO's open from blocking */
    assert_true(writer >= 0);
    sf_input_t *in = NULL;
    char err[256] = "";
    assert_int_equal(sf_input_open(&in, fifo, err, sizeof err), SF_OK);
    sf_input_close(in);
    close(writer);
    unlink(fifo);
}

/* Regression (input hardening): a PNG given as a candump was 508 bad lines and exit 0. An input without one
 * valid frame says so; one valid frame among bad lines is enough. */
static void test_nothing_valid_is_told(void **state)
{
    (void)state;
    char path[64];
    temp_path(path, sizeof path, "junk");
    FILE *const f = fopen(path, "wb");
    assert_non_null(f);
    fputs("\x89PNG\r\n\x1a\nnot a frame\n(1.0) can0 7FF#00\n", f);
    fclose(f);
    sf_input_t *in = NULL;
    char err[256];
    char why[256] = "";
    assert_int_equal(sf_input_open(&in, path, err, sizeof err), SF_OK);
    sf_input_item_t *const item = malloc(sizeof *item);
    assert_non_null(item);
    while (sf_input_next(in, item) != 0) {
    }
    assert_true(sf_input_nothing_valid(in, why, sizeof why));
    assert_non_null(strstr(why, "nothing valid"));
    assert_non_null(strstr(why, path));
    sf_input_close(in);

    const int n_lines = write_candump(path);
    assert_true(n_lines > 1);
    assert_int_equal(sf_input_open(&in, path, err, sizeof err), SF_OK);
    while (sf_input_next(in, item) != 0) {
    }
    assert_false(sf_input_nothing_valid(in, why, sizeof why));
    sf_input_close(in);
    free(item);
    unlink(path);
}

/* The kind table: every kind has a channel that decodes back to it; other channels are not inputs,
 * and a payload that does not decode is SF_ESYNTAX. */
static void test_every_kind_has_a_channel(void **state)
{
    (void)state;
    assert_null(sf_rx_lcm_channel(sf_rx_none));
    static const unsigned char junk[3] = {1, 2, 3};
    for (int k = 1; k <= SF_RX_KIND_COUNT; k++) {
        const char *const ch = sf_rx_lcm_channel((sf_rx_kind_t)k);
        assert_non_null(ch);
        sf_rx_event_t ev;
        assert_int_equal(sf_rx_lcm_decode(ch, junk, sizeof junk, &ev, NULL, NULL, 0), SF_ESYNTAX);
    }
    sf_rx_event_t ev;
    assert_int_equal(sf_rx_lcm_decode("TRUTH", junk, sizeof junk, &ev, NULL, NULL, 0), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_candump_and_lcm_replay_give_the_same_events),
        cmocka_unit_test(test_describe_names_file_and_line),
        cmocka_unit_test(test_asc2log_output_gives_the_same_events),
        cmocka_unit_test(test_replay_close_does_not_close_stdin),
        cmocka_unit_test(test_missing_inputs_fail_with_a_message),
        cmocka_unit_test(test_every_kind_has_a_channel),
        cmocka_unit_test(test_devices_and_directories_are_refused),
        cmocka_unit_test(test_nothing_valid_is_told),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
