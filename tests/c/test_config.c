/* test_config.c — sf_config_load / sf_config_set: good files, every kind of bad line with its
 * file:line in the message, missing files, and --set overrides. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sf_config.h"
#include "sf_error.h"
#include "sf_params.h"

static char g_path[64];

static void write_config(const char *const text)
{
    if (g_path[0] != '\0') {
        unlink(g_path);
    }
    strcpy(g_path, "/tmp/sf_test_config_XXXXXX");
    const int fd = mkstemp(g_path);
    assert_true(fd >= 0);
    const size_t len = strlen(text);
    assert_int_equal(write(fd, text, len), (ssize_t)len);
    close(fd);
}

static int remove_config(void **state)
{
    (void)state;
    if (g_path[0] != '\0') {
        unlink(g_path);
        g_path[0] = '\0';
    }
    return 0;
}

/* Loads text; checks the code and, on failure, that the message starts "path:line:" and contains
 * `needle`. Returns the params. */
static sf_params_t load(const char *const text, const int want_rc, const int want_line, const char *const needle)
{
    write_config(text);
    sf_params_t p;
    sf_params_default(&p);
    char err[512] = "";
    const int rc = sf_config_load(g_path, &p, err, sizeof err);
    if (rc != want_rc) {
        fail_msg("got %d (%s), want %d; message: %s", rc, sf_strerror(rc), want_rc, err);
    }
    if (want_line > 0) {
        char prefix[96];
        snprintf(prefix, sizeof prefix, "%s:%d: ", g_path, want_line);
        if (strncmp(err, prefix, strlen(prefix)) != 0) {
            fail_msg("message '%s' does not start with '%s'", err, prefix);
        }
    }
    if (needle != NULL && strstr(err, needle) == NULL) {
        fail_msg("message '%s' does not name '%s'", err, needle);
    }
    return p;
}

static void test_good_file_sets_values(void **state)
{
    (void)state;
    const sf_params_t p = load("; StrideFix config\n"
                               "[init]\n"
                               "x_m = 12.5\n"
                               "floor = 3\n"
                               "\n"
                               "[stride]\n"
                               "weinberg_k = 0.72   ; a comment\n"
                               "[steps]\n"
                               "refractory_ms = 250\n"
                               "max_gap_ms=1000\n"
                               "[output]\n"
                               "pose_period_ms = 200\n",
                               SF_OK, 0, NULL);
    sf_params_t d;
    sf_params_default(&d);
    assert_true(p.init_x_m == 12.5);
    assert_int_equal(p.init_floor, 3);
    assert_true(p.stride_weinberg_k == 0.72);
    assert_int_equal(p.steps_refractory_ms, 250);
    assert_int_equal(p.steps_max_gap_ms, 1000);
    assert_int_equal(p.output_pose_period_ms, 200);
    /* the rest keep their defaults */
    assert_true(p.init_y_m == d.init_y_m);
    assert_true(p.steps_pt_threshold == d.steps_pt_threshold);
    assert_int_equal(p.output_health_period_ms, d.output_health_period_ms);
}

static void test_empty_file_keeps_defaults(void **state)
{
    (void)state;
    const sf_params_t p = load("", SF_OK, 0, NULL);
    sf_params_t d;
    sf_params_default(&d);
    for (size_t i = 0; i < sf_param_count; i++) {
        assert_true(sf_param_get(&p, &sf_param_table[i]) == sf_param_get(&d, &sf_param_table[i]));
    }
    assert_true(d.stride_weinberg_k == 0.47);
    assert_int_equal(d.steps_max_gap_ms, 500);
}

static void test_unknown_key(void **state)
{
    (void)state;
    load("[stride]\nweinberg_k = 0.8\n\nweinberg = 0.9\n", SF_ESYNTAX, 4, "weinberg");
}

static void test_unknown_section(void **state)
{
    (void)state;
    load("[stride]\nweinberg_k = 0.8\n[gnss]\nweight = 2\n", SF_ESYNTAX, 4, "gnss");
}

static void test_key_outside_section(void **state)
{
    (void)state;
    load("weinberg_k = 0.8\n", SF_ESYNTAX, 1, "weinberg_k");
}

