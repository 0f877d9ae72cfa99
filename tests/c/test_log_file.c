/* test_log_file.c — sf_log_file and sf_lcm_out's rotation: the .part is renamed on close and never
 * replaces a file that appeared meanwhile; existing names and symlinks are refused; a failed write
 * (injected: /dev/full) leaves the file as it was; rotated names and default names; size rotation
 * and sf_lcm_out_rotate give files that each start with the header, with a writer thread and with
 * caller_writes; sf_log_file_append numbers a laid-out run; drops count their bytes. */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "sf_error.h"
#include "sf_lcm_out.h"
#include "sf_log_file.h"

typedef struct {
    char dir[64];
    char path[128];
} fixture_t;

static int setup(void **state)
{
    fixture_t *const fx = calloc(1, sizeof *fx);
    snprintf(fx->dir, sizeof fx->dir, "/tmp/sf_test_log_file_XXXXXX");
    if (fx == NULL || mkdtemp(fx->dir) == NULL) {
        return -1;
    }
    snprintf(fx->path, sizeof fx->path, "%s/walk.lcmlog", fx->dir);
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture_t *const fx = *state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", fx->dir);
    const int rc = system(cmd);
    free(fx);
    return rc == 0 ? 0 : -1;
}

static bool exists(const char *const path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

/* Events of one file read back with liblcm: count, and the channel of the first. */
static int read_back(const char *const path, char *const first_channel, const size_t size)
{
    lcm_eventlog_t *const log = lcm_eventlog_create(path, "r");
    assert_non_null(log);
    int n = 0;
    lcm_eventlog_event_t *ev;
    while ((ev = lcm_eventlog_read_next_event(log)) != NULL) {
        assert_int_equal(ev->eventnum, n);
        if (n == 0) {
            snprintf(first_channel, size, "%s", ev->channel);
        }
        lcm_eventlog_free_event(ev);
        n++;
    }
    lcm_eventlog_destroy(log);
    return n;
}

static void test_part_renamed_on_close(void **state)
{
    const fixture_t *const fx = *state;
    sf_log_file_t f;
    char err[256];
    assert_int_equal(sf_log_file_open(&f, fx->path, false, err, sizeof err), SF_OK);
    assert_true(exists(f.part_path) && !exists(fx->path));
    for (int i = 0; i < 10; i++) {
        assert_int_equal(sf_log_file_write(&f, "X", 1000 + i, "abc", 3), SF_OK);
    }
    assert_int_equal(f.offset, 10 * (SF_LOG_FILE_EVENT_OVERHEAD + 1 + 3));
    assert_int_equal(sf_log_file_sync(&f), SF_OK);
    assert_int_equal(sf_log_file_close(&f, err, sizeof err), SF_OK);
    assert_true(!exists(f.part_path) && exists(fx->path));
    char first[32];
    assert_int_equal(read_back(fx->path, first, sizeof first), 10);
    assert_string_equal(first, "X");
    assert_int_equal(sf_log_file_close(&f, err, sizeof err), SF_OK); /* closed: nothing to do */
}

static void test_existing_names_and_symlinks_refused(void **state)
{
    const fixture_t *const fx = *state;
    sf_log_file_t f;
    char err[256];
    FILE *const existing = fopen(fx->path, "w");
    fputs("precious", existing);
    fclose(existing);
    assert_int_equal(sf_log_file_open(&f, fx->path, false, err, sizeof err), SF_EIO);
    assert_int_equal(errno, EEXIST);
    assert_non_null(strstr(err, "--force"));
    unlink(fx->path);
    char part[160];
    snprintf(part, sizeof part, "%s%s", fx->path, SF_LOG_FILE_PART_SUFFIX);
    assert_int_equal(symlink("/tmp/sf_test_log_file_victim", part), 0);
    assert_int_equal(sf_log_file_open(&f, fx->path, false, err, sizeof err), SF_EIO);
    assert_int_equal(sf_log_file_open(&f, fx->path, true, err, sizeof err), SF_EIO); /* --force: still no */
    assert_int_equal(errno, ELOOP);
    assert_false(exists("/tmp/sf_test_log_file_victim"));
    unlink(part);
}

/* Regression for "rename replaces a log that appeared meanwhile": without force the rename refuses
 * and the .part stays, named in the message. */
static void test_close_never_replaces_a_file_that_appeared(void **state)
{
    const fixture_t *const fx = *state;
    sf_log_file_t f;
    char err[512];
    assert_int_equal(sf_log_file_open(&f, fx->path, false, err, sizeof err), SF_OK);
    FILE *const other = fopen(fx->path, "w");
    fputs("other", other);
    fclose(other);
    assert_int_equal(sf_log_file_close(&f, err, sizeof err), SF_EIO);
    assert_non_null(strstr(err, ".part"));
    assert_true(exists(f.part_path));
}

/* Injected disk full: /dev/full fails every write with ENOSPC; the event is not counted. */
static void test_failed_write_leaves_the_file_as_it_was(void **state)
{
    (void)state;
    sf_log_file_t f = {.fd = open("/dev/full", O_WRONLY)};
    assert_true(f.fd >= 0);
    assert_int_equal(sf_log_file_write(&f, "X", 1, "abc", 3), SF_EIO);
    assert_int_equal(errno, ENOSPC);
    assert_int_equal(f.offset, 0);
    assert_int_equal(f.next_event, 0);
    close(f.fd);
}

/* sf_log_file_append: events laid out by the caller (any number in their number field) are
 * numbered on from the file's count, in one write; a layout that does not add up is refused before
 * anything is written; on /dev/full the file stays as it was. */
static void test_append_numbers_the_events_in_one_write(void **state)
{
    const fixture_t *const fx = *state;
    sf_log_file_t f;
    char err[256];
    assert_int_equal(sf_log_file_open(&f, fx->path, false, err, sizeof err), SF_OK);
    assert_int_equal(sf_log_file_write(&f, "X", 1, "abc", 3), SF_OK);
    uint8_t events[3 * (SF_LOG_FILE_EVENT_OVERHEAD + 2 + 4)];
    size_t at = 0;
    for (int i = 0; i < 3; i++) {
        sf_log_file_put_header(events + at, 777 + i, 2 + i, 2, 4);
        memcpy(events + at + SF_LOG_FILE_EVENT_OVERHEAD, "YZ" "data", 6);
        assert_int_equal(sf_log_file_event_bytes(events + at), SF_LOG_FILE_EVENT_OVERHEAD + 6);
        at += SF_LOG_FILE_EVENT_OVERHEAD + 6;
    }
    assert_int_equal(sf_log_file_append(&f, events, sizeof events - 1, 3), SF_EINVAL);
    assert_int_equal(sf_log_file_append(&f, events, sizeof events, 2), SF_EINVAL);
    assert_int_equal(f.next_event, 1);
    assert_int_equal(sf_log_file_append(&f, events, sizeof events, 3), SF_OK);
    assert_int_equal(f.next_event, 4);
    assert_int_equal(f.offset, SF_LOG_FILE_EVENT_OVERHEAD + 4 + sizeof events);
    assert_int_equal(sf_log_file_close(&f, err, sizeof err), SF_OK);
    char first[8];
    assert_int_equal(read_back(fx->path, first, sizeof first), 4); /* numbered 0, 1, 2, 3 */
    sf_log_file_t full = {.fd = open("/dev/full", O_WRONLY)};
    assert_true(full.fd >= 0);
    assert_int_equal(sf_log_file_append(&full, events, sizeof events, 3), SF_EIO);
    assert_int_equal(errno, ENOSPC);
    assert_int_equal(full.offset, 0);
    assert_int_equal(full.next_event, 0);
    close(full.fd);
}

static void test_names(void **state)
{
    (void)state;
    char name[256];
    assert_int_equal(sf_log_file_rotated_name(name, sizeof name, "d/walk.lcmlog", 0), SF_OK);
    assert_string_equal(name, "d/walk.lcmlog");
    assert_int_equal(sf_log_file_rotated_name(name, sizeof name, "d/walk.lcmlog", 7), SF_OK);
    assert_string_equal(name, "d/walk.007.lcmlog");
    assert_int_equal(sf_log_file_rotated_name(name, sizeof name, "d/walk.log", 12), SF_OK);
    assert_string_equal(name, "d/walk.log.012");
    assert_int_equal(sf_log_file_rotated_name(name, 8, "d/walk.lcmlog", 1), SF_EINVAL);
    const struct timespec t = {.tv_sec = 1700000000, .tv_nsec = 123456789};
    assert_int_equal(sf_log_file_default_name(name, sizeof name, "logs", &t, 4242, 0), SF_OK);
    assert_string_equal(name, "logs/stridefixd-20231114-221320-123456-4242.lcmlog");
    assert_int_equal(sf_log_file_default_name(name, sizeof name, "logs", &t, 4242, 3), SF_OK);
    assert_string_equal(name, "logs/stridefixd-20231114-221320-123456-4242-3.lcmlog");
}

static sf_lcm_out_config_t config(const char *const path)
{
    return (sf_lcm_out_config_t){.log_path = path, .queue_capacity = 64, .block_when_full = true,
                                 .fsync_interval_ms = 0, .report = stderr};
}

static void size_rotation(const fixture_t *const fx, const bool caller_writes)
{
    sf_lcm_out_config_t cfg = config(fx->path);
    cfg.caller_writes = caller_writes;
    const char payload[72] = {0};                               /* 28 + 1 + 72 = 101 bytes an event */
    cfg.rotate_bytes = 1000;                                    /* 9 events and a 101-byte header */
    sf_lcm_out_t *out = NULL;
    char err[256];
    assert_int_equal(sf_lcm_out_open_config(&out, &cfg, err, sizeof err), SF_OK);
    assert_int_equal(sf_lcm_out_write_header(out, "H", 0, payload, sizeof payload), SF_OK);
    for (int i = 1; i < 30; i++) {
        assert_int_equal(sf_lcm_out_write(out, "X", i, payload, sizeof payload), SF_OK);
    }
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    /* 30 queued: files of 9 or 10 events (the first holds the header itself and 9 more) */
    assert_int_equal(c.files, 4);
    assert_int_equal(c.header_copies, 3);
    assert_int_equal(c.events - c.header_copies + c.drops, 30);
    int total = 0;
    for (unsigned k = 0; k < c.files; k++) {
        char name[160], first[8];
        assert_int_equal(sf_log_file_rotated_name(name, sizeof name, fx->path, k), SF_OK);
        const int n = read_back(name, first, sizeof first);
        assert_string_equal(first, "H");
        total += n;
        struct stat st;
        assert_int_equal(stat(name, &st), 0);
        assert_true(st.st_size <= 1000);
    }
    assert_int_equal(total, (int)c.events);
}

static void test_size_rotation_and_rotate_request(void **state)
{
    size_rotation(*state, false);
}

/* The same rules when the caller writes the batches (a file replay: sf_lcm_out.h caller_writes). */
static void test_size_rotation_caller_writes(void **state)
{
    size_rotation(*state, true);
}

static void rotate_request(const fixture_t *const fx, const bool caller_writes)
{
    sf_lcm_out_config_t cfg = config(fx->path);
    cfg.caller_writes = caller_writes;
    sf_lcm_out_t *out = NULL;
    char err[256];
    assert_int_equal(sf_lcm_out_open_config(&out, &cfg, err, sizeof err), SF_OK);
    assert_int_equal(sf_lcm_out_write_header(out, "H", 0, "h", 1), SF_OK);
    assert_int_equal(sf_lcm_out_write(out, "X", 1, "x", 1), SF_OK);
    sf_lcm_out_rotate(out);
    for (int i = 0; i < 200 && !exists(fx->path); i++) {
        usleep(10000);
    }
    assert_true(exists(fx->path)); /* renamed before any further event */
    assert_int_equal(sf_lcm_out_write(out, "X", 2, "x", 1), SF_OK);
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    char second[160], first[8];
    assert_int_equal(sf_log_file_rotated_name(second, sizeof second, fx->path, 1), SF_OK);
    assert_int_equal(read_back(fx->path, first, sizeof first), 2);
    assert_int_equal(read_back(second, first, sizeof first), 2);
    assert_string_equal(first, "H");
    assert_int_equal(c.events, 4);
}

static void test_rotate_request_closes_the_file_at_once(void **state)
{
    rotate_request(*state, false);
}

static void test_rotate_request_caller_writes(void **state)
{
    rotate_request(*state, true);
}

static void test_queue_drops_count_their_bytes(void **state)
{
    const fixture_t *const fx = *state;
    sf_lcm_out_config_t cfg = config(fx->path);
    cfg.queue_capacity = 1;
    cfg.block_when_full = false;
    sf_lcm_out_t *out = NULL;
    char err[256];
    assert_int_equal(sf_lcm_out_open_config(&out, &cfg, err, sizeof err), SF_OK);
    const char payload[100] = {1};
    int full = 0;
    for (int i = 0; i < 3000; i++) {
        full += sf_lcm_out_write(out, "XY", i, payload, sizeof payload) == SF_EFULL;
    }
    sf_lcm_out_counters_t c;
    assert_int_equal(sf_lcm_out_close(out, &c), SF_OK);
    assert_int_equal(c.drops, (uint64_t)full);
    assert_int_equal(c.drop_bytes, (uint64_t)full * (SF_LOG_FILE_EVENT_OVERHEAD + 2 + 100));
    assert_int_equal(c.events + c.drops, 3000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_part_renamed_on_close, setup, teardown),
        cmocka_unit_test_setup_teardown(test_existing_names_and_symlinks_refused, setup, teardown),
        cmocka_unit_test_setup_teardown(test_close_never_replaces_a_file_that_appeared, setup, teardown),
        cmocka_unit_test(test_failed_write_leaves_the_file_as_it_was),
        cmocka_unit_test(test_names),
        cmocka_unit_test_setup_teardown(test_size_rotation_and_rotate_request, setup, teardown),
        cmocka_unit_test_setup_teardown(test_rotate_request_closes_the_file_at_once, setup, teardown),
        cmocka_unit_test_setup_teardown(test_size_rotation_caller_writes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_rotate_request_caller_writes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_append_numbers_the_events_in_one_write, setup, teardown),
        cmocka_unit_test_setup_teardown(test_queue_drops_count_their_bytes, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
