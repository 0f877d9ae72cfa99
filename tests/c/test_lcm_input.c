/* test_lcm_input.c — the raw-sensor replay (sf_lcm_input.h) on hostile logs, built byte by byte in
 * memory: an input-hardening review found that a WIFI event declaring 2^29 readings overflowed the heap in the
 * generated decode (SIGSEGV), a negative count asked for a huge allocation and an event header
 * claiming 1.9 GB made liblcm map 1.9 GB and then end the replay silently with status 0. Each case
 * checks the code, the counters, the message (event number, offset, field) and that the good events
 * around the bad one are still used. BLE (ble_scan_t, the other type with a count) gets the same
 * checks, and a scan of more beacons than SF_BLE_MAX_BEACONS keeps its first ones. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sf_error.h"
#include "sf_eventlog.h"
#include "sf_lcm_input.h"
#include "stridefix_ble_scan_t.h"
#include "stridefix_imu_t.h"
#include "stridefix_wifi_scan_t.h"

#define LOG_CAP (3u << 20)

typedef struct {
    uint8_t *p;
    size_t n;
    int64_t next_number;
} log_t;

static void put_be(log_t *const log, const uint64_t v, const int bytes)
{
    assert_true(log->n + (size_t)bytes <= LOG_CAP);
    for (int i = bytes - 1; i >= 0; i--) {
        log->p[log->n++] = (uint8_t)(v >> (8 * i));
    }
}

/* One event header with the given lengths (the caller writes what follows). */
static void put_header(log_t *const log, const uint32_t magic, const int32_t channel_len, const int32_t data_len)
{
    put_be(log, magic, 4);
    put_be(log, (uint64_t)log->next_number++, 8);
    put_be(log, 1000u * (uint64_t)log->next_number, 8);
    put_be(log, (uint32_t)channel_len, 4);
    put_be(log, (uint32_t)data_len, 4);
}

static void put_event(log_t *const log, const char *const channel, const void *const data, const size_t size)
{
    put_header(log, SF_EVENTLOG_MAGIC, (int32_t)strlen(channel), (int32_t)size);
    memcpy(log->p + log->n, channel, strlen(channel));
    log->n += strlen(channel);
    memcpy(log->p + log->n, data, size);
    log->n += size;
}

static void put_imu(log_t *const log, const int64_t seq)
{
    const stridefix_imu_t m = {.t_us = 10 * seq, .seq = seq, .accel_mps2 = {0, 0, 9.81}};
    uint8_t buf[256];
    const int n = stridefix_imu_t_encode(buf, 0, sizeof buf, &m);
    assert_true(n > 0);
    put_event(log, "IMU", buf, (size_t)n);
}

/* A scan of one AP whose n_ap field is then overwritten with n_ap_claimed. */
static void put_wifi_claiming(log_t *const log, const int32_t n_ap_claimed)
{
    int64_t bssid = 0x0123456789ab;
    float rssi = -60.0f;
    int32_t freq = 2412;
    const stridefix_wifi_scan_t m = {.t_us = 1, .scan_id = 2, .complete = 1, .n_ap = 1, .bssid = &bssid,
                                     .rssi_dbm = &rssi, .freq_mhz = &freq};
    uint8_t buf[256];
    const int n = stridefix_wifi_scan_t_encode(buf, 0, sizeof buf, &m);
    assert_true(n > 0);
    const size_t at = 8 + 8 + 8 + 1; /* hash, t_us, scan_id, complete */
    for (int i = 0; i < 4; i++) {
        buf[at + (size_t)i] = (uint8_t)((uint32_t)n_ap_claimed >> (24 - 8 * i));
    }
    put_event(log, "WIFI", buf, (size_t)n);
}

/* A BLE scan of n beacons (ids 1 .. n, rssi -40 - i) whose n field is then overwritten with n_claimed. */
static void put_ble_claiming(log_t *const log, const int32_t n, const int32_t n_claimed)
{
    int64_t id[64];
    float rssi[64];
    assert_true(n <= 64);
    for (int32_t i = 0; i < n; i++) {
        id[i] = i + 1;
        rssi[i] = -40.0f - (float)i;
    }
    const stridefix_ble_scan_t m = {.t_us = 5, .n = n, .beacon_id = id, .rssi_dbm = rssi};
    uint8_t buf[2048];
    const int size = stridefix_ble_scan_t_encode(buf, 0, sizeof buf, &m);
    assert_true(size > 0);
    const size_t at = 8 + 8; /* hash, t_us */
    for (int i = 0; i < 4; i++) {
        buf[at + (size_t)i] = (uint8_t)((uint32_t)n_claimed >> (24 - 8 * i));
    }
    put_event(log, "BLE", buf, (size_t)size);
}

