/* test_cls_floor.c — the floor a BLE scan identifies by the site's constellations (sf_cls_ble_floor):
 * one floor's members at their thresholds name it, a member below its threshold names nothing, two
 * floors heard at once name nothing, a context that needs two members needs two, and a context whose
 * CDD is Wi-Fi is not asked. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "sf_cls.h"
#include "sf_error.h"

/* floors -2 (BLE, needs 2 members), -1 (Wi-Fi), 0 (BLE, 1 member) of one building */
static const int16_t kind[] = {sf_context_floor, sf_context_floor, sf_context_floor};
static const int16_t building[] = {0, 0, 0};
static const int16_t floors[] = {-2, -1, 0};
static const int16_t cdd_method[] = {sf_fix_ble, sf_fix_wifi, sf_fix_ble};
static const int16_t min_hits[] = {2, 1, 1};
static const int16_t cdd_context[] = {0, 0, 1, 2};
static const int64_t cdd_id[] = {0xB2, 0xB4, 0xA1, 0xB3};
static const float cdd_min_dbm[] = {-66.5f, -71.0f, -70.0f, -70.5f};

static sf_context_map_t map(void)
{
    return (sf_context_map_t){.n_contexts = 3, .kind = kind, .building = building, .floor = floors,
                              .cdd_method = cdd_method, .cdd_min_hits = min_hits, .n_cdd = 4,
                              .cdd_context = cdd_context, .cdd_id = cdd_id, .cdd_min_dbm = cdd_min_dbm};
}

static int floor_of(const int64_t *ids, const float *rssi, const int32_t n, int16_t *floor)
{
    const sf_context_map_t m = map();
    const sf_ble_scan_t scan = {.t_us = 1, .n = n, .beacon_id = ids, .rssi_dbm = rssi};
    return sf_cls_ble_floor(&m, &scan, floor);
}

static void test_one_floor_identified(void **state)
{
    (void)state;
    int16_t floor = 99;
    const int64_t ids[] = {0xB3, 0xB2};
    const float loud[] = {-70.0f, -80.0f}; /* floor 0's member at its threshold, one of -2's below */
    assert_int_equal(floor_of(ids, loud, 2, &floor), SF_OK);
    assert_int_equal(floor, 0);
    const float quiet[] = {-71.0f, -80.0f}; /* 0.5 dB under floor 0's threshold */
    assert_int_equal(floor_of(ids, quiet, 2, &floor), SF_ERANGE);
}

static void test_two_members_needed(void **state)
{
    (void)state;
    int16_t floor = 99;
    const int64_t one[] = {0xB2};
    const float one_dbm[] = {-60.0f};
    assert_int_equal(floor_of(one, one_dbm, 1, &floor), SF_ERANGE); /* -2 needs two of its members */
    const int64_t two[] = {0xB2, 0xB4};
    const float two_dbm[] = {-60.0f, -70.0f};
    assert_int_equal(floor_of(two, two_dbm, 2, &floor), SF_OK);
    assert_int_equal(floor, -2);
}

static void test_two_floors_name_nothing(void **state)
{
    (void)state;
    int16_t floor = 99;
    const int64_t ids[] = {0xB2, 0xB4, 0xB3};
    const float dbm[] = {-60.0f, -70.0f, -65.0f};
    assert_int_equal(floor_of(ids, dbm, 3, &floor), SF_ERANGE);
}

static void test_wifi_members_not_asked(void **state)
{
    (void)state;
    int16_t floor = 99;
    const int64_t ids[] = {0xA1}; /* floor -1's member is a Wi-Fi AP: a BLE id equal to it is no evidence */
    const float dbm[] = {-40.0f};
    assert_int_equal(floor_of(ids, dbm, 1, &floor), SF_ERANGE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_floor_identified),
        cmocka_unit_test(test_two_members_needed),
        cmocka_unit_test(test_two_floors_name_nothing),
        cmocka_unit_test(test_wifi_members_not_asked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