static void test_out_of_range(void **state)
{
    (void)state;
    load("[stride]\nweinberg_k = 2.1\n", SF_ERANGE, 2, "weinberg_k");
    load("[stride]\nweinberg_k = 0.04\n", SF_ERANGE, 2, "weinberg_k");
    load("[init]\nfloor = -21\n", SF_ERANGE, 2, "floor");
    load("[steps]\n\n\nmax_gap_ms = 10001\n", SF_ERANGE, 4, "max_gap_ms");
    /* an int32 key with a fraction */
    load("[steps]\nmax_gap_ms = 500.5\n", SF_ERANGE, 2, "max_gap_ms");
    /* the bounds themselves are allowed */
    const sf_params_t p = load("[stride]\nweinberg_k = 2.0\n[steps]\nmax_gap_ms = 20\n", SF_OK, 0, NULL);
    assert_true(p.stride_weinberg_k == 2.0);
    assert_int_equal(p.steps_max_gap_ms, 20);
}

static void test_not_a_number(void **state)
{
    (void)state;
    load("[stride]\nweinberg_k = long\n", SF_ESYNTAX, 2, "long");
    load("[stride]\nweinberg_k = 0.8m\n", SF_ESYNTAX, 2, "0.8m");
    load("[stride]\nweinberg_k =\n", SF_ESYNTAX, 2, "weinberg_k");
    load("[stride]\nweinberg_k = nan\n", SF_ERANGE, 2, "weinberg_k"); /* a number, but not in range */
}

static void test_bad_line(void **state)
{
    (void)state;
    load("[stride]\nweinberg_k = 0.8\nthis is not ini\n", SF_ESYNTAX, 3, NULL);
    load("[stride\nweinberg_k = 0.8\n", SF_ESYNTAX, 1, NULL);
}

/* Regression test for "config error forgotten after a later good line" (open). inih (Debian's
 * build, INI_STOP_ON_FIRST_ERROR off) goes on calling the handler after the handler reported an error,
 * and sf_config.c's on_entry() overwrites ctx->rc with each later line's result. A bad line followed
 * by a good one therefore loses its code and its message: an out-of-range value comes back as
 * SF_ESYNTAX "not 'key = value' or '[section]'" instead of SF_ERANGE naming the key, and the lines
 * after the error are still applied. */
static void test_error_is_kept_when_good_lines_follow(void **state)
{
    (void)state;
    const sf_params_t p = load("[steps]\nrefractory_ms = 250\nbogus = 1\nmax_gap_ms = 900\n", SF_ESYNTAX, 3, "bogus");
    assert_int_equal(p.steps_max_gap_ms, 500); /* the line after the error was not applied */
    load("[stride]\nweinberg_k = 9\nmax_gap_ms = 900\n", SF_ERANGE, 2, "weinberg_k");
    load("[stride]\nweinberg_k = abc\n[init]\nfloor = 1\n", SF_ESYNTAX, 2, "abc");
}

static void test_missing_file(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    char err[256] = "";
    assert_int_equal(sf_config_load("/nonexistent/stridefix.ini", &p, err, sizeof err), SF_ENOENT);
    assert_non_null(strstr(err, "/nonexistent/stridefix.ini"));
}

static void test_set(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    char err[256] = "";
    assert_int_equal(sf_config_set("stride.weinberg_k=0.8", &p, err, sizeof err), SF_OK);
    assert_true(p.stride_weinberg_k == 0.8);
    assert_int_equal(sf_config_set("init.floor=-2", &p, err, sizeof err), SF_OK);
    assert_int_equal(p.init_floor, -2);

    assert_int_equal(sf_config_set("stride.weinberg_k=9", &p, err, sizeof err), SF_ERANGE);
    assert_true(p.stride_weinberg_k == 0.8); /* unchanged */
    assert_non_null(strstr(err, "weinberg_k"));
    assert_int_equal(sf_config_set("stride.weinberg=0.8", &p, err, sizeof err), SF_ESYNTAX);
    assert_non_null(strstr(err, "weinberg"));
    assert_int_equal(sf_config_set("stride.weinberg_k=x", &p, err, sizeof err), SF_ESYNTAX);
    assert_int_equal(sf_config_set("weinberg_k=0.8", &p, err, sizeof err), SF_ESYNTAX);
    assert_int_equal(sf_config_set("stride.weinberg_k", &p, err, sizeof err), SF_ESYNTAX);
    assert_true(strlen(err) > 0);
}

/* Regression (input hardening): a --set longer than 255 characters was cut short silently; the value is
 * now read in place (no limit) and an over-long key is refused. */