typedef struct {
    int used;
    int skipped;
    int final_rc; /* 0, or SF_ECORRUPT */
    char first_error[512];
    sf_lcm_input_counters_t c;
} replay_t;

static replay_t replay(const log_t *const log)
{
    FILE *const f = fmemopen(log->p, log->n, "rb");
    assert_non_null(f);
    sf_lcm_input_t *in = NULL;
    char err[256];
    assert_int_equal(sf_lcm_input_open_stream(&in, f, "hostile.lcmlog", err, sizeof err), SF_OK);
    replay_t r = {0};
    for (;;) {
        sf_rx_event_t ev;
        int64_t t_us;
        const int rc = sf_lcm_input_next(in, &ev, &t_us);
        if (rc == 1) {
            r.used++;
            continue;
        }
        if (rc == SF_ESYNTAX || rc == SF_ECORRUPT) {
            if (r.skipped++ == 0) {
                snprintf(r.first_error, sizeof r.first_error, "%s", sf_lcm_input_error(in));
            }
        }
        if (rc != SF_ESYNTAX) {
            r.final_rc = rc;
            assert_int_equal(sf_lcm_input_next(in, &ev, &t_us), 0); /* the end stays the end */
            break;
        }
    }
    sf_lcm_input_counters(in, &r.c);
    sf_lcm_input_close(in);
    return r;
}

static void expect_error(const replay_t *const r, const char *const part)
{
    if (strstr(r->first_error, part) == NULL) {
        fail_msg("message '%s' lacks '%s'", r->first_error, part);
    }
}

static int setup(void **state)
{
    log_t *const log = calloc(1, sizeof *log);
    log->p = malloc(LOG_CAP);
    *state = log;
    return log->p == NULL;
}

static int teardown(void **state)
{
    log_t *const log = *state;
    free(log->p);
    free(log);
    return 0;
}

static void test_wifi_declaring_2_pow_29_readings_is_skipped(void **state)
{
    log_t *const log = *state;
    put_imu(log, 1);
    put_wifi_claiming(log, 1 << 29);
    put_imu(log, 2);
    const replay_t r = replay(log);
    assert_int_equal(r.used, 2);
    assert_int_equal(r.c.decode_errors, 1);
    assert_int_equal(r.final_rc, 0);
    expect_error(&r, "hostile.lcmlog: event 1 at offset 103 (WIFI): payload: n_ap = 536870912 needs");
}

static void test_wifi_with_a_negative_count_is_skipped(void **state)
{
    log_t *const log = *state;
    put_wifi_claiming(log, -5);
    put_imu(log, 1);
    const replay_t r = replay(log);
    assert_int_equal(r.used, 1);
    assert_int_equal(r.c.decode_errors, 1);
    expect_error(&r, "n_ap = -5 is negative");
}

static void test_wifi_with_trailing_bytes_is_skipped(void **state)
{
    log_t *const log = *state;
    put_wifi_claiming(log, 0); /* one AP's 16 bytes left over */
    const replay_t r = replay(log);
    assert_int_equal(r.used, 0);
    expect_error(&r, "16 trailing bytes");
}

static void test_ble_with_hostile_counts_is_skipped(void **state)
{
    log_t *const log = *state;
    put_ble_claiming(log, 1, 1 << 29);
    put_ble_claiming(log, 1, -3);
    put_ble_claiming(log, 2, 1); /* one beacon's 12 bytes left over */
    put_imu(log, 1);
    const replay_t r = replay(log);
    assert_int_equal(r.used, 1);
    assert_int_equal(r.c.decode_errors, 3);
    expect_error(&r, "event 0 at offset 0 (BLE): payload: n = 536870912 needs");
}

/* GIVEN a logged BLE scan of 40 beacons, WHEN replayed, THEN the event keeps the first
 * SF_BLE_MAX_BEACONS with their levels, in order. */
static void test_ble_longer_than_the_window_keeps_the_first(void **state)
{
    log_t *const log = *state;
    put_ble_claiming(log, 40, 40);
    FILE *const f = fmemopen(log->p, log->n, "rb");
    assert_non_null(f);
    sf_lcm_input_t *in = NULL;
    assert_int_equal(sf_lcm_input_open_stream(&in, f, "long.lcmlog", NULL, 0), SF_OK);
    static sf_rx_event_t ev;
    int64_t t_us;
    assert_int_equal(sf_lcm_input_next(in, &ev, &t_us), 1);
    assert_int_equal(ev.kind, sf_rx_ble);
    assert_int_equal(ev.u.ble.t_us, 5);
    assert_int_equal(ev.u.ble.n, SF_BLE_MAX_BEACONS);
    assert_int_equal(ev.u.ble.beacon_id[SF_BLE_MAX_BEACONS - 1], SF_BLE_MAX_BEACONS);
    assert_float_equal(ev.u.ble.rssi_dbm[SF_BLE_MAX_BEACONS - 1], -40.0 - (SF_BLE_MAX_BEACONS - 1), 1e-6);
    assert_int_equal(sf_lcm_input_next(in, &ev, &t_us), 0);
    sf_lcm_input_close(in);
}

