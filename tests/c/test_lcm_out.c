/* test_lcm_out.c — sf_lcm_out: what goes in comes out of the event log, in order, byte for byte,
 * read back with liblcm's own reader; the counters agree with the file; a small blocking queue
 * loses nothing; live publishing to memq:// (no network); the same with caller_writes; a batch cut
 * short by the file size limit keeps exactly the events that fit. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "sf_error.h"
#include "sf_lcm_out.h"
#include "stridefix_imu_t.h"
#include "stridefix_pose_t.h"

#define N_IMU 1000
#define N_POSE 5
#define T_BASE_US 1700000000000000LL

static void temp_path(char *const path, const size_t size)
{
    snprintf(path, size, "/tmp/sf_test_lcm_XXXXXX");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path); /* the log is created O_EXCL: the name only, not the file */
}

static stridefix_imu_t imu_sample(const int i)
{
    stridefix_imu_t m;
    memset(&m, 0, sizeof m);
    m.t_us = 1000000 + 10000LL * i;
    m.seq = i;
    for (int k = 0; k < 3; k++) {
        m.accel_mps2[k] = 0.001 * i + k;
        m.gyro_radps[k] = -0.0001 * i - k;
    }
    return m;
}

static stridefix_pose_t pose_sample(const int i)
{
    stridefix_pose_t m;
    memset(&m, 0, sizeof m);
    m.t_us = 1000000 + 2000000LL * i;
    m.x_m = 0.7 * i;
    m.y_m = -0.1 * i;
    m.floor = (int16_t)i;
    m.heading_rad = 0.25f * (float)i;
    m.sigma_m = 0.5f;
    m.step_count = i;
    m.scheme = STRIDEFIX_POSE_T_SCHEME_PDR_ONLY;
    return m;
}

/* The event timestamp of message j in the order written (IMU i, a POSE after every 200th IMU). */
static int64_t stamp(const int j)
{
    return T_BASE_US + 10000LL * j;
}

static long file_size(const char *const path)
{
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    return (long)st.st_size;
}

/* Writes N_IMU IMU messages with a POSE after every 200th; returns the number written. */
static int write_all(sf_lcm_out_t *const out)
{
    int j = 0;
    int pose = 0;
    for (int i = 0; i < N_IMU; i++) {
        const stridefix_imu_t m = imu_sample(i);
        const int size = stridefix_imu_t_encoded_size(&m);
        unsigned char buf[256];
        assert_true(size > 0 && size <= (int)sizeof buf);
        assert_int_equal(stridefix_imu_t_encode(buf, 0, size, &m), size);
        assert_int_equal(sf_lcm_out_write(out, "IMU", stamp(j++), buf, (size_t)size), SF_OK);
        if (i % 200 == 199) {
            const stridefix_pose_t p = pose_sample(pose++);
            SF_LCM_WRITE(out, "POSE", stamp(j++), stridefix_pose_t, &p);
        }
    }
    assert_int_equal(pose, N_POSE);
    return j;
}

/* Reads the log back with liblcm and checks every event. */
static void check_log(const char *const path, const int n_events)
{
    lcm_eventlog_t *const log = lcm_eventlog_create(path, "r");
    assert_non_null(log);
    int j = 0, imu = 0, pose = 0;
    lcm_eventlog_event_t *ev;
    while ((ev = lcm_eventlog_read_next_event(log)) != NULL) {
        assert_true(j < n_events);
        assert_int_equal(ev->timestamp, stamp(j));
        assert_int_equal(ev->eventnum, j);
        if (strcmp(ev->channel, "IMU") == 0) {
            stridefix_imu_t got;
            assert_int_equal(stridefix_imu_t_decode(ev->data, 0, ev->datalen, &got), ev->datalen);
            const stridefix_imu_t want = imu_sample(imu);
            assert_int_equal(got.t_us, want.t_us);
            assert_int_equal(got.seq, want.seq);
            assert_memory_equal(got.accel_mps2, want.accel_mps2, sizeof want.accel_mps2);
            assert_memory_equal(got.gyro_radps, want.gyro_radps, sizeof want.gyro_radps);
            stridefix_imu_t_decode_cleanup(&got);
            imu++;
        } else if (strcmp(ev->channel, "POSE") == 0) {
            stridefix_pose_t got;
            assert_int_equal(stridefix_pose_t_decode(ev->data, 0, ev->datalen, &got), ev->datalen);
            const stridefix_pose_t want = pose_sample(pose);
            assert_int_equal(got.t_us, want.t_us);
            assert_true(got.x_m == want.x_m && got.y_m == want.y_m);
            assert_int_equal(got.floor, want.floor);
            assert_true(got.heading_rad == want.heading_rad);
            assert_int_equal(got.step_count, want.step_count);
            assert_int_equal(imu, 200 * (pose + 1)); /* in the order written */
            stridefix_pose_t_decode_cleanup(&got);
            pose++;
        } else {
            fail_msg("event %d: unexpected channel '%s'", j, ev->channel);
        }
        lcm_eventlog_free_event(ev);
        j++;
    }
    lcm_eventlog_destroy(log);
    assert_int_equal(j, n_events);
    assert_int_equal(imu, N_IMU);
    assert_int_equal(pose, N_POSE);
}