static void test_set_is_never_cut_short(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    char err[256] = "";
    char long_value[600];
    snprintf(long_value, sizeof long_value, "stride.weinberg_k=0.5%0500d", 0); /* 0.5000...0 */
    assert_int_equal(sf_config_set(long_value, &p, err, sizeof err), SF_OK);
    assert_true(p.stride_weinberg_k == 0.5);
    snprintf(long_value, sizeof long_value, "stride.weinberg_k=0.5%0300dx", 0); /* the tail counts */
    assert_int_equal(sf_config_set(long_value, &p, err, sizeof err), SF_ESYNTAX);
    char long_key[400];
    memset(long_key, 'a', 300);
    strcpy(long_key + 300, ".b=1");
    assert_int_equal(sf_config_set(long_key, &p, err, sizeof err), SF_ESYNTAX);
    assert_non_null(strstr(err, "characters"));
}

/* Regression (input hardening): a line longer than inih's INI_MAX_LINE was split, and the error named a
 * later line and a key made of the line's tail. It is now refused with its own line number. */
static void test_over_long_line_names_its_line(void **state)
{
    (void)state;
    char text[1024];
    char comment[400];
    memset(comment, 'x', 300);
    comment[300] = '\0';
    snprintf(text, sizeof text, "[stride]\nweinberg_k = 0.5\n# %s\nweinberg_k = 0.6\n", comment);
    load(text, SF_ESYNTAX, 3, "longer than");
    snprintf(text, sizeof text, "[stride]\nweinberg_k = 0.5%s\n", comment);
    load(text, SF_ESYNTAX, 2, "longer than");
    /* 199 characters fit exactly (inih's 200-byte buffer less its NUL) */
    snprintf(text, sizeof text, "[stride]\n# %.197s\nweinberg_k = 0.6", comment);
    const sf_params_t p = load(text, SF_OK, 0, NULL);
    assert_true(p.stride_weinberg_k == 0.6);
}

static void test_nul_byte_is_refused(void **state)
{
    (void)state;
    write_config("");
    FILE *const f = fopen(g_path, "w");
    assert_non_null(f);
    fwrite("[stride]\nweinberg_k = 0.5\0\n", 1, 28, f);
    fclose(f);
    sf_params_t p;
    sf_params_default(&p);
    char err[512] = "";
    assert_int_equal(sf_config_load(g_path, &p, err, sizeof err), SF_ESYNTAX);
    assert_non_null(strstr(err, ":2: a NUL byte"));
}

/* Regression (input hardening): --config /dev/zero hung in inih, --config DIR was accepted. */
static void test_device_and_directory_are_refused(void **state)
{
    (void)state;
    sf_params_t p;
    sf_params_default(&p);
    char err[256] = "";
    assert_int_equal(sf_config_load("/dev/zero", &p, err, sizeof err), SF_EIO);
    assert_non_null(strstr(err, "/dev/zero: config is a character device"));
    assert_int_equal(sf_config_load("/tmp", &p, err, sizeof err), SF_EIO);
    assert_non_null(strstr(err, "/tmp: config is a directory"));
}

static void test_param_table_matches_struct(void **state)
{
    (void)state;
    assert_int_equal(sf_param_count, SF_PARAM_COUNT);
    sf_params_t p;
    sf_params_default(&p);
    for (size_t i = 0; i < sf_param_count; i++) {
        const sf_param_desc_t *const d = &sf_param_table[i];
        assert_ptr_equal(sf_param_find(d->section, d->name), d);
        assert_true(sf_param_get(&p, d) == d->default_value);
        assert_true(d->min_value <= d->default_value && d->default_value <= d->max_value);
    }
    assert_null(sf_param_find("pdr", "nope"));
}

#define CFG_TEST(fn) cmocka_unit_test_teardown(fn, remove_config)

int main(void)
{
    const struct CMUnitTest tests[] = {
        CFG_TEST(test_good_file_sets_values),
        CFG_TEST(test_empty_file_keeps_defaults),
        CFG_TEST(test_unknown_key),
        CFG_TEST(test_unknown_section),
        CFG_TEST(test_key_outside_section),
        CFG_TEST(test_out_of_range),
        CFG_TEST(test_not_a_number),
        CFG_TEST(test_bad_line),
        CFG_TEST(test_error_is_kept_when_good_lines_follow),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_set),
        cmocka_unit_test(test_set_is_never_cut_short),
        CFG_TEST(test_over_long_line_names_its_line),
        CFG_TEST(test_nul_byte_is_refused),
        cmocka_unit_test(test_device_and_directory_are_refused),
        cmocka_unit_test(test_param_table_matches_struct),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