static void test_header_claiming_1_9_gb_is_a_truncated_last_event(void **state)
{
    log_t *const log = *state;
    put_imu(log, 1);
    put_imu(log, 2);
    put_header(log, SF_EVENTLOG_MAGIC, 3, 1900000000);
    memcpy(log->p + log->n, "IMU", 3);
    log->n += 3;
    put_be(log, 0, 8); /* a little data, far less than claimed */
    const replay_t r = replay(log);
    assert_int_equal(r.used, 2);
    assert_int_equal(r.c.truncated, 1);
    assert_int_equal(r.c.decode_errors, 1);
    assert_int_equal(r.final_rc, 0);
    expect_error(&r, "event 2 at offset");
    expect_error(&r, "log ends inside the data");
}

static void test_event_above_the_cap_is_skipped_unread(void **state)
{
    log_t *const log = *state;
    const size_t big = SF_EVENTLOG_MAX_DATA_BYTES + 1u;
    put_header(log, SF_EVENTLOG_MAGIC, 4, (int32_t)big);
    memcpy(log->p + log->n, "WIFI", 4);
    log->n += 4;
    memset(log->p + log->n, 0xAB, big);
    log->n += big;
    put_imu(log, 1);
    const replay_t r = replay(log);
    assert_int_equal(r.used, 1);
    assert_int_equal(r.c.oversized, 1);
    expect_error(&r, "data length 1048577 exceeds the limit of 1048576 bytes; skipped");
}

static void test_bad_magic_refuses_the_rest(void **state)
{
    log_t *const log = *state;
    put_imu(log, 1);
    put_header(log, 0xDEADBEEFu, 3, 0);
    put_imu(log, 2); /* never reached: the reader does not hunt for the next magic */
    const replay_t r = replay(log);
    assert_int_equal(r.used, 1);
    assert_int_equal(r.final_rc, SF_ECORRUPT);
    assert_int_equal(r.c.refused, 1);
    expect_error(&r, "bad magic 0xDEADBEEF");
}

static void test_untrusted_lengths_refuse_the_rest(void **state)
{
    const int32_t bad[][2] = {{0, 10}, {256, 10}, {-1, 10}, {3, -2}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        log_t *const log = *state;
        log->n = 0;
        put_header(log, SF_EVENTLOG_MAGIC, bad[i][0], bad[i][1]);
        put_be(log, 0, 8);
        const replay_t r = replay(log);
        assert_int_equal(r.final_rc, SF_ECORRUPT);
        expect_error(&r, "the rest of the log is refused");
    }
}

static void test_truncated_header_and_channel_are_reported(void **state)
{
    log_t *const log = *state;
    put_imu(log, 1);
    const size_t whole = log->n;
    put_imu(log, 2);
    const size_t cuts[] = {whole + 5, whole + SF_EVENTLOG_HEADER_SIZE + 1};
    const char *const parts[] = {"inside the header", "inside the channel"};
    for (int i = 0; i < 2; i++) {
        log->n = cuts[i];
        const replay_t r = replay(log);
        assert_int_equal(r.used, 1);
        assert_int_equal(r.c.truncated, 1);
        expect_error(&r, parts[i]);
    }
}

static void test_channel_with_nul_is_skipped(void **state)
{
    log_t *const log = *state;
    put_event(log, "IMU", "", 0);
    log->p[SF_EVENTLOG_HEADER_SIZE + 1] = 0; /* "I\0U" */
    put_imu(log, 1);
    const replay_t r = replay(log);
    assert_int_equal(r.used, 1);
    expect_error(&r, "NUL");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_wifi_declaring_2_pow_29_readings_is_skipped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_wifi_with_a_negative_count_is_skipped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_wifi_with_trailing_bytes_is_skipped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ble_with_hostile_counts_is_skipped, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ble_longer_than_the_window_keeps_the_first, setup, teardown),
        cmocka_unit_test_setup_teardown(test_header_claiming_1_9_gb_is_a_truncated_last_event, setup, teardown),
        cmocka_unit_test_setup_teardown(test_event_above_the_cap_is_skipped_unread, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_magic_refuses_the_rest, setup, teardown),
        cmocka_unit_test_setup_teardown(test_untrusted_lengths_refuse_the_rest, setup, teardown),
        cmocka_unit_test_setup_teardown(test_truncated_header_and_channel_are_reported, setup, teardown),
        cmocka_unit_test_setup_teardown(test_channel_with_nul_is_skipped, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