static void test_log_write_read_back(void **state)
{
    (void)state;
    char path[64];
    temp_path(path, sizeof path);
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, path, NULL, 4096, false, err, sizeof err), SF_OK);
    const int n = write_all(out);
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.events, (uint64_t)n);
    assert_int_equal(c.drops, 0);
    assert_int_equal(c.publish_errors, 0);
    check_log(path, n);
    unlink(path);
}

/* Regression test for "LCM log byte counter short by 8 per event" (open). counters.bytes is
 * documented as the log bytes written, so it must equal the file size. sf_lcm_out.c counts a 20-byte
 * event header, but liblcm writes 28 (sync word 4 + event number 8 + timestamp 8 + channel length 4
 * + data length 4), so HEALTH under-reports the log size by 8 bytes per event. */
static void test_log_bytes_counter_equals_file_size(void **state)
{
    (void)state;
    char path[64];
    temp_path(path, sizeof path);
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, path, NULL, 4096, false, err, sizeof err), SF_OK);
    const int n = write_all(out);
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.events, (uint64_t)n);
    const long size = file_size(path);
    unlink(path);
    if ((long)c.bytes != size) {
        fail_msg("counters.bytes = %llu, file size = %ld (difference %ld = %.1f bytes per event)",
                 (unsigned long long)c.bytes, size, size - (long)c.bytes, (double)(size - (long)c.bytes) / n);
    }
}

static void test_small_blocking_queue_loses_nothing(void **state)
{
    (void)state;
    char path[64];
    temp_path(path, sizeof path);
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, path, NULL, 4, true, err, sizeof err), SF_OK);
    const int n = write_all(out); /* every write returned SF_OK */
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.events, (uint64_t)n);
    assert_int_equal(c.drops, 0);
    check_log(path, n);
    unlink(path);
}

static void test_small_dropping_queue_counts_drops(void **state)
{
    (void)state;
    char path[64];
    temp_path(path, sizeof path);
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, path, NULL, 2, false, err, sizeof err), SF_OK);
    const char payload[100] = {1};
    int full = 0;
    const int n = 5000;
    for (int i = 0; i < n; i++) {
        const int rc = sf_lcm_out_write(out, "X", i, payload, sizeof payload);
        assert_true(rc == SF_OK || rc == SF_EFULL);
        full += rc == SF_EFULL;
    }
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.drops, (uint64_t)full);
    assert_int_equal(c.events + c.drops, (uint64_t)n);
    unlink(path);
}

static void test_live_memq_publishing(void **state)
{
    (void)state;
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, NULL, "memq://", 16, false, err, sizeof err), SF_OK);
    const stridefix_imu_t m = imu_sample(3);
    for (int i = 0; i < 100; i++) {
        SF_LCM_WRITE(out, "IMU", stamp(i), stridefix_imu_t, &m);
    }
    sf_lcm_out_counters_t c;
    sf_lcm_out_counters(out, &c);
    assert_int_equal(c.publish_errors, 0);
    assert_int_equal(c.events, 0); /* no log */
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.publish_errors, 0);
    assert_int_equal(c.drops, 0);
}

static void test_log_and_memq_together(void **state)
{
    (void)state;
    char path[64];
    temp_path(path, sizeof path);
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, path, "memq://", 64, true, err, sizeof err), SF_OK);
    const int n = write_all(out);
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.events, (uint64_t)n);
    assert_int_equal(c.publish_errors, 0);
    check_log(path, n);
    unlink(path);
}

/* caller_writes (a file replay): the same log, byte for byte in content, from batches the caller
 * writes; a queue of 4 messages still loses nothing (the caller writes it out when it is full). */
static void test_caller_writes_the_same_log(void **state)
{
    (void)state;
    for (size_t capacity = 4; capacity <= 4096; capacity *= 1024) {
        char path[64];
        temp_path(path, sizeof path);
        const sf_lcm_out_config_t cfg = {.log_path = path, .queue_capacity = capacity, .block_when_full = true,
                                         .caller_writes = true, .fsync_interval_ms = 1000, .report = stderr};
        sf_lcm_out_t *out = NULL;
        char err[256] = "";
        assert_int_equal(sf_lcm_out_open_config(&out, &cfg, err, sizeof err), SF_OK);
        const int n = write_all(out);
        sf_lcm_out_counters_t c;
        assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
        assert_int_equal(c.events, (uint64_t)n);
        assert_int_equal(c.drops, 0);
        assert_int_equal((long)c.bytes, file_size(path));
        check_log(path, n);
        unlink(path);
    }
}

