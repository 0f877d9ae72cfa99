/* test_radiomap.c — sf_radiomap_check catches each broken invariant of the AP-major radio map, names
 * it, and passes a good map and an empty one; sf_radiomap_find_ap finds every BSSID and nothing else. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "sf_error.h"
#include "sf_radiomap.h"

/* 3 APs × 3 RPs, 6 entries: a0 → r0 r1 r2, a1 → r1, a2 → r0 r2. Copies are mutated per test. */
typedef struct {
    int64_t bssid[3];
    int32_t first[4];
    float x[3], y[3];
    int16_t floor[3];
    int32_t scans[3];
    int32_t rp[6];
    float mean[6], std[6];
    int32_t count[6];
    sf_radiomap_t map;
} fixture_t;

static void make(fixture_t *const f)
{
    *f = (fixture_t){
        .bssid = {10, 20, 30},
        .first = {0, 3, 4, 6},
        .x = {0, 1, 2},
        .y = {0, 0, 0},
        .floor = {0, 0, 1},
        .scans = {5, 5, 5},
        .rp = {0, 1, 2, 1, 0, 2},
        .mean = {-50, -60, -70, -55, -65, -75},
        .std = {2, 2, 2, 2, 2, 2},
        .count = {5, 4, 3, 5, 1, 5},
    };
    f->map = (sf_radiomap_t){3, f->bssid, f->first, 3, f->x, f->y, f->floor, f->scans,
                             6, f->rp, f->mean, f->std, f->count};
}

static void expect_broken(fixture_t *const f, const char *const text)
{
    const char *what = NULL;
    assert_int_equal(sf_radiomap_check(&f->map, &what), SF_ERANGE);
    assert_non_null(what);
    assert_string_equal(what, text);
}

static void test_good_and_empty(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    const char *what = NULL;
    assert_int_equal(sf_radiomap_check(&f.map, &what), SF_OK);
    assert_int_equal(sf_radiomap_check(&f.map, NULL), SF_OK);
    const sf_radiomap_t empty = {0};
    assert_int_equal(sf_radiomap_check(&empty, &what), SF_OK);
    assert_int_equal(sf_radiomap_check(NULL, &what), SF_ERANGE);
}

static void test_unsorted_bssids(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.bssid[2] = 20; /* equal is not strictly ascending */
    expect_broken(&f, "ap_bssid not strictly ascending");
    make(&f);
    f.bssid[0] = 25;
    expect_broken(&f, "ap_bssid not strictly ascending");
}

static void test_bad_ap_first(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.first[0] = 1;
    expect_broken(&f, "ap_first[0] != 0");
    make(&f);
    f.first[2] = 2; /* 3, 2: decreasing */
    expect_broken(&f, "ap_first decreasing");
    make(&f);
    f.first[3] = 5;
    expect_broken(&f, "ap_first[n_ap] != n_entries");
}

static void test_rp_index_out_of_range(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.rp[3] = 3;
    expect_broken(&f, "entry_rp out of range");
    make(&f);
    f.rp[0] = -1;
    expect_broken(&f, "entry_rp out of range");
}

static void test_entries_unsorted_by_rp(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.rp[1] = 0; /* r0 twice under a0 */
    expect_broken(&f, "entries of an AP not strictly ascending by rp");
}

static void test_count_above_scans(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.count[2] = 6;
    expect_broken(&f, "entry_count outside [1, rp_scans]");
    make(&f);
    f.count[2] = 0;
    expect_broken(&f, "entry_count outside [1, rp_scans]");
    make(&f);
    f.scans[1] = 0;
    expect_broken(&f, "rp_scans < 1");
}

static void test_nan_values(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.mean[4] = NAN;
    expect_broken(&f, "entry_mean_dbm not finite");
    make(&f);
    f.std[4] = -1.0f;
    expect_broken(&f, "entry_std_db not finite or negative");
    make(&f);
    f.x[1] = INFINITY;
    expect_broken(&f, "rp position not finite");
}

static void test_sizes_and_nulls(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    f.map.n_rp = -1;
    expect_broken(&f, "negative n_ap, n_rp or n_entries");
    make(&f);
    f.map.entry_mean_dbm = NULL;
    expect_broken(&f, "NULL array with a non-zero size");
    make(&f);
    f.map.n_ap = 0;
    expect_broken(&f, "entries without access points");
}

static void test_find_ap(void **state)
{
    (void)state;
    fixture_t f;
    make(&f);
    assert_int_equal(sf_radiomap_find_ap(&f.map, 10), 0);
    assert_int_equal(sf_radiomap_find_ap(&f.map, 20), 1);
    assert_int_equal(sf_radiomap_find_ap(&f.map, 30), 2);
    assert_int_equal(sf_radiomap_find_ap(&f.map, 5), -1);
    assert_int_equal(sf_radiomap_find_ap(&f.map, 15), -1);
    assert_int_equal(sf_radiomap_find_ap(&f.map, 31), -1);
    assert_int_equal(sf_radiomap_find_ap(NULL, 10), -1);
    const sf_radiomap_t empty = {0};
    assert_int_equal(sf_radiomap_find_ap(&empty, 10), -1);
    /* A longer table: every BSSID found at its index, every gap missed. */
    int64_t b[101];
    for (int i = 0; i < 101; i++) {
        b[i] = 1000 + 7 * (int64_t)i;
    }
    sf_radiomap_t big = {0};
    big.n_ap = 101;
    big.ap_bssid = b;
    for (int i = 0; i < 101; i++) {
        assert_int_equal(sf_radiomap_find_ap(&big, b[i]), i);
        assert_int_equal(sf_radiomap_find_ap(&big, b[i] + 1), -1);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_and_empty),   cmocka_unit_test(test_unsorted_bssids),
        cmocka_unit_test(test_bad_ap_first),     cmocka_unit_test(test_rp_index_out_of_range),
        cmocka_unit_test(test_entries_unsorted_by_rp), cmocka_unit_test(test_count_above_scans),
        cmocka_unit_test(test_nan_values),       cmocka_unit_test(test_sizes_and_nulls),
        cmocka_unit_test(test_find_ap),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