/* Injected: the file may not grow past 10,000 bytes (RLIMIT_FSIZE; the write that crosses it is cut
 * short, the next fails with EFBIG). A batch that does not fit is undone and its events go one by
 * one, so exactly the events that fit are in the file, numbered, whole, and each other one is
 * dropped and counted with its bytes; the episode is reported once. With the writer thread and with
 * caller_writes. */
static void test_a_batch_that_does_not_fit_keeps_exactly_the_events_that_fit(void **state)
{
    (void)state;
    struct rlimit old;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
    void (*const old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
    for (int mode = 0; mode < 2; mode++) {
        char path[64], report_path[64];
        temp_path(path, sizeof path);
        temp_path(report_path, sizeof report_path);
        FILE *const report = fopen(report_path, "w+");
        assert_non_null(report);
        const sf_lcm_out_config_t cfg = {.log_path = path, .queue_capacity = 4096, .block_when_full = true,
                                         .caller_writes = mode == 1, .fsync_interval_ms = 1000, .report = report};
        sf_lcm_out_t *out = NULL;
        char err[256] = "";
        assert_int_equal(sf_lcm_out_open_config(&out, &cfg, err, sizeof err), SF_OK);
        const struct rlimit small = {10000, old.rlim_max};
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
        const char payload[72] = {7}; /* 28 + 1 + 72 = 101 bytes an event */
        for (int i = 0; i < 500; i++) {
            assert_int_equal(sf_lcm_out_write(out, "X", i, payload, sizeof payload), SF_OK);
        }
        sf_lcm_out_counters_t c;
        assert_int_equal(sf_lcm_out_close(out, &c), SF_EIO); /* the log is incomplete */
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
        assert_int_equal(c.events, 10000 / 101);
        assert_int_equal(c.events + c.drops, 500);
        assert_int_equal(c.drop_bytes, c.drops * 101);
        assert_int_equal((long)c.bytes, file_size(path));
        lcm_eventlog_t *const log = lcm_eventlog_create(path, "r");
        assert_non_null(log);
        int64_t j = 0;
        lcm_eventlog_event_t *ev;
        while ((ev = lcm_eventlog_read_next_event(log)) != NULL) {
            assert_int_equal(ev->eventnum, j);
            assert_int_equal(ev->timestamp, j);
            lcm_eventlog_free_event(ev);
            j++;
        }
        lcm_eventlog_destroy(log);
        assert_int_equal(j, (int64_t)c.events);
        char line[512];
        int told = 0;
        rewind(report);
        while (fgets(line, sizeof line, report) != NULL) {
            told += strstr(line, "writing the log failed") != NULL;
        }
        assert_int_equal(told, 1);
        fclose(report);
        unlink(report_path);
        unlink(path);
    }
    signal(SIGXFSZ, old_handler);
}

static void test_open_errors(void **state)
{
    (void)state;
    sf_lcm_out_t *out = NULL;
    char err[256] = "";
    assert_int_equal(sf_lcm_out_open(&out, "/nonexistent/dir/x.lcmlog", NULL, 16, false, err, sizeof err), SF_EIO);
    assert_non_null(strstr(err, "/nonexistent/dir/x.lcmlog"));
    assert_int_equal(sf_lcm_out_open(&out, NULL, NULL, 0, false, err, sizeof err), SF_EINVAL);
    assert_int_equal(sf_lcm_out_open(NULL, NULL, NULL, 16, false, err, sizeof err), SF_EINVAL);
    /* neither log nor LCM: writes are accepted and go nowhere */
    assert_int_equal(sf_lcm_out_open(&out, NULL, NULL, 16, false, err, sizeof err), SF_OK);
    assert_int_equal(sf_lcm_out_write(out, "X", 0, "a", 1), SF_OK);
    assert_int_equal(sf_lcm_out_write(out, NULL, 0, "a", 1), SF_EINVAL);
    assert_int_equal(sf_lcm_out_write(out, "X", 0, NULL, 1), SF_EINVAL);
    assert_int_equal(sf_lcm_out_close(out, NULL), SF_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_log_write_read_back),
        cmocka_unit_test(test_log_bytes_counter_equals_file_size),
        cmocka_unit_test(test_small_blocking_queue_loses_nothing),
        cmocka_unit_test(test_small_dropping_queue_counts_drops),
        cmocka_unit_test(test_live_memq_publishing),
        cmocka_unit_test(test_log_and_memq_together),
        cmocka_unit_test(test_caller_writes_the_same_log),
        cmocka_unit_test(test_a_batch_that_does_not_fit_keeps_exactly_the_events_that_fit),
        cmocka_unit_test(test_open_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
